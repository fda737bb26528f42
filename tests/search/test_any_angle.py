"""Theta* and Lazy Theta*: every segment legal under an independent exact checker (and
shapely), and the cost never above A*'s (and networkx's optimum for every move rule)."""

import itertools
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import skyroute
from skyroute.search.los import line_of_sight
from skyroute.search.space import space_of
from skyroute.world.movingai import read_scen
from tests.search.checks import assert_any_angle_path_legal, segment_legal, two_indices

ANY_ANGLE = ("theta", "lazy_theta")


def test_checker_knows_squeezes_and_corner_touches():
    c = np.zeros((3, 3), bool)
    c[0, 1] = c[1, 0] = True
    assert not segment_legal(c, (0, 0), (2, 2))  # squeeze through (1, 1)
    d = np.zeros((3, 3), bool)
    d[0, 1] = True
    assert segment_legal(d, (0, 0), (2, 2))  # touching one corner is allowed
    e = np.zeros((3, 5), bool)
    e[1, 2] = True
    assert not segment_legal(e, (0, 1), (4, 1))  # straight through a blocked cell
    assert segment_legal(e, (0, 0), (4, 0))


@pytest.mark.parametrize("algorithm", ANY_ANGLE)
def test_open_field_is_one_straight_segment(algorithm):
    grid = skyroute.Grid(np.zeros((20, 30), bool))
    r = skyroute.plan(grid, (1, 2), (27, 15), algorithm=algorithm)
    assert r.found and len(r.path) == 2
    assert r.cost == pytest.approx(math.hypot(26, 13), rel=1e-12)


@pytest.mark.parametrize("algorithm", ANY_ANGLE)
@pytest.mark.parametrize("seed", range(6))
def test_random_grids_legal_and_not_longer_than_astar(algorithm, seed):
    rng = np.random.default_rng(seed)
    blocked = rng.random((35, 45)) < 0.25
    grid = skyroute.Grid(blocked)
    ys, xs = np.nonzero(~blocked)
    for _ in range(25):
        i, j = rng.integers(len(xs), size=2)
        s, t = (xs[i], ys[i]), (xs[j], ys[j])
        a = skyroute.plan(grid, s, t)
        r = skyroute.plan(grid, s, t, algorithm=algorithm)
        assert r.status is a.status
        if r.found:
            length = assert_any_angle_path_legal(blocked, r.path)
            assert length == pytest.approx(r.cost, rel=1e-9)
            assert r.cost <= a.cost + 1e-9
            assert r.los_checks > 0 or len(r.path) <= 2


@pytest.mark.parametrize("algorithm", ANY_ANGLE)
def test_real_map_legal_and_shorter(algorithm):
    grid = skyroute.load_map("den312d")
    scen = read_scen(skyroute.bundled_maps()["den312d"].with_suffix(".map.scen"))
    for i in range(0, len(scen), 15):
        s, t = tuple(scen.starts[i]), tuple(scen.goals[i])
        r = skyroute.plan(grid, s, t, algorithm=algorithm)
        assert r.found
        assert_any_angle_path_legal(grid.blocked, r.path)
        assert r.cost <= scen.optimal[i] + 1e-6


# -- against shapely and networkx, across the move rules -------------------------------

def shapely_sight(blocked: np.ndarray):
    """Line of sight between cell centres by shapely, nothing of skyroute's: illegal when
    the segment meets the interior of the union of the blocked unit squares, or passes
    through a grid vertex where two diagonal blocked cells touch (the docs' squeeze)."""
    import shapely

    ys, xs = np.nonzero(blocked)
    union = shapely.union_all(shapely.box(xs, ys, xs + 1, ys + 1))
    b = np.pad(blocked, 1)
    pinch = (b[:-1, :-1] & b[1:, 1:] & ~b[:-1, 1:] & ~b[1:, :-1]) | \
        (b[:-1, 1:] & b[1:, :-1] & ~b[:-1, :-1] & ~b[1:, 1:])
    py, px = np.nonzero(pinch)  # vertex (px, py) in cell units
    points = shapely.multipoints(np.c_[px, py]) if len(px) else None

    def sees(a, c) -> bool:
        if tuple(a) == tuple(c):
            return not blocked[a[1], a[0]]
        line = shapely.LineString([(a[0] + .5, a[1] + .5), (c[0] + .5, c[1] + .5)])
        if not union.is_empty and shapely.relate_pattern(line, union, "T********"):
            return False
        return points is None or not line.intersects(points)
    return sees


