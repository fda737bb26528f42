"""Every algorithm through the same battery of cases (as OMPL runs its planners)."""

import collections
import decimal
import re
import types

import numpy as np
import pytest

import skyroute
from skyroute import OptionError, QueryError, Status
from skyroute.roadmap.world_plan import WORLD_ALGORITHMS
from skyroute.search import GRID_ALGORITHMS
from tests.conftest import ROOT

ALGS = GRID_ALGORITHMS


def open_grid(h, w):
    return skyroute.Grid(np.zeros((h, w), bool))


@pytest.mark.parametrize("algorithm", ALGS)
def test_start_equals_goal(algorithm):
    r = skyroute.plan(open_grid(5, 5), (2, 3), (2, 3), algorithm=algorithm)
    assert r.status is Status.FOUND and r.cost == 0.0
    np.testing.assert_array_equal(r.path, [[2, 3]])


def _city(frame):
    return skyroute.load_world(ROOT / "examples" / "city.csv", altitude=10, frame=frame)


@pytest.mark.parametrize("where, algorithm", [
    *(("grid", a) for a in ALGS),
    *((frame, a) for frame in ("ned", "lonlat") for a in WORLD_ALGORITHMS)])
def test_start_equals_goal_is_one_point_everywhere(where, algorithm):
    # PlanResult: a path of (K, 2) points with cost its length. For start == goal the
    # grid planners and PRM gave one point, the visibility graph and the grid planners
    # on a World two (the same point twice, and so a waypoint heading north from nowhere)
    if where == "grid":
        space, point = open_grid(5, 5), (2, 3)
    else:
        space = _city(where)
        point = tuple(space.from_plane([[0.3, -0.7]])[0])  # free: between the buildings
    r = skyroute.plan(space, point, point, algorithm=algorithm)
    assert r.status is Status.FOUND and r.cost == 0.0, r
    np.testing.assert_array_equal(r.path, [point])
    if r.path_lonlat is not None:
        assert r.path_lonlat.shape == (1, 2)
    if where == "grid":
        from skyroute.io.geojson import grid_path_geojson

        line = grid_path_geojson(space, r)["features"][0]["geometry"]
    else:
        from skyroute.io.world_out import waypoints, world_path_geojson

        assert len(waypoints(space, r.path, 5.0)) == 1
        line = world_path_geojson(space, r)["features"][0]["geometry"]
    assert line["type"] == "LineString" and len(line["coordinates"]) == 2  # RFC 7946


@pytest.mark.parametrize("algorithm", ALGS)
def test_one_by_one_grid(algorithm):
    r = skyroute.plan(open_grid(1, 1), (0, 0), (0, 0), algorithm=algorithm)
    assert r.found and r.cost == 0.0 and r.path.shape == (1, 2)


@pytest.mark.parametrize("algorithm", ALGS)
@pytest.mark.parametrize("shape", [(1, 9), (9, 1)])
def test_one_by_n_grids(algorithm, shape):
    grid = open_grid(*shape)
    goal = (shape[1] - 1, shape[0] - 1)
    r = skyroute.plan(grid, (0, 0), goal, algorithm=algorithm)
    assert r.found and r.cost == pytest.approx(8.0)
    np.testing.assert_array_equal(r.path[0], [0, 0])
    np.testing.assert_array_equal(r.path[-1], goal)


@pytest.mark.parametrize("algorithm", ALGS)
def test_unreachable_goal_is_a_status(algorithm):
    b = np.zeros((5, 7), bool)
    b[:, 3] = True
    r = skyroute.plan(skyroute.Grid(b), (0, 2), (6, 2), algorithm=algorithm)
    assert r.status is Status.NO_PATH and not r.found
    assert r.path.shape == (0, 2) and np.isinf(r.cost)
    if algorithm == "jps":  # expands jump points only
        assert 1 <= r.expanded <= 15
    else:
        assert r.expanded == 15  # every reachable cell, once


@pytest.mark.parametrize("algorithm", ALGS)
def test_diagonal_gap_is_closed_without_corner_cutting(algorithm):
    b = np.array([[0, 1], [1, 0]], bool)
    r = skyroute.plan(skyroute.Grid(b), (0, 0), (1, 1), algorithm=algorithm)
    assert r.status is Status.NO_PATH


@pytest.mark.parametrize("algorithm", ALGS)
def test_budget_exhausted(algorithm):
    b = np.zeros((30, 30), bool)  # a serpentine: walls with gaps at alternate ends
    for k, x in enumerate(range(2, 28, 3)):
        b[:, x] = True
        b[29 if k % 2 == 0 else 0, x] = False
    grid = skyroute.Grid(b)
    assert skyroute.plan(grid, (0, 0), (29, 29), algorithm=algorithm).expanded > 3
    r = skyroute.plan(grid, (0, 0), (29, 29), algorithm=algorithm, max_expansions=3)
    assert r.status is Status.BUDGET_EXHAUSTED and r.expanded == 3 and not r.found
    assert r.path.shape == (0, 2)


