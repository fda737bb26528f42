"""Visibility graph: closed-form lengths, an independent brute force, exact freedom."""

import itertools
import math

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

import skyroute
from skyroute import QueryError, Status, World
from skyroute.roadmap.world_plan import visibility_graph


def rect_world(boxes, boundary=None, frame="enu"):
    polys = shapely.box(*np.asarray(boxes, dtype=float).T)
    n = len(polys)
    return World(polys, np.full(n, -np.inf), np.full(n, np.inf), (), boundary, frame)


def brute_force(boxes, s, t):
    """All vertices of the union, every pair tested with shapely's DE-9IM directly,
    Dijkstra by scipy: nothing of skyroute's geometry code."""
    union = shapely.unary_union(shapely.box(*np.asarray(boxes, dtype=float).T))
    verts = [np.asarray(r.coords)[:-1] for p in getattr(union, "geoms", [union])
             for r in (p.exterior, *p.interiors)]
    pts = np.vstack([s, t, *verts])
    n = len(pts)
    rows, cols, w = [], [], []
    for i in range(n):
        for j in range(i + 1, n):
            line = shapely.LineString([pts[i], pts[j]])
            if not union.relate_pattern(line, "T********"):
                rows.append(i)
                cols.append(j)
                w.append(math.dist(pts[i], pts[j]) + 1e-300)
    g = coo_matrix((w, (rows, cols)), shape=(n, n)).tocsr()
    return dijkstra(g, directed=False, indices=0)[1]


def assert_free(boxes, path):
    union = shapely.unary_union(shapely.box(*np.asarray(boxes, dtype=float).T))
    for a, b in itertools.pairwise(path):
        assert not union.relate_pattern(shapely.LineString([a, b]), "T********"), (a, b)


@pytest.mark.parametrize("boxes, s, t, expected", [
    ([(1, 1, 3, 3)], (0, 2), (4, 2), 2 + 2 * math.sqrt(2)),                   # one square
    ([(1, -1, 3, 1), (5, -1, 7, 1)], (0, 0), (8, 0), 6 + 2 * math.sqrt(2)),   # two squares
    ([(2, -5, 3, -0.5), (2, 0.5, 3, 5)], (0, 3), (5, -3),                    # a slit
     2 * math.hypot(2, 2.5) + math.sqrt(2)),
    ([(1, 1, 3, 3)], (0, 0), (4, 0), 4.0),                  # along an edge: touching is free
])
def test_closed_form_lengths(boxes, s, t, expected):
    r = skyroute.plan(rect_world(boxes), s, t)
    assert r.status is Status.FOUND
    assert r.cost == pytest.approx(expected, rel=1e-12)
    assert_free(boxes, r.path)
    np.testing.assert_allclose(r.path[[0, -1]], [s, t])


@st.composite
def rect_worlds(draw):
    k = draw(st.integers(1, 7))
    boxes = []
    for _ in range(k):
        x, y = draw(st.integers(0, 18)), draw(st.integers(0, 18))
        w, h = draw(st.integers(1, 6)), draw(st.integers(1, 6))
        boxes.append((x, y, x + w, y + h))
    coords = st.floats(-2, 26, allow_nan=False).map(lambda v: round(v, 3))
    s = (draw(coords), draw(coords))
    t = (draw(coords), draw(coords))
    if draw(st.booleans()):  # across the first box, from beyond the others: a path that
        # bends (points anywhere: 43 of 60 were a straight segment or start == goal)
        y0, y1 = boxes[0][1], boxes[0][3]
        y = st.floats(y0 + 0.01, y1 - 0.01).map(lambda v: round(v, 3))
        s = (draw(st.sampled_from([-2, -1])), draw(y))
        t = (draw(st.sampled_from([25, 26])), draw(y))
    assume(s != t)
    return boxes, s, t


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(rect_worlds())
def test_matches_brute_force_on_random_rectangle_worlds(case):
    boxes, s, t = case
    world = rect_world(boxes)
    union = shapely.unary_union(world.obstacles)
    if union.contains(shapely.Point(s)) or union.contains(shapely.Point(t)):
        with pytest.raises(QueryError):
            skyroute.plan(world, s, t)
        return
    expected = brute_force(boxes, s, t)
    r = skyroute.plan(world, s, t)
    if np.isinf(expected):
        assert r.status is Status.NO_PATH
    else:
        assert r.found and r.cost == pytest.approx(expected, rel=1e-9, abs=1e-9)
        assert_free(boxes, r.path)


def test_boundary_is_strict_and_corners_outside_are_ignored():
    boundary = shapely.box(0, 0, 10, 10)
    world = rect_world([(4, -5, 6, 9)], boundary)  # a wall from below, gap at the top
    r = skyroute.plan(world, (2, 5), (8, 5))
    assert r.found and r.cost == pytest.approx(2 * math.hypot(2, 4) + 2, rel=1e-12)
    closed = rect_world([(4, -5, 6, 10)], boundary)  # the wall reaches the boundary
    assert skyroute.plan(closed, (2, 5), (8, 5)).status is Status.NO_PATH
    with pytest.raises(QueryError, match=r"outside the map \(x in \(0, 10\)"):
        skyroute.plan(world, (10, 5), (8, 5))  # on the boundary counts as outside


