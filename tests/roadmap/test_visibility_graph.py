"""The eager visibility graph: its compiled sight test against shapely, exact signs against
fractions, costs against an independent brute force (rotated obstacles, a cut of the
FCND city), no path across free regions, and the disk cache."""

import math
from fractions import Fraction

import numpy as np
import pytest
import shapely
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

import skyroute
from skyroute import Status, World
from skyroute.roadmap import sight_kernels as sk
from skyroute.roadmap.visibility import VisibilityGraph
from skyroute.roadmap.visibility_cache import graph_key, graph_path
from tests.conftest import SHARED
from tests.roadmap.test_visibility import rect_world

CITY = SHARED / "fcnd" / "colliders.csv"


def world_of(polys, boundary=None):
    n = len(polys)
    return World(np.array(polys, dtype=object), np.full(n, -np.inf), np.full(n, np.inf), (),
                 boundary, "enu")


def brute_force(world, s, t):
    return brute_force_pairs(world, [(s, t)])[0]


def brute_force_pairs(world, pairs):
    """Shortest lengths for (s, t) pairs: every vertex of the union and every point, every
    pair of them tested with shapely's DE-9IM relate, scipy's Dijkstra: nothing of
    skyroute's geometry."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    union = shapely.unary_union(world.obstacles)
    verts = shapely.get_coordinates(shapely.get_rings(shapely.get_parts(union)))
    pts = np.vstack([np.reshape(pairs, (-1, 2)), np.unique(verts, axis=0)])
    i, j = np.triu_indices(len(pts), 1)
    lines = shapely.linestrings(np.stack([pts[i], pts[j]], axis=1))
    ok = ~shapely.relate_pattern(union, lines, "T********")
    w = np.hypot(*(pts[j] - pts[i]).T)[ok] + 1e-300
    g = coo_matrix((w, (i[ok], j[ok])), shape=(len(pts), len(pts))).tocsr()
    k = 2 * np.arange(len(pairs))
    return dijkstra(g, directed=False, indices=k)[np.arange(len(pairs)), k + 1]


def assert_path_free(world, path):
    union = shapely.unary_union(world.obstacles)
    lines = shapely.linestrings(np.stack([path[:-1], path[1:]], axis=1))
    assert not shapely.relate_pattern(union, lines, "T********").any()


# -- the compiled sight test ------------------------------------------------------------

coord = st.integers(-4, 4).map(lambda v: v * 0.1)  # decimal, not binary: near-degenerate


@st.composite
def lattice_worlds(draw):
    """Boxes on a 0.1 lattice (whose points are not exact binary numbers: collinear in
    decimal, within rounding in binary) and segments between their corners and points."""
    boxes = []
    for _ in range(draw(st.integers(1, 5))):
        x, y = draw(coord), draw(coord)
        boxes.append((x, y, x + draw(st.integers(1, 3)) * 0.1, y + draw(st.integers(1, 3)) * 0.1))
    return boxes, [((draw(coord), draw(coord)), (draw(coord), draw(coord)))
                   for _ in range(20)]


# two boxes meeting along x = 0.4 over 4e-17 (0.2 against 0.1 + 0.1 + ...): their union's
# interior holds that sliver, whose ends gave one parameter along the segment (FREE)
PINCH = ([(0.4, 0.2, 0.5, 0.30000000000000004), (0.4, 0.4, 0.5, 0.5),
          (0.1, -0.1, 0.4, 0.20000000000000004)], [((0.4, -0.1), (0.4, 0.5))])


@settings(max_examples=80, deadline=None)
@given(lattice_worlds())
@example(PINCH)
def test_sight_test_agrees_with_shapely(case):
    boxes, segs = case
    world = rect_world(boxes).merged()
    segs = [(s, t) for s, t in segs if world.is_free([s, t]).all()]  # ends in no obstacle
    corners = shapely.get_coordinates(world.obstacles)
    a = np.array([s for s, _ in segs] + list(corners[:-1]), dtype=float).reshape(-1, 2)
    b = np.array([t for _, t in segs] + list(corners[1:][::-1]), dtype=float).reshape(-1, 2)
    index = sk.edge_index(world.obstacles)
    codes = sk.segment_codes(a, b, *index.args(), *sk.scratch(index))
    ref = world.segments_free(a, b)
    sure = codes != sk.UNSURE
    np.testing.assert_array_equal(codes[sure] == sk.FREE, ref[sure])
    np.testing.assert_array_equal(VisibilityGraph(world, cache=False).free(a, b), ref)


def test_sight_test_settles_almost_every_segment_of_a_random_world():
    from skyroute.bench.world import random_rect_world

    world = random_rect_world(3).merged()
    pts = np.random.default_rng(0).uniform(0, 100, size=(6000, 2))
    pts = pts[world.is_free(pts)][:4000]  # the test's contract: ends in no obstacle
    a, b = pts[:2000], pts[2000:]
    index = sk.edge_index(world.obstacles)
    codes = sk.segment_codes(a, b, *index.args(), *sk.scratch(index))
    sure = codes != sk.UNSURE
    assert sure.mean() > 0.99  # shapely is asked only within rounding of a touch
    np.testing.assert_array_equal(codes[sure] == sk.FREE, world.segments_free(a, b)[sure])


@settings(max_examples=200, deadline=None)
@given(st.lists(st.integers(-30, 30).map(lambda v: v / 10 + 100.0), min_size=6, max_size=6))
def test_exact_sign_matches_fractions(v):
    ax, ay, bx, by, cx, cy = v
    exact = (Fraction(bx) - Fraction(ax)) * (Fraction(cy) - Fraction(ay)) - \
        (Fraction(by) - Fraction(ay)) * (Fraction(cx) - Fraction(ax))
    assert sk._exact_sign(ax, ay, bx, by, cx, cy) == (exact > 0) - (exact < 0)


# -- costs against the brute force ------------------------------------------------------

@st.composite
def rotated_worlds(draw):
    """Up to 6 rotated rectangles and triangles (no axis-parallel edges) and two points."""
    polys = []
    for _ in range(draw(st.integers(1, 6))):
        cx, cy = draw(st.floats(0, 20)), draw(st.floats(0, 20))
        ang = draw(st.floats(0.1, 1.4))
        if draw(st.booleans()):
            p = shapely.box(-draw(st.floats(0.5, 4)), -draw(st.floats(0.5, 4)), 1, 1)
        else:
            p = shapely.Polygon([(0, 0), (draw(st.floats(1, 5)), 0), (0, draw(st.floats(1, 5)))])
        polys.append(shapely.affinity.translate(shapely.affinity.rotate(p, ang, use_radians=True),
                                                cx, cy))
    pt = st.tuples(st.floats(-3, 23), st.floats(-3, 23))
    s, t = draw(pt), draw(pt)
    if draw(st.booleans()):  # through the first obstacle, from beyond the others: a path
        # that bends (points anywhere: 32 of 40 were a straight segment, start == goal or
        # in an obstacle)
        c = polys[0].representative_point()
        s, t = (draw(st.floats(-6, -4)), c.y), (draw(st.floats(25, 27)), c.y)
    assume(s != t)
    return polys, s, t


@settings(max_examples=40, deadline=None)
@given(rotated_worlds())
def test_costs_match_brute_force_on_rotated_obstacles(case):
    polys, s, t = case
    world = world_of(polys)
    union = shapely.unary_union(world.obstacles)
    if union.contains(shapely.Point(s)) or union.contains(shapely.Point(t)):
        return
    expected = brute_force(world, s, t)
    r = VisibilityGraph(world, cache=False).plan(s, t)
    if np.isinf(expected):
        assert r.status is Status.NO_PATH
    else:
        assert r.found and r.cost == pytest.approx(expected, rel=1e-9, abs=1e-9)
        assert r.cost == pytest.approx(np.hypot(*np.diff(r.path, axis=0).T).sum(), rel=1e-12)
        assert_path_free(world, r.path)


# -- no path across free regions --------------------------------------------------------

def courtyard():
    """A 10 x 10 block with a 4 x 4 courtyard and a box in it, and a box beside it."""
    block = shapely.box(0, 0, 10, 10).difference(shapely.box(3, 3, 7, 7))
    return world_of([block, shapely.box(4.5, 4.5, 5.5, 5.5), shapely.box(12, 0, 14, 4)])


def test_no_path_between_free_regions_is_answered_without_a_search():
    graph = VisibilityGraph(courtyard(), cache=False)
    assert len(set(graph.labels.tolist())) == 2  # the courtyard's box, the outside
    r = graph.plan((4, 4), (20, 20))  # courtyard -> outside
    assert r.status is Status.NO_PATH and r.expanded == 0
    r = graph.plan((15, 5), (6, 6))
    assert r.status is Status.NO_PATH and r.expanded == 0
    inside = graph.plan((4, 4), (6, 6))  # round the box in the courtyard
    assert inside.found and inside.cost == pytest.approx(2 * math.hypot(0.5, 1.5))
    out = graph.plan((-1, 5), (11, 5))  # round the block
    assert out.found and out.cost == pytest.approx(2 * math.hypot(1, 5) + 10)


def test_a_wall_across_the_boundary_splits_the_free_space():
    boundary = shapely.box(0, 0, 10, 10)
    world = world_of([shapely.box(4, -5, 6, 10), shapely.box(7, 2, 8, 3)], boundary)
    r = VisibilityGraph(world, cache=False).plan((2, 5), (9, 5))
    assert r.status is Status.NO_PATH and r.expanded == 0


def test_budget_is_a_status():
    world = rect_world([(1, -1, 3, 1), (5, -1, 7, 1), (9, -1, 11, 1)])
    r = VisibilityGraph(world, cache=False).plan((0, 0), (12, 0), max_expansions=1)
    assert r.status is Status.BUDGET_EXHAUSTED


# -- the disk cache ---------------------------------------------------------------------

def same_graph(a, b):
    for k in ("corners", "_prev", "_next", "_indptr", "_indices", "_weights", "labels"):
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k))
    assert a.world.names == b.world.names
    assert shapely.equals(a.world.obstacles, b.world.obstacles).all()


def test_cache_round_trip_and_stale_files(tmp_path, monkeypatch):
    monkeypatch.setenv("SKYROUTE_CACHE", str(tmp_path))
    world = courtyard()
    built = VisibilityGraph(world, cache=True)
    path = graph_path(graph_key(world))
    assert not built.from_cache and path.is_file()
    read = VisibilityGraph(world, cache=True)
    assert read.from_cache
    same_graph(built, read)
    q = ((-1, 5), (13, 6))
    assert read.plan(*q).cost == built.plan(*q).cost
    with pytest.raises(skyroute.QueryError, match="inside obstacle 'obstacle 0'"):
        read.plan((1, 1), (20, 20))  # names came back from the file
    assert not VisibilityGraph(world, cache=False).from_cache
    # a damaged file is ignored, rebuilt and overwritten
    path.write_bytes(b"not a zip file")
    again = VisibilityGraph(world, cache=True)
    assert not again.from_cache and VisibilityGraph(world, cache=True).from_cache
    # another world's graph under this world's name (a stale file) is ignored too
    other = world_of([shapely.box(0, 0, 1, 1)])
    VisibilityGraph(other, cache=True)
    graph_path(graph_key(other)).replace(path)
    stale = VisibilityGraph(world, cache=True)
    assert not stale.from_cache
    same_graph(stale, built)


def test_the_key_changes_with_safety_and_altitude(tmp_path):
    from skyroute.world.colliders import read_colliders

    text = "lat0 37.79, lon0 -122.39\nposX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n" \
           "0,0,10,5,5,10\n30,0,40,5,5,40\n"
    keys = {graph_key(read_colliders("c.csv", text=text, safety=s).at(a))
            for s, a in ((0, 5), (2, 5), (0, 25))}
    assert len(keys) == 3


# -- the FCND city ----------------------------------------------------------------------

@pytest.mark.shared_data
def test_city_cut_against_the_brute_force_and_a_no_path_pair():
    world = skyroute.load_world(CITY, altitude=5, safety=5, frame="enu")
    window = shapely.box(-250, -150, 50, 150)
    cut = world_of(list(world.obstacles[shapely.within(world.obstacles, window)]))
    graph = VisibilityGraph(cut, cache=False)
    assert len(graph.corners) > 80
    rng = np.random.default_rng(0)
    pts = rng.uniform([-250, -150], [50, 150], size=(40, 2))
    pairs = pts[cut.is_free(pts)][:12].reshape(-1, 2, 2)
    found = 0
    for (s, t), expected in zip(pairs, brute_force_pairs(cut, pairs), strict=True):
        r = graph.plan(s, t)
        if np.isinf(expected):
            assert r.status is Status.NO_PATH
        else:
            found += 1
            assert r.found and r.cost == pytest.approx(expected, rel=1e-9)
            assert_path_free(cut, r.path)
    assert found >= 4
    # the whole city: a point in a closed courtyard (a hole of the union, by shapely)
    # and one in the streets have no path, answered without a search
    street, yard = (-81.0, -315.0), (-205.0, 71.0)
    rings, part = shapely.get_rings(shapely.get_parts(shapely.unary_union(world.obstacles)),
                                    return_index=True)
    holes = shapely.polygons(rings[np.r_[False, part[1:] == part[:-1]]])  # not shells
    assert shapely.contains_xy(holes, *yard).sum() == 1
    assert not shapely.contains_xy(holes, *street).any()
    r = VisibilityGraph(world, cache=False).plan(street, yard)
    assert r.status is Status.NO_PATH and r.expanded == 0


# -- the size limit: refused before the pairs of corners are tested -----------------------

def row_of_boxes(n, gap=10.0):
    """``n`` 2 m boxes in a row (``gap`` apart: apart; 2: touching), named like a file."""
    polys = [shapely.box(gap * k, 0, gap * k + 2, 2) for k in range(n)]
    return World(np.array(polys, dtype=object), np.full(n, -np.inf), np.full(n, np.inf),
                 (), None, "enu", None, "city.csv")


def test_a_world_past_the_corner_limit_is_refused_before_its_pairs(monkeypatch):
    from skyroute.errors import OptionError
    from skyroute.roadmap import visibility

    def fail(*_args):
        pytest.fail("the pairs of corners were tested")

    monkeypatch.setattr(visibility, "MAX_CORNERS", 40)
    monkeypatch.setattr(visibility.sk, "corner_pairs", fail)
    tail = (" obstacle corners, over the limit of 40 for the visibility graph (built over "
            "every pair of them); plan with prm or on a grid (theta, astar), or plan at an "
            "altitude that keeps fewer obstacles")
    # 12 boxes apart: 48 corners, counted after the union (12 groups: at least 36)
    with pytest.raises(OptionError) as err:
        VisibilityGraph(row_of_boxes(12), cache=False)
    assert str(err.value) == "city.csv: 48" + tail and err.value.param == "algorithm"
    with pytest.raises(OptionError, match=r"^city\.csv: 48 obstacle corners"):
        visibility.check_size(row_of_boxes(12))
    # 14 apart are at least 42: refused without the union of the obstacles
    monkeypatch.setattr(World, "merged", fail)
    with pytest.raises(OptionError) as err:
        VisibilityGraph(row_of_boxes(14), cache=False)
    assert str(err.value) == "city.csv: at least 42" + tail
    # 30 touching boxes are one obstacle of 4 corners: built and planned on
    monkeypatch.undo()
    touching = row_of_boxes(30, gap=2.0)
    assert visibility.fewest_corners(touching) == 3
    assert skyroute.plan(touching, (-1.0, -1.0), (61.0, 3.0)).found


def test_the_corner_bound_is_a_lower_bound():
    from skyroute.roadmap.visibility import fewest_corners
    from skyroute.world.colliders import read_colliders
    from skyroute.world.geometry import convex_corners
    from skyroute.world.synth import synth_city

    for seed in range(3):
        text = synth_city(np.random.default_rng(seed), blocks=4)
        for safety in (0.0, 8.0):  # grown boxes touch and merge
            world = read_colliders("c.csv", text=text, safety=safety)
            assert 0 < fewest_corners(world) <= len(convex_corners(world.merged())[0])


@pytest.mark.shared_data
def test_the_fcnd_city_is_far_inside_the_limits():
    from skyroute.roadmap import visibility
    from skyroute.world import colliders
    from skyroute.world.geometry import convex_corners

    world = skyroute.load_world(CITY, frame="enu")
    assert len(world.obstacles) == 3845 and colliders.MAX_BOXES > 10 * 3845
    corners = len(convex_corners(world.merged())[0])
    assert visibility.fewest_corners(world) <= corners == 3347
    assert 2 * corners < visibility.MAX_CORNERS
    visibility.check_size(world)  # no error
