"""Hypothesis: the Python API's contract on random small grids, as a notebook meets it.

- Every move rule (4- or 8-connected, corner cutting or not) and every cell-by-cell
  algorithm that takes it: the cost is scipy's shortest path on the same move graph, the
  path walks it cell by cell (connected, never on or past a blocked cell's corner), and
  the algorithms agree (test_properties.py covers the default rule only).
- ``prepare(grid).plan`` answers as ``plan(grid)``: status, cost, endpoints and result
  shape, for both index kinds.
- The same grid and query given in other types (numpy integers or floats, Fortran order,
  a strided view; cells as lists, numpy integers or arrays) give the same answer.
"""

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import skyroute
from skyroute import Status
from tests.search.checks import assert_grid_path_legal, grid_optimum, two_indices

SETTINGS = settings(max_examples=100, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow])
RULES = [(4, False), (8, False), (8, True)]  # 4-connected: corner cutting means nothing


def algorithms_of(connectivity: int, corner_cutting: bool) -> tuple[str, ...]:
    """The cell-by-cell algorithms that search under a move rule."""
    if connectivity == 4:
        return "astar", "dijkstra", "bfs"
    return ("astar", "dijkstra") if corner_cutting else ("astar", "dijkstra", "jps")


@st.composite
def queries(draw, *, side=12):
    """A grid of 1-``side`` cells a side, a fifth to a half blocked, and two free cells
    (x, y), distinct unless the grid has one free cell."""
    h, w = draw(st.integers(1, side)), draw(st.integers(1, side))
    share = draw(st.sampled_from([0.2, 0.3, 0.4, 0.5]))
    blocked = np.random.default_rng(draw(st.integers(0, 2**32 - 1))).random((h, w)) < share
    free = np.argwhere(~blocked)
    if len(free) < 2:
        blocked[0, 0] = blocked[-1, -1] = False
        free = np.argwhere(~blocked)
    i, j = two_indices(draw, len(free))
    (sy, sx), (ty, tx) = free[i], free[j]
    return blocked, (int(sx), int(sy)), (int(tx), int(ty))


def assert_result_shape(r: skyroute.PlanResult) -> None:
    """One result shape for every planner and every ending."""
    assert isinstance(r, skyroute.PlanResult) and isinstance(r.status, Status)
    assert r.path.dtype == np.float64 and r.path.ndim == 2 and r.path.shape[1] == 2
    assert type(r.cost) is float and type(r.expanded) is int
    assert type(r.max_frontier) is int and type(r.los_checks) is int
    assert r.path_lonlat is None and isinstance(r.extra, dict)
    if r.found:
        assert len(r.path) >= 1 and math.isfinite(r.cost)
    else:
        assert r.path.shape == (0, 2) and r.cost == math.inf
        assert r.to_dict()["cost"] is None and r.to_dict()["path"] == []


@SETTINGS
@given(queries(), st.sampled_from(RULES))
def test_every_move_rule_costs_scipy_s_optimum_with_legal_paths(q, rule):
    blocked, s, t = q
    connectivity, corner_cutting = rule
    grid = skyroute.Grid(blocked)
    optimum = grid_optimum(blocked, s, t, connectivity=connectivity,
                           corner_cutting=corner_cutting)
    for algorithm in algorithms_of(*rule):
        r = skyroute.plan(grid, s, t, algorithm=algorithm, connectivity=connectivity,
                          corner_cutting=corner_cutting)
        assert_result_shape(r)
        assert r.algorithm == algorithm
        if math.isinf(optimum):
            assert r.status is Status.NO_PATH, algorithm
            continue
        assert r.found and r.cost == pytest.approx(optimum, abs=1e-9), (algorithm, rule)
        assert tuple(r.path[0]) == s and tuple(r.path[-1]) == t
        walked = assert_grid_path_legal(blocked, r.path, connectivity=connectivity,
                                        corner_cutting=corner_cutting)
        assert walked == pytest.approx(r.cost, abs=1e-9)


@SETTINGS
@given(queries(side=16), st.sampled_from(["subgoal", "jump"]))
def test_a_prepared_grid_answers_as_plan(q, method):
    blocked, s, t = q
    grid = skyroute.Grid(blocked)
    want = skyroute.plan(grid, s, t)
    got = skyroute.prepare(grid, method=method).plan(s, t)
    assert_result_shape(got)
    assert got.status is want.status and got.algorithm == method
    if want.found:
        # equal costs, maybe another of the equally short paths
        assert got.cost == pytest.approx(want.cost, abs=1e-9)
        assert tuple(got.path[0]) == s and tuple(got.path[-1]) == t
        assert assert_grid_path_legal(blocked, got.path) == pytest.approx(got.cost, abs=1e-9)


def _as_other_types(blocked: np.ndarray, kind: int) -> np.ndarray | list:
    """``blocked`` in another of the forms a caller may hold it in."""
    if kind == 0:
        return blocked.astype(np.int8)
    if kind == 1:
        return np.asfortranarray(blocked.astype(np.float32) * 3.5)
    if kind == 2:  # a strided view of a larger array
        wide = np.zeros((blocked.shape[0], 2 * blocked.shape[1]), np.uint8)
        wide[:, ::2] = blocked
        return wide[:, ::2]
    return blocked.astype(int).tolist()


def _cell_as(cell: tuple[int, int], kind: int):
    return ([cell[0], cell[1]], (np.int64(cell[0]), np.int32(cell[1])),
            np.array(cell, np.uint16), cell)[kind]


@SETTINGS
@given(queries(), st.integers(0, 3), st.integers(0, 3),
       st.sampled_from(["astar", "jps", "bfs", "theta"]))
def test_the_same_query_in_other_types_gives_the_same_answer(q, grid_kind, cell_kind,
                                                             algorithm):
    blocked, s, t = q
    want = skyroute.plan(skyroute.Grid(blocked), s, t, algorithm=algorithm)
    other = skyroute.Grid(_as_other_types(blocked, grid_kind))
    assert np.array_equal(other.blocked, blocked)
    got = skyroute.plan(other, _cell_as(s, cell_kind), _cell_as(t, cell_kind),
                        algorithm=algorithm)
    assert got.status is want.status and got.cost == want.cost
    assert np.array_equal(got.path, want.path)
