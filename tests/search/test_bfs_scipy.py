"""BFS step counts against scipy.sparse.csgraph on the 4-connected free-cell graph."""

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import shortest_path

import skyroute
from tests.search.checks import assert_grid_path_legal, free_cells


def four_connected_distances(blocked: np.ndarray, source: tuple[int, int]) -> np.ndarray:
    h, w = blocked.shape
    idx = np.arange(h * w).reshape(h, w)
    free = ~blocked
    rows, cols = [], []
    right = free[:, :-1] & free[:, 1:]
    down = free[:-1, :] & free[1:, :]
    rows += [idx[:, :-1][right], idx[:-1, :][down]]
    cols += [idx[:, 1:][right], idx[1:, :][down]]
    r, c = np.concatenate(rows), np.concatenate(cols)
    m = coo_matrix((np.ones(len(r)), (r, c)), shape=(h * w, h * w)).tocsr()
    d = shortest_path(m, directed=False, unweighted=True, indices=idx[source[1], source[0]])
    return d.reshape(h, w)


@pytest.mark.parametrize("seed", range(4))
def test_bfs_equals_scipy_on_random_grids(seed):
    rng = np.random.default_rng(seed)
    blocked = rng.random((40, 55)) < 0.3
    grid = skyroute.Grid(blocked)
    cells = free_cells(blocked)
    s = tuple(cells[rng.integers(len(cells))])
    dist = four_connected_distances(blocked, s)
    for t in cells[rng.choice(len(cells), 40, replace=False)]:
        r = skyroute.plan(grid, s, tuple(t), algorithm="bfs")
        expected = dist[t[1], t[0]]
        if np.isinf(expected):
            assert r.status is skyroute.Status.NO_PATH and np.isinf(r.cost)
        else:
            assert r.found and r.cost == expected
            assert assert_grid_path_legal(blocked, r.path, connectivity=4) == expected


def test_bfs_equals_scipy_on_a_real_map():
    grid = skyroute.load_map("den312d")
    cells = free_cells(grid.blocked)
    rng = np.random.default_rng(7)
    s = tuple(cells[0])
    dist = four_connected_distances(grid.blocked, s)
    for t in cells[rng.choice(len(cells), 30, replace=False)]:
        r = skyroute.plan(grid, s, tuple(t), algorithm="bfs")
        expected = dist[t[1], t[0]]
        assert (r.cost == expected) if r.found else np.isinf(expected)