def test_paths_bend_round_the_corners_of_a_boundary_that_is_not_convex():
    # an L-shaped map (and a square one with a square hole): the shortest way from one arm
    # to the other bends at the inner corner; the graph had no node there ("no_path")
    ell = shapely.Polygon([(0, 0), (10, 0), (10, 4), (4, 4), (4, 10), (0, 10)])
    ring = shapely.box(0, 0, 10, 10).difference(shapely.box(3, 3, 7, 7))
    for boundary, s, t, infimum in ((ell, (8, 2), (2, 8), 2 * math.hypot(4, 2)),
                                    (ring, (1, 5), (9, 5), 2 * math.hypot(2, 2) + 4)):
        world = rect_world([(20, 20, 21, 21)], boundary)  # an obstacle outside the map
        r = skyroute.plan(world, s, t)
        assert r.found, boundary
        # strictly inside the boundary, so just longer than the path through the corner
        assert infimum < r.cost < infimum + 1e-6
        assert world.segments_free(r.path[:-1], r.path[1:]).all()


@st.composite
def boundary_worlds(draw):
    """A star-shaped or comb-shaped boundary (reflex corners everywhere), a few rotated
    bars inside, and two free points strictly inside it."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    if draw(st.booleans()):
        a = np.linspace(0, 2 * np.pi, 13)[:-1]
        r = np.where(np.arange(12) % 2, 12, rng.uniform(3, 9))
        boundary = shapely.Polygon(np.c_[10 + r * np.cos(a), 10 + r * np.sin(a)])
    else:
        teeth = [shapely.box(x, 0 if x != 10 else 6, x + 1, 14 if x != 10 else 20)
                 for x in (4, 10, 16)]
        boundary = shapely.box(0, 0, 20, 20).difference(shapely.union_all(teeth))
    bars = [shapely.affinity.rotate(shapely.box(x - r, y - r / 3, x + r, y + r / 3), turn)
            for x, y, r, turn in zip(*rng.uniform(0, 20, (2, 3)), rng.uniform(0.5, 3, 3),
                                     rng.uniform(0, 180, 3), strict=True)]
    bars = bars[:draw(st.integers(0, 3))]
    world = World(bars, np.full(len(bars), -np.inf), np.full(len(bars), np.inf), (),
                  boundary, "enu")
    pts = rng.uniform(0, 20, (400, 2))
    pts = pts[world.is_free(pts)][:2]
    return world, boundary, bars, pts


def reference_length(boundary, bars, s, t):
    """Shortest length with the boundary closed (the infimum of the strict problem): the
    bars and the outside of the boundary as one union, every vertex of it, an edge where
    shapely says the segment meets no interior of the union, Dijkstra by scipy."""
    outside = shapely.box(*np.add(boundary.bounds, (-9, -9, 9, 9))).difference(boundary)
    union = shapely.union_all([*bars, outside])
    rings = [r for p in getattr(union, "geoms", [union]) for r in (p.exterior, *p.interiors)]
    pts = np.vstack([s, t, *(np.asarray(r.coords)[:-1] for r in rings)])
    rows, cols, w = [], [], []
    for i, j in itertools.combinations(range(len(pts)), 2):
        line = shapely.LineString([pts[i], pts[j]])
        if not union.relate_pattern(line, "T********"):
            rows.append(i)
            cols.append(j)
            w.append(math.dist(pts[i], pts[j]) + 1e-300)
    graph = coo_matrix((w, (rows, cols)), shape=(len(pts), len(pts)))
    return dijkstra(graph, directed=False, indices=0)[1]


@settings(max_examples=25, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(boundary_worlds())
def test_boundaries_that_are_not_convex_match_an_independent_graph(case):
    world, boundary, bars, pts = case
    if len(pts) < 2:
        return
    expected = reference_length(boundary, bars, *pts)
    r = skyroute.plan(world, pts[0], pts[1])
    if math.isinf(expected):
        assert r.status is Status.NO_PATH
        return
    assert r.found
    assert expected - 1e-9 <= r.cost < expected + 1e-6
    assert r.cost == pytest.approx(np.hypot(*np.diff(r.path, axis=0).T).sum(), rel=1e-12)
    assert world.segments_free(r.path[:-1], r.path[1:]).all()


def test_start_inside_an_obstacle_names_it_and_a_free_point():
    world = rect_world([(1, 1, 3, 3)])
    with pytest.raises(QueryError, match=r"start \(2.00, 1.50\) lies inside obstacle "
                       r"'obstacle 0'; nearest free point \(2.00, 0.99\)"):
        skyroute.plan(world, (2, 1.5), (5, 5))


def test_repeated_queries_reuse_the_graph():
    boxes = [(1, 1, 3, 3), (5, 0, 6, 8)]
    world = rect_world(boxes)
    first = skyroute.plan(world, (0, 0), (8, 4))
    graph = visibility_graph(world)
    again = skyroute.plan(world, (0, 0), (8, 4))
    fresh = skyroute.plan(rect_world(boxes), (0, 0), (8, 4))  # the same world, new graph
    assert first.cost == again.cost == fresh.cost
    np.testing.assert_array_equal(first.path, again.path)
    # the graph is kept with the world; a query tests only its own segments (the direct
    # one, and those from the start and to the goal), never corner-to-corner edges
    assert visibility_graph(world) is graph
    assert again.los_checks == first.los_checks == fresh.los_checks
    assert first.los_checks <= 1 + 2 * len(graph.corners)
    assert first.extra["edges"] == graph.edge_count > 0


@pytest.mark.parametrize("budget", [-1, "5", 5.0, True])
def test_visibility_refuses_a_bad_budget(budget):
    # -1 ended "budget_exhausted" and "5" was taken as 5
    world = World([shapely.box(1, 1, 3, 3)], [0], [50], ("tower",))
    with pytest.raises(skyroute.OptionError, match="max_expansions="):
        skyroute.plan(world, (0, 2), (4, 2), max_expansions=budget)