@pytest.mark.parametrize("algorithm", ALGS)
@pytest.mark.parametrize("start, goal, words", [
    ((1, 1), (4, 4), "start (1, 1) is on a blocked cell"),
    ((0, 0), (1, 1), "goal (1, 1) is on a blocked cell"),
    ((-1, 0), (4, 4), "start (-1, 0) lies outside the 5x5 grid"),
    ((0, 0), (5, 4), "goal (5, 4) lies outside the 5x5 grid"),
    ((0.5, 0), (4, 4), "two integers"),
    ("ab", (4, 4), "two integers"),
    # each fails plan's inline test in its own way (an array's truth value, a NaN
    # Decimal's comparison, a float index), and check_cell names it
    ((np.array([0, 1]), 0), (4, 4), "two integers"),
    ((decimal.Decimal("NaN"), 0), (4, 4), "two integers"),
    ((0, 0), (4.0, 4), "goal (4.0, 4) must be two integers"),
])
def test_bad_queries_raise(algorithm, start, goal, words):
    b = np.zeros((5, 5), bool)
    b[1, 1] = True
    with pytest.raises(QueryError, match=words.replace("(", r"\(").replace(")", r"\)")) \
            as err:
        skyroute.plan(skyroute.Grid(b), start, goal, algorithm=algorithm)
    # param names the argument the message starts with, as an OptionError's does (None)
    assert err.value.param == str(err.value).split()[0]
    assert err.value.param in ("start", "goal")


# keys, members or bytes that are free in-range ints: each passed as a cell
NOT_CELLS = [({3: "x", 0: "y"}, "dict"), ({0: 0, 3: 0}.keys(), "dict_keys"),
             ({0, 3}, "set"), (frozenset({0, 3}), "frozenset"),
             (types.MappingProxyType({0: 0, 3: 0}), "mappingproxy"), (b"\x00\x03", "bytes")]


@pytest.mark.parametrize("algorithm", ALGS)
@pytest.mark.parametrize("cell, kind", NOT_CELLS, ids=[k for _, k in NOT_CELLS])
def test_a_mapping_or_set_is_not_a_cell(algorithm, cell, kind):
    grid = skyroute.Grid(np.zeros((5, 5), bool))
    with pytest.raises(QueryError) as start:
        skyroute.plan(grid, cell, (4, 4), algorithm=algorithm)
    assert str(start.value) == f"start {cell!r} must be two integers (x, y), not a {kind}"
    with pytest.raises(QueryError, match=rf"^goal .* must be two integers \(x, y\), not "
                                         rf"a {kind}$"):
        skyroute.plan(grid, [4, 4], cell, algorithm=algorithm)


# bools: Python counts True as the int 1, and (True, 3) planned from (1, 3); numpy's bool
# was refused already (no __index__), so a cell read from a mask and one typed differed
BOOL_CELLS = [((True, 3), (4, 4), "start (True, 3)"), ((0, 0), (4, False), "goal (4, False)"),
              ([np.True_, 3], (4, 4), "start [np.True_, 3]"),
              ((0, 0), (np.int64(4), True), "goal (np.int64(4), True)")]


@pytest.mark.parametrize("algorithm", ALGS)
@pytest.mark.parametrize("start, goal, words", BOOL_CELLS)
def test_a_bool_is_not_a_cell_coordinate(algorithm, start, goal, words):
    grid = skyroute.Grid(np.zeros((5, 5), bool))
    with pytest.raises(QueryError) as err:
        skyroute.plan(grid, start, goal, algorithm=algorithm)
    assert str(err.value) == f"{words} must be two integers (x, y), not booleans"
    assert err.value.param == words.split()[0]


def test_a_bool_is_not_a_cell_of_a_prepared_grid_nor_a_grid_method():
    grid = skyroute.Grid(np.zeros((5, 5), bool))
    index = skyroute.prepare(grid)
    for start, goal, words in BOOL_CELLS:
        with pytest.raises(QueryError, match=rf"^{re.escape(words)} .* not booleans$"):
            index.plan(start, goal)
    for method in (grid.is_free, grid.in_bounds):
        with pytest.raises(QueryError, match=r"^cell \(True, 0\) .* not booleans$"):
            method((True, 0))
    from skyroute.motion.turn_lattice import plan_turns

    with pytest.raises(QueryError, match=r"^goal \(4, False\) .* not booleans$"):
        plan_turns(grid, (0, 0), (4, False))
    # whole numbers of every other kind still plan, on the inline path and off it
    for cell in ((1, 3), [1, 3], (np.int64(1), np.int32(3)), np.array([1, 3])):
        assert skyroute.plan(grid, cell, (4, 4)).path[0].tolist() == [1, 3]
        assert index.plan(cell, (4, 4)).path[0].tolist() == [1, 3]