def move_rule_optimum(blocked, s, t, connectivity, corner_cutting) -> float:
    """networkx's Dijkstra on the free cells under a move rule (docs/architecture.md)."""
    import networkx as nx

    h, w = blocked.shape
    g = nx.Graph()
    g.add_nodes_from([s, t])
    moves = [(1, 0), (0, 1)] + ([(1, 1), (1, -1)] if connectivity == 8 else [])
    for y, x in np.argwhere(~blocked):
        for dx, dy in moves:
            u, v = x + dx, y + dy
            if not (0 <= u < w and 0 <= v < h) or blocked[v, u]:
                continue
            sides = blocked[y, u], blocked[v, x]
            if dx and dy and (all(sides) if corner_cutting else any(sides)):
                continue
            g.add_edge((int(x), int(y)), (int(u), int(v)), weight=math.hypot(dx, dy))
    try:
        return nx.dijkstra_path_length(g, s, t)
    except nx.NetworkXNoPath:
        return math.inf


@st.composite
def rule_queries(draw):
    h, w = draw(st.integers(1, 12)), draw(st.integers(1, 12))
    odds = draw(st.sampled_from([2, 3, 4]))  # a half, a third or a quarter blocked
    blocked = draw(arrays(np.bool_, (h, w), fill=st.nothing(),
                          elements=st.integers(0, odds - 1).map(lambda v: v == 0)))
    free = np.argwhere(~blocked)
    if len(free) < 2:
        blocked[0, 0] = blocked[-1, -1] = False
        free = np.argwhere(~blocked)
    i, j = two_indices(draw, len(free))
    return blocked, (int(free[i][1]), int(free[i][0])), (int(free[j][1]), int(free[j][0]))


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(rule_queries())
def test_line_of_sight_is_shapely_s(q):
    blocked, s, _ = q
    space = space_of(skyroute.Grid(blocked))
    sees = shapely_sight(blocked)
    for c in map(tuple, np.argwhere(~blocked)[:, ::-1].tolist()):
        assert bool(line_of_sight(space.blocked, space.Wp, space.index(s), space.index(c))) \
            == sees(s, c), (s, c)


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(rule_queries(), st.sampled_from(ANY_ANGLE),
       st.sampled_from([(4, False), (8, False), (8, True)]),  # 4-connected: no corners
       st.sampled_from(["none", "collinear", "los"]))
def test_any_angle_on_every_move_rule(q, algorithm, rule, prune):
    # the existing properties ran the default rule only: 4-connected moves and corner
    # cutting too, against networkx's optimum for that rule; every segment seen by shapely
    blocked, s, t = q
    connectivity, corner_cutting = rule
    r = skyroute.plan(skyroute.Grid(blocked), s, t, algorithm=algorithm, prune=prune,
                      connectivity=connectivity, corner_cutting=corner_cutting)
    optimum = move_rule_optimum(blocked, s, t, connectivity, corner_cutting)
    assert r.found == math.isfinite(optimum)
    if r.found:
        path = [tuple(map(int, p)) for p in r.path]
        assert path[0] == s and path[-1] == t
        sees = shapely_sight(blocked)
        assert all(sees(a, b) for a, b in itertools.pairwise(path))
        assert r.cost == pytest.approx(sum(math.dist(a, b) for a, b in
                                           itertools.pairwise(path)), rel=1e-12, abs=1e-12)
        assert r.cost <= optimum + 1e-9
