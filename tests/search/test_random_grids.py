"""A*, JPS and Dijkstra on random grids with scattered obstacles against scipy's Dijkstra
(an independent solver) on the same move graph: the canonical-successor pruning, the
equal-f stack and JPS's diagonal jumps must never change an optimal cost."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import skyroute
from skyroute.bench.random_maps import far_queries, random_grid
from skyroute.search.canonical import CANONICAL, EVERY, START
from skyroute.search.jps import fill
from skyroute.search.moves import MOVES
from tests.search.checks import assert_grid_path_legal, grid_optimum, two_indices

ALGORITHMS = ("astar", "jps", "dijkstra")


@st.composite
def cluttered_query(draw):
    """A grid of 6-40 cells a side with 10-40% blocked; start and goal free cells, often
    beside a wall (where forced neighbours and the pruning rules matter)."""
    w, h = draw(st.integers(6, 40)), draw(st.integers(6, 40))
    share = draw(st.floats(0.1, 0.4))
    seed = draw(st.integers(0, 2**32 - 1))
    blocked = np.random.default_rng(seed).random((h, w)) < share
    free = np.argwhere(~blocked)
    if len(free) < 2:
        blocked[0, 0] = blocked[-1, -1] = False
        free = np.argwhere(~blocked)
    padded = np.pad(blocked, 1, constant_values=True)
    walled = [i for i, (y, x) in enumerate(free) if padded[y:y + 3, x:x + 3].any()]
    pool = walled if len(walled) >= 2 and draw(st.booleans()) else range(len(free))
    i, j = two_indices(draw, len(pool))  # start != goal (one index twice before: 53%)
    s, t = free[pool[i]], free[pool[j]]
    return blocked, (int(s[1]), int(s[0])), (int(t[1]), int(t[0]))


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(cluttered_query())
def test_costs_equal_scipy_dijkstra_and_paths_are_legal(q):
    blocked, s, t = q
    optimum = grid_optimum(blocked, s, t)
    grid = skyroute.Grid(blocked)
    for algorithm in ALGORITHMS:
        r = skyroute.plan(grid, s, t, algorithm=algorithm)
        if np.isinf(optimum):
            assert r.status is skyroute.Status.NO_PATH, algorithm
            continue
        assert r.found and abs(r.cost - optimum) < 1e-9, (algorithm, r.cost, optimum)
        assert tuple(r.path[0]) == s and tuple(r.path[-1]) == t
        assert abs(assert_grid_path_legal(blocked, r.path) - r.cost) < 1e-9


@pytest.mark.parametrize("share", [0.1, 0.2, 0.3, 0.4])
def test_far_queries_on_a_cluttered_map_match_scipy(share):
    # long queries: many heap levels, equal-f stacks and jumps of every length
    grid = random_grid(128, share, seed=11)
    scen = far_queries(grid, 6, seed=11)
    for s, t, opt in zip(scen.starts, scen.goals, scen.optimal, strict=True):
        # the scenario's optima come from skyroute.bench's graph: checked apart here
        assert opt == pytest.approx(grid_optimum(grid.blocked, s, t), abs=1e-9)
        for algorithm in ALGORITHMS:
            r = skyroute.plan(grid, tuple(s.tolist()), tuple(t.tolist()), algorithm=algorithm)
            assert r.found and r.cost == pytest.approx(opt, abs=1e-9), (algorithm, share)
            assert_grid_path_legal(grid.blocked, r.path)


def test_budget_and_no_path_still_reported():
    grid = random_grid(64, 0.3, seed=2)
    scen = far_queries(grid, 1, seed=2)
    s, t = tuple(scen.starts[0].tolist()), tuple(scen.goals[0].tolist())
    for algorithm in ALGORITHMS:
        r = skyroute.plan(grid, s, t, algorithm=algorithm, max_expansions=5)
        assert r.status is skyroute.Status.BUDGET_EXHAUSTED and r.expanded == 5
    walled = grid.blocked.copy()
    walled[:, 30] = True  # a wall across the map
    a, b = (5, 5), (60, 60)
    walled[5, 5] = walled[60, 60] = False
    for algorithm in ALGORITHMS:
        assert skyroute.plan(skyroute.Grid(walled), a, b, algorithm=algorithm).status \
            is skyroute.Status.NO_PATH


def bits(*moves):
    return sum(1 << MOVES.index(m) for m in moves)


def test_canonical_successors_literal():
    everything = 0xFF
    east, northeast = MOVES.index((1, 0)), MOVES.index((1, 1))
    # in the open: straight keeps its direction, diagonal adds its two straight parts
    assert CANONICAL[east, everything] == bits((1, 0))
    assert CANONICAL[northeast, everything] == bits((1, 0), (0, 1), (1, 1))
    assert CANONICAL[START, everything] == everything
    # entered eastwards with the cell up-left of it blocked: that diagonal move is
    # illegal, which forces the step up and the diagonal up-right
    blocked_behind = everything & ~bits((-1, -1))
    assert CANONICAL[east, blocked_behind] == bits((1, 0), (0, -1), (1, -1))
    # never a move the mask forbids; without the canonical rule, every legal move
    assert all(int(CANONICAL[k, m]) & ~m == 0 for k in range(9) for m in range(256))
    assert all(EVERY[k, m] == m for k in range(9) for m in range(256))


def test_fill_walks_diagonal_first_legs():
    Wp = 10  # flat index = y * 10 + x
    points = np.array([0, 3 * Wp + 5, 3 * Wp + 5 + 2 * Wp], np.int64)  # (0,0) (5,3) (5,5)
    cells = [(int(c % Wp), int(c // Wp)) for c in fill(points, Wp)]
    assert cells == [(0, 0), (1, 1), (2, 2), (3, 3), (4, 3), (5, 3), (5, 4), (5, 5)]