def test_a_mapping_or_set_is_not_a_cell_of_a_prepared_grid():
    index = skyroute.prepare(skyroute.Grid(np.zeros((5, 5), bool)))
    for cell, kind in NOT_CELLS:
        with pytest.raises(QueryError, match=rf"^start .* not a {kind}$"):
            index.plan(cell, (4, 4))
        with pytest.raises(QueryError, match=rf"^goal .* not a {kind}$"):
            index.plan((4, 4), cell)


@pytest.mark.parametrize("algorithm", ALGS)
def test_cells_as_numpy_ints_or_lists_plan_as_tuples(algorithm):
    # plain int pairs take plan's inline check; anything else goes through check_cell
    b = np.zeros((6, 6), bool)
    b[2, 1:5] = True
    grid = skyroute.Grid(b)
    want = skyroute.plan(grid, (0, 0), (5, 5), algorithm=algorithm)
    cell = collections.namedtuple("Cell", "x y")
    for s, t in (([0, 0], [5, 5]), (np.array([0, 0]), np.array([5, 5])),
                 ((np.int32(0), np.int64(0)), (5, 5)), (cell(0, 0), cell(5, 5))):
        # (False, False) planned as (0, 0) here: bools are refused now (BOOL_CELLS)
        got = skyroute.plan(grid, s, t, algorithm=algorithm)
        assert got.cost == want.cost and np.array_equal(got.path, want.path)


@pytest.mark.parametrize("options, words", [
    ({"algorithm": "dstar"}, "choose one of 'bfs', 'dijkstra', 'astar', 'jps'"),
    ({"connectivity": 6}, "connectivity=6 is not valid; choose one of 4, 8"),
    ({"heuristic": "chebyshev"}, "heuristic='chebyshev'"),
    ({"weight": 0.5}, "weight=0.5 must be a number >= 1"),
    ({"prune": "all"}, "choose one of 'none', 'collinear', 'los'"),
    ({"max_expansions": -1}, "max_expansions=-1"),
    ({"algorithm": "bfs", "connectivity": 8}, "bfs' is 4-connected"),
    ({"algorithm": "jps", "corner_cutting": True}, "jps' needs"),
    ({"algorithm": "dijkstra", "heuristic": "octile"}, "takes no heuristic"),
    # corner cutting with 4-connected moves was read by nothing and ignored
    ({"connectivity": 4, "corner_cutting": True}, "connectivity=4 has no diagonal steps"),
    ({"algorithm": "theta", "connectivity": 4, "corner_cutting": True}, "no corners to cut"),
    ({"algorithm": "bfs", "corner_cutting": True}, "bfs' is 4-connected, so it has no"),
])
def test_bad_options_raise_listing_valid_ones(options, words):
    with pytest.raises(OptionError, match=words.replace("(", r"\(")):
        skyroute.plan(open_grid(3, 3), (0, 0), (2, 2), **options)


def test_options_are_keyword_only():
    with pytest.raises(TypeError):
        skyroute.plan(open_grid(3, 3), (0, 0), (2, 2), "astar")


def test_repeated_queries_reuse_state_without_leaking():
    rng = np.random.default_rng(3)
    b = rng.random((40, 40)) < 0.3
    b[0, 0] = b[39, 39] = b[0, 39] = False
    grid = skyroute.Grid(b)
    first = [skyroute.plan(grid, s, t, algorithm=a) for a in ALGS
             for s, t in (((0, 0), (39, 39)), ((0, 39), (0, 0)))]
    again = [skyroute.plan(grid, s, t, algorithm=a) for a in ALGS
             for s, t in (((0, 0), (39, 39)), ((0, 39), (0, 0)))]
    for x, y in zip(first, again, strict=True):
        assert x.status is y.status and x.cost == y.cost and x.expanded == y.expanded
        np.testing.assert_array_equal(x.path, y.path)


def test_result_is_frozen_and_serialisable():
    r = skyroute.plan(open_grid(3, 3), (0, 0), (2, 2))
    with pytest.raises(AttributeError):
        r.cost = 1.0
    d = r.to_dict()
    assert list(d) == ["status", "cost", "path", "expanded", "max_frontier", "los_checks",
                       "seconds", "algorithm"]
    assert d["status"] == "found" and d["path"] == [[0, 0], [1, 1], [2, 2]]


