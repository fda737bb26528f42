"""GridOptions: equal option sets are interchangeable as dict keys, in this process and
after pickling; a grid keeps one query call per option set; a conflict names its
option."""

import pickle
import re
from dataclasses import astuple

import numpy as np
import pytest

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
    opts = grid_options("astar", prune="los")
    assert [entry[0] for entry in space_of(grid).runners.values()] == [opts]
    assert list(space_of(grid).runners) == [id(opts)]
    assert again.path.tolist() == first.path.tolist() == [[0, 0], [5, 3]]
    assert again.cost == first.cost == np.hypot(5, 3)


def test_a_cached_option_set_does_not_admit_equal_values_of_another_type():
    grid = skyroute.Grid(np.zeros((4, 4), bool))
    skyroute.plan(grid, (0, 0), (3, 3), max_expansions=5)
    skyroute.plan(grid, (0, 0), (3, 3), max_expansions=1)
    for bad in (5.0, True):  # equal to 5 and 1, so an untyped cache would hand those back
        with pytest.raises(skyroute.OptionError, match="must be an integer"):
            skyroute.plan(grid, (0, 0), (3, 3), max_expansions=bad)


def test_equal_option_sets_share_one_runner():
    from skyroute.search.grid_plan import plan_grid

    grid = skyroute.Grid(np.zeros((6, 6), bool))
    first = plan_grid(grid, (0, 0), (5, 3), grid_options("astar", max_expansions=7))
    for other in (pickle.loads(pickle.dumps(grid_options("astar", max_expansions=7))),
                  GridOptions(*astuple(grid_options("astar", max_expansions=7)))):
        again = plan_grid(grid, (0, 0), (5, 3), other)
        assert "setup_seconds" not in again.extra  # the runner of the equal set
        assert again.cost == first.cost
    assert len(space_of(grid).runners) == 1
    w2, w20 = grid_options("astar", weight=2), grid_options("astar", weight=2.0)
    assert w2 is w20  # the typed cache made two, the canonical set is one


def test_clearing_caches_does_not_pile_up_finalizers():
    import weakref

    grid = skyroute.Grid(np.zeros((4, 4), bool))
    before = len(weakref.finalize._registry)
    for _ in range(50):
        skyroute.clear_caches()
        skyroute.plan(grid, (0, 0), (3, 3))
    assert len(weakref.finalize._registry) - before <= 1


@pytest.mark.parametrize("kwargs,param", [
    ({"connectivity": np.array([8])}, "connectivity"),
    ({"corner_cutting": np.array([True, False])}, "corner_cutting"),
    ({"corner_cutting": "yes"}, "corner_cutting"),
    ({"prune": np.array(["los"])}, "prune"),
    ({"heuristic": np.array(["octile"])}, "heuristic")])
def test_array_options_are_option_errors(kwargs, param):
    g = skyroute.Grid(np.zeros((3, 3), bool))
    with pytest.raises(skyroute.OptionError) as err:
        skyroute.plan(g, (0, 0), (2, 2), **kwargs)
    assert err.value.param == param


def test_numpy_scalars_are_options_like_their_values():
    g = skyroute.Grid(np.zeros((3, 3), bool))
    r = skyroute.plan(g, (0, 0), (2, 2), connectivity=np.int64(4), prune=np.str_("collinear"),
                      corner_cutting=np.bool_(False))
    assert r.found and r.cost == 4


@pytest.mark.parametrize("budget", [2**63, 2**64, np.uint64(2**64 - 1)])
def test_a_budget_beyond_int64_means_no_budget(budget):
    g = skyroute.Grid(np.zeros((3, 3), bool))
    assert grid_options(max_expansions=budget).max_expansions == np.iinfo(np.int64).max
    assert skyroute.plan(g, (0, 0), (2, 2), max_expansions=budget).found


def test_results_compare_by_identity_and_hash():
    g = skyroute.Grid(np.zeros((3, 3), bool))
    a, b = skyroute.plan(g, (0, 0), (2, 2)), skyroute.plan(g, (0, 0), (2, 2))
    assert a == a and a != b and len({a, b}) == 2  # used to raise on the path arrays


@pytest.mark.parametrize("options, param", [
    ({"algorithm": "dijkstra", "weight": 2}, "weight"),
    ({"algorithm": "bfs", "weight": 2}, "weight"),
    ({"algorithm": "astar", "weight": 0.5}, "weight"),
    ({"algorithm": "bfs", "heuristic": "octile"}, "heuristic"),
    ({"algorithm": "bfs", "connectivity": 8}, "connectivity"),
    ({"algorithm": "jps", "weight": 2}, "weight"),
    ({"algorithm": "jps", "heuristic": "manhattan"}, "heuristic"),
    ({"algorithm": "jps", "connectivity": 4}, "connectivity"),
    ({"algorithm": "jps", "corner_cutting": True}, "corner_cutting"),
    ({"algorithm": "astar", "max_expansions": -1}, "max_expansions"),
    ({"algorithm": "astar", "connectivity": 4, "corner_cutting": True}, "corner_cutting"),
    ({"algorithm": "bfs", "corner_cutting": True}, "corner_cutting"),
])
def test_an_option_conflict_names_the_option(options, param):
    with pytest.raises(skyroute.OptionError) as info:
        grid_options(**options)
    at_fault = info.value.param  # first; then the others its message names, if any
    assert (at_fault if isinstance(at_fault, str) else at_fault[0]) == param
    for name in re.findall(r"\b(\w+)=", str(info.value)):
        assert name in ((at_fault,) if isinstance(at_fault, str) else at_fault), name


@pytest.mark.parametrize("weight", [np.float32(1.5), np.int64(2), np.array(1.5)])
def test_numpy_weights_are_numbers(weight):
    # np.float32, np.int64 and 0-d arrays were refused as "must be a number >= 1"
    grid = skyroute.load_map("den312d")
    r = skyroute.plan(grid, (50, 76), (60, 13), weight=weight)
    assert r.found and r.cost <= float(weight) * 112.55634919 + 1e-9


def test_a_bool_weight_is_refused():
    with pytest.raises(skyroute.OptionError, match="weight=True"):
        skyroute.plan(skyroute.load_map("den312d"), (50, 76), (60, 13), weight=True)


@pytest.mark.parametrize("option", [{"seed": 3}, {"resolution": 2.0}, {"samples": 50},
                                    {"neighbours": 4}, {"prm_star": True}])
def test_world_options_on_a_grid_are_refused(option):
    # they were ignored without a word: a grid is searched as it is
    (name, _), = option.items()
    with pytest.raises(skyroute.OptionError, match=f"{name}=") as err:
        skyroute.plan(skyroute.load_map("den312d"), (50, 76), (60, 13), **option)
    assert err.value.param == name


@pytest.mark.parametrize("grid", [np.zeros((4, 5), bool), [[0, 1], [0, 0]]])
def test_an_array_is_refused_with_how_to_wrap_it(grid):
    # a researcher's first try, plan(array, ...), said only "got ndarray"
    with pytest.raises(skyroute.OptionError, match=r"skyroute\.Grid\(array\)"):
        skyroute.plan(grid, (0, 0), (1, 1))
    assert skyroute.plan(skyroute.Grid(np.asarray(grid, bool)), (0, 0), (1, 1)).found
