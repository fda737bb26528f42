"""GridOptions: the cached hash keeps equal option sets interchangeable as dict keys."""

import pickle
from dataclasses import astuple

import numpy as np

import skyroute
from skyroute.search.grid_plan import GridOptions, grid_options
from skyroute.search.space import space_of


def test_equal_options_hash_alike():
    a = grid_options("astar", prune="los")
    b = GridOptions(*astuple(a))  # a second instance, not the lru_cache's
    assert a is not b and a == b and hash(a) == hash(b)
    assert {a: 1}[b] == 1
    assert grid_options("jps") != a and hash(grid_options("jps")) != hash(a)


def test_pickled_options_hash_anew():
    a = grid_options("theta", weight=1.5)
    data = pickle.dumps(a)
    # string hashes differ between processes: a pickled hash would be stale in another
    assert b"_hash" not in data
    b = pickle.loads(data)
    assert b == a and hash(b) == hash(a) and {a: 1}[b] == 1


def test_one_runner_per_option_set():
    grid = skyroute.Grid(np.zeros((6, 6), bool))
    first = skyroute.plan(grid, (0, 0), (5, 3), prune="los")
    again = skyroute.plan(grid, (0, 0), (5, 3), prune="los")
    assert "setup_seconds" in first.extra and "setup_seconds" not in again.extra
    assert list(space_of(grid).runners) == [grid_options("astar", prune="los")]
    assert again.path.tolist() == first.path.tolist() == [[0, 0], [5, 3]]
    assert again.cost == first.cost == np.hypot(5, 3)
