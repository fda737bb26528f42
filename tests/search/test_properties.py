"""Hypothesis: invariants on random grids."""

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import skyroute
from tests.search.checks import (
    assert_any_angle_path_legal,
    assert_grid_path_legal,
    grid_optimum,
    two_indices,
)

SETTINGS = settings(max_examples=150, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow])


@st.composite
def grid_query(draw):
    h = draw(st.integers(1, 14))
    w = draw(st.integers(1, 14))
    # every cell drawn (fill=nothing; with a fill most grids were all blocked or all
    # free), a quarter of them blocked (at a half most queries were no_path)
    blocked = draw(arrays(np.bool_, (h, w), elements=st.integers(0, 3).map(lambda v: v == 3),
                          fill=st.nothing()))
    free = np.argwhere(~blocked)
    if len(free) < 2:  # two free cells (one on a 1 x 1 grid)
        blocked[0, 0] = blocked[-1, -1] = False
        free = np.argwhere(~blocked)
    i, j = two_indices(draw, len(free))  # start != goal but on a 1 x 1 grid
    s, t = free[i], free[j]
    return blocked, (int(s[1]), int(s[0])), (int(t[1]), int(t[0]))


@SETTINGS
@given(grid_query())
def test_astar_dijkstra_jps_agree_and_paths_are_legal(q):
    blocked, s, t = q
    grid = skyroute.Grid(blocked)
    results = {a: skyroute.plan(grid, s, t, algorithm=a) for a in ("astar", "dijkstra", "jps")}
    optimum = grid_optimum(blocked, s, t)  # scipy: the three agreeing is not enough
    for r in results.values():
        if np.isinf(optimum):
            assert r.status is skyroute.Status.NO_PATH and np.isinf(r.cost)
        else:
            assert r.found and abs(r.cost - optimum) < 1e-9
            assert abs(assert_grid_path_legal(blocked, r.path) - r.cost) < 1e-9
            assert tuple(r.path[0]) == s and tuple(r.path[-1]) == t


@SETTINGS
@given(grid_query())
def test_four_connected_bfs_equals_astar_and_dijkstra(q):
    blocked, s, t = q
    grid = skyroute.Grid(blocked)
    b = skyroute.plan(grid, s, t, algorithm="bfs")
    a = skyroute.plan(grid, s, t, connectivity=4)
    d = skyroute.plan(grid, s, t, algorithm="dijkstra", connectivity=4)
    assert b.status is a.status is d.status
    optimum = grid_optimum(blocked, s, t, connectivity=4)
    assert b.found == np.isfinite(optimum)
    if b.found:
        assert b.cost == a.cost == d.cost == optimum
        for r in (b, a, d):
            assert assert_grid_path_legal(blocked, r.path, connectivity=4) == r.cost


@SETTINGS
@given(grid_query(), st.sampled_from(["collinear", "los"]),
       st.sampled_from(["astar", "jps", "theta", "lazy_theta"]))
def test_pruning_keeps_paths_legal_and_never_longer(q, prune, algorithm):
    blocked, s, t = q
    grid = skyroute.Grid(blocked)
    raw = skyroute.plan(grid, s, t, algorithm=algorithm)
    pruned = skyroute.plan(grid, s, t, algorithm=algorithm, prune=prune)
    assert raw.status is pruned.status
    if raw.found:
        assert pruned.cost <= raw.cost + 1e-9
        assert_any_angle_path_legal(blocked, pruned.path)
        assert tuple(pruned.path[0]) == s and tuple(pruned.path[-1]) == t
        # pruned points are a subsequence of the raw path
        raw_pts = [tuple(p) for p in raw.path]
        k = 0
        for p in map(tuple, pruned.path):
            k = raw_pts.index(p, k) + 1
        if prune == "collinear":
            assert abs(pruned.cost - raw.cost) < 1e-9


@SETTINGS
@given(grid_query())
def test_any_angle_never_longer_than_astar(q):
    blocked, s, t = q
    grid = skyroute.Grid(blocked)
    a = skyroute.plan(grid, s, t)
    for algorithm in ("theta", "lazy_theta"):
        r = skyroute.plan(grid, s, t, algorithm=algorithm)
        assert r.status is a.status
        if r.found:
            assert r.cost <= a.cost + 1e-9
            assert abs(assert_any_angle_path_legal(blocked, r.path) - r.cost) < 1e-9


@SETTINGS
@given(grid_query(), st.floats(1.0, 3.0))
def test_weighted_astar_is_bounded(q, w):
    blocked, s, t = q
    grid = skyroute.Grid(blocked)
    a = skyroute.plan(grid, s, t)
    r = skyroute.plan(grid, s, t, weight=w)
    assert r.status is a.status
    if r.found:
        assert a.cost - 1e-9 <= r.cost <= w * a.cost + 1e-9
        assert_grid_path_legal(blocked, r.path)