@pytest.mark.parametrize("algorithm", ALGS)
def test_search_state_is_clean_after_every_ending(algorithm):
    # Kernels share per-grid arrays between queries and must leave `state` all zeros,
    # whether they found a path, found none or ran out of budget.
    from skyroute.search.space import space_of

    b = np.zeros((12, 12), bool)
    b[:, 6] = True
    b[3, 6] = False
    grid = skyroute.Grid(b)
    state = space_of(grid).workspace()[1][1]
    ends = [((0, 0), (11, 11), None), ((0, 0), (11, 11), 2)]
    b2 = b.copy()
    b2[3, 6] = True
    closed = skyroute.Grid(b2)
    for s, t, budget in ends:
        skyroute.plan(grid, s, t, algorithm=algorithm, max_expansions=budget)
        assert not state.any()
    r = skyroute.plan(closed, (0, 0), (11, 11), algorithm=algorithm)
    assert r.status is Status.NO_PATH
    assert not space_of(closed).workspace()[1][1].any()


@pytest.mark.parametrize("algorithm", ALGS)
def test_setup_is_timed_apart_from_the_search(algorithm, monkeypatch):
    # A fake clock that only the kernel runs move: 100 s for the set-up run that a new
    # grid needs (masks, tables, workspace, compiled kernels; a start-to-start search),
    # 1 s for each real search. No wall-clock time is asserted.
    import types

    from skyroute.search import grid_plan

    clock = [0.0]
    runner = grid_plan._runner

    def timed_runner(space, opts):
        run = runner(space, opts)

        def search(s, t):
            clock[0] += 100.0 if s == t else 1.0
            return run(s, t)
        return search

    monkeypatch.setattr(grid_plan, "_runner", timed_runner)
    monkeypatch.setattr(grid_plan, "time", types.SimpleNamespace(perf_counter=lambda: clock[0]))
    rng = np.random.default_rng(5)
    grid = skyroute.Grid(rng.random((60, 60)) < 0.2)
    free = np.argwhere(~grid.blocked)
    s, t = tuple(free[0][::-1]), tuple(free[-1][::-1])
    first = skyroute.plan(grid, s, t, algorithm=algorithm)
    again = skyroute.plan(grid, s, t, algorithm=algorithm)
    assert first.extra["setup_seconds"] == 100.0 and first.seconds == 1.0
    assert "setup_seconds" not in again.extra and again.seconds == 1.0  # set up once
    assert first.cost == again.cost and first.expanded == again.expanded


@pytest.mark.parametrize("start, goal, param", [
    ((-158.75, -163.19), (-160.0, -160.0), "goal"),  # inside a building
    ((np.nan, 0.0), (0.3, -0.7), "start"), ((1.0, 2.0, 3.0), (0.3, -0.7), "start"),
    ((0.3, -0.7), "ab", "goal"), ((0.3, -0.7), [(0.3, -0.7)] * 2, "goal"),
])
def test_a_bad_world_point_names_its_argument(start, goal, param):
    with pytest.raises(QueryError) as err:
        skyroute.plan(_city("ned"), start, goal)
    assert err.value.param == param and str(err.value).startswith(param)


def test_a_prepared_grid_names_its_bad_argument():
    index = skyroute.prepare(skyroute.Grid(np.eye(4, dtype=bool)))
    with pytest.raises(QueryError) as err:
        index.plan((1, 0), (1, 1))
    assert err.value.param == "goal"
    with pytest.raises(OptionError, match=r"ask the index itself: index\.plan") as err:
        skyroute.plan(index, (1, 0), (0, 1))  # it said only "got PreparedGrid"
    assert err.value.param == "grid"


@pytest.mark.parametrize("algorithm", WORLD_ALGORITHMS)
def test_a_world_result_has_one_shape_found_or_not(algorithm):
    # PRM's no_path lacked extra's k, raw_cost and build_seconds: a KeyError for a
    # notebook tabling its runs
    import shapely

    ring = shapely.box(0, 0, 10, 10).difference(shapely.box(3, 3, 7, 7))
    world = skyroute.World([ring], [0], [50], ("ring",))
    found = skyroute.plan(world, (-2, 5), (12, 5), algorithm=algorithm)
    walled = skyroute.plan(world, (-2, 5), (5, 5), algorithm=algorithm)  # inside the ring
    assert found.status is Status.FOUND and walled.status is Status.NO_PATH
    assert sorted(found.extra) == sorted(walled.extra)
    assert walled.path.shape == (0, 2) and walled.path.dtype == found.path.dtype
    assert walled.cost == np.inf and found.algorithm == walled.algorithm == algorithm
    assert walled.path_lonlat is found.path_lonlat is None  # a plane world, no home


@pytest.mark.parametrize("cell", [np.array([[0], [1]]), np.array([[0, 1], [1, 0]])])
def test_a_cell_given_as_a_2d_array_is_refused_in_one_line(cell):
    with pytest.raises(QueryError) as err:
        skyroute.plan(open_grid(3, 3), (0, 0), cell)
    assert "\n" not in str(err.value)  # the array's repr ran over two lines
    assert str(err.value).startswith("goal array([[0") and err.value.param == "goal"
