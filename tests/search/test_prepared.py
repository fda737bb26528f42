"""Prepared grids (skyroute.prepare): exact optima through the subgoal index, against the
MovingAI scenarios, Dijkstra on random grids, and the corner cases; the .npz round trip
and its refusals; the CLI's prepare and plan --index."""

import json
import sys

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import skyroute
from skyroute.cli.app import main
from skyroute.search import subgoal_contract, subgoal_table
from skyroute.search.index_file import FORMAT_VERSION
from skyroute.search.prepared import build_arrays
from skyroute.search.subgoal_ch_query import ch_query
from skyroute.search.subgoal_landmarks import landmark_count, landmark_distances
from skyroute.search.subgoal_query import subgoal_query
from skyroute.world.movingai import read_map, read_scen
from tests.conftest import movingai_pairs
from tests.search.checks import assert_grid_path_legal, grid_optimum, two_indices

PAIRS = movingai_pairs()


def _check_scenario(grid, scen, lines, walk_every=1, method="auto"):
    """Through an index of ``method``: every line's cost is the optimum and its path
    runs from start to goal; every ``walk_every``-th path is also walked cell by cell
    (legal steps summing to the cost: the slow part on long maze paths). Returns the
    index."""
    index = skyroute.prepare(grid, method=method)
    for n, i in enumerate(lines):
        s, t = tuple(scen.starts[i].tolist()), tuple(scen.goals[i].tolist())
        r = index.plan(s, t)
        assert r.found, (grid.name, i)
        assert scen.matches(int(i), r.cost), (grid.name, i, r.cost, scen.optimal[i])
        assert tuple(r.path[0]) == s and tuple(r.path[-1]) == t
        if n % walk_every == 0:
            walked = assert_grid_path_legal(grid.blocked, r.path)
            assert walked == pytest.approx(r.cost, abs=1e-9)
    return index


@pytest.mark.parametrize("name", sorted(skyroute.bundled_maps()))
def test_every_line_of_the_bundled_scenarios(name):
    path = skyroute.bundled_maps()[name]
    grid, scen = read_map(path), read_scen(path.with_name(path.name + ".scen"))
    _check_scenario(grid, scen, range(len(scen)))


@pytest.mark.shared_data
@pytest.mark.parametrize("map_path, scen_path", PAIRS, ids=[m.stem for m, _ in PAIRS])
def test_every_line_of_the_shared_scenarios(map_path, scen_path):
    # the default index ("auto": table, hierarchy, landmarks or jump, whichever the map
    # gets) on all 29,655 lines of the 18 maps
    grid, scen = read_map(map_path), read_scen(scen_path)
    _check_scenario(grid, scen, range(len(scen)), walk_every=16)


@st.composite
def random_query(draw):
    h, w = draw(st.integers(2, 24)), draw(st.integers(2, 24))
    share = draw(st.sampled_from([0.1, 0.2, 0.3, 0.4]))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    blocked = rng.random((h, w)) < share
    if draw(st.booleans()):  # one-cell corridors: walls every other row with gaps
        blocked[1::2, :] = True
        blocked[1::2, rng.integers(0, w, size=blocked[1::2].shape[0])] = False
    free = np.argwhere(~blocked)
    if len(free) == 0:
        blocked[0, 0] = False
        free = np.argwhere(~blocked)
    i, j = two_indices(draw, len(free))  # start != goal (one index twice before: 36%)
    s, t = free[i], free[j]
    return blocked, (int(s[1]), int(s[0])), (int(t[1]), int(t[0]))


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_query())
def test_prepared_costs_equal_dijkstra(q):
    blocked, s, t = q
    _check_against_dijkstra(skyroute.prepare(skyroute.Grid(blocked)), blocked, s, t)


def _forced(blocked, table_max, budget):
    """An index of ``blocked`` built with the table limit (and so the hierarchy's core
    size) and the contraction budget set: graphs this small reach the hierarchy or the
    landmark A* only so (larger maps reach them by themselves: Boston_0_256's and
    Paris_1_512's every line above)."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(subgoal_table, "TABLE_MAX", table_max)
        mp.setattr(subgoal_contract, "BUDGET", budget)
        return skyroute.prepare(skyroute.Grid(blocked), method="subgoal")


def _check_against_dijkstra(index, blocked, s, t):
    """The index's answer against scipy's Dijkstra (not skyroute's own: a fault shared by
    the kernels would pass a comparison with them), its path walked cell by cell."""
    want = grid_optimum(blocked, s, t)
    got = index.plan(s, t)
    if np.isinf(want):
        assert got.status is skyroute.Status.NO_PATH
        assert got.path.shape == (0, 2) and got.cost == np.inf
    else:
        assert got.found and got.cost == pytest.approx(want, abs=1e-9)
        assert assert_grid_path_legal(blocked, got.path) == pytest.approx(got.cost, abs=1e-9)
        assert tuple(got.path[0]) == s and tuple(got.path[-1]) == t


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_query())
def test_landmark_search_costs_equal_dijkstra(q):
    blocked, s, t = q
    index = _forced(blocked, 0, -1)  # no table, no hierarchy
    assert index._kernel is subgoal_query and index.accelerator == "landmarks"
    _check_against_dijkstra(index, blocked, s, t)


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_query(), st.sampled_from([0, 1, 4, 12]))
def test_hierarchy_costs_equal_dijkstra(q, core):
    # core 0: every node contracted, the two upward searches alone meet; else the
    # core's table joins them (a core of one node: every path through it)
    blocked, s, t = q
    index = _forced(blocked, core, subgoal_contract.BUDGET)
    if index.subgoals > core:
        assert index._kernel is ch_query and index.accelerator == "hierarchy"
        assert int((index._arrays["ch_core"] >= 0).sum()) == core
    _check_against_dijkstra(index, blocked, s, t)


def test_hierarchy_every_pair_of_a_room_map():
    # rooms and doors: long shortcuts unpack through several levels; all pairs of a
    # sample against Dijkstra, with and without a core, after a save and load
    blocked = np.zeros((33, 33), bool)
    blocked[::8, :] = blocked[:, ::8] = True
    blocked[4::8, ::8] = blocked[::8, 4::8] = False
    blocked[[0, -1], :] = blocked[:, [0, -1]] = False
    free = [(int(x), int(y)) for y, x in np.argwhere(~blocked)][::7]
    for core in (0, 16):
        index = _forced(blocked, core, subgoal_contract.BUDGET)
        assert index.accelerator == "hierarchy"
        for s in free:
            for t in free[::3]:
                _check_against_dijkstra(index, blocked, s, t)


def test_hierarchy_is_the_same_on_one_thread_and_on_two():
    # the priority estimates run on numba's threads, each with its own scratch: the
    # order, and so every array of the index, must not depend on the thread count
    import numba

    blocked = np.random.default_rng(5).random((96, 96)) < 0.3
    before = numba.get_num_threads()
    built = []
    try:
        for threads in (1, min(2, numba.config.NUMBA_NUM_THREADS)):
            numba.set_num_threads(threads)
            built.append(_forced(blocked, 8, subgoal_contract.BUDGET))
    finally:
        numba.set_num_threads(before)
    one, two = built
    assert one.accelerator == two.accelerator == "hierarchy" and one.subgoals > 500
    assert one._arrays.keys() == two._arrays.keys()
    for key, arr in one._arrays.items():
        assert arr.dtype == two._arrays[key].dtype and np.array_equal(arr, two._arrays[key])


def test_hierarchy_index_round_trip(tmp_path):
    blocked = np.random.default_rng(3).random((40, 40)) < 0.25
    grid = skyroute.Grid(blocked)
    index = _forced(blocked, 8, subgoal_contract.BUDGET)
    assert index.accelerator == "hierarchy"
    loaded = skyroute.load_index(index.save(tmp_path / "r.idx"), grid)
    assert loaded.accelerator == "hierarchy"
    free = [(int(x), int(y)) for y, x in np.argwhere(~blocked)]
    for s, t in zip(free[::5], free[::-7], strict=False):
        a, b = index.plan(s, t), loaded.plan(s, t)
        assert a.cost == b.cost and np.array_equal(a.path, b.path)


def test_every_pair_of_a_corridor_maze_matches_dijkstra():
    # one-cell corridors, dead ends and starts right beside walls: all pairs
    rows = ["....#.....",
            "###.#.###.",
            "..#...#...",
            ".####.#.##",
            "......#..."]
    blocked = np.array([[c == "#" for c in r] for r in rows])
    grid = skyroute.Grid(blocked)
    index = skyroute.prepare(grid)
    free = [(int(x), int(y)) for y, x in np.argwhere(~blocked)]
    for s in free:
        for t in free:
            _check_against_dijkstra(index, blocked, s, t)  # scipy's


def test_landmark_distances_are_the_grids_optima():
    # the landmark bound is admissible only because the subgoal graph's distances are
    # the grid's: check a sample against Dijkstra on the grid, through the float32 store
    grid = skyroute.load_map("den312d")
    arrays = build_arrays(grid.blocked)
    cells, Wp = arrays["cells"], grid.width + 2
    assert arrays["lmd"].shape == (179, 0)  # a small map: the table answers instead
    lmd = landmark_distances(cells, arrays["offs"], arrays["nbr"],
                             arrays["label"][cells], Wp)
    assert lmd.shape == (cells.size, landmark_count(cells.size)) == (179, 8)
    xy = [(int(c % Wp) - 1, int(c // Wp) - 1) for c in cells]
    rng = np.random.default_rng(7)
    for j in range(lmd.shape[1]):
        landmark = int(np.flatnonzero(lmd[:, j] == 0)[0])
        for v in rng.choice(cells.size, size=8, replace=False):
            want = grid_optimum(grid.blocked, xy[landmark], xy[v])  # scipy's Dijkstra
            if np.isfinite(want):
                assert lmd[v, j] == pytest.approx(want, rel=2**-23)
            else:
                assert lmd[v, j] == np.inf
    assert landmark_count(100_000) == 64 and landmark_count(3) == 3


def test_no_path_across_components_is_answered_from_the_labels():
    blocked = np.zeros((20, 30), bool)
    blocked[:, 15] = True  # a wall splits the map
    index = skyroute.prepare(skyroute.Grid(blocked))
    r = index.plan((0, 0), (29, 19))
    assert r.status is skyroute.Status.NO_PATH and r.expanded == 0 and r.cost == np.inf
    # a diagonal gap is no way through without corner cutting
    index = skyroute.prepare(skyroute.Grid(np.array([[False, True], [True, False]])))
    assert index.plan((0, 0), (1, 1)).status is skyroute.Status.NO_PATH


def test_start_equals_goal_and_bad_queries():
    grid = skyroute.load_map("den312d")
    index = skyroute.prepare(grid)
    r = index.plan((50, 76), (50, 76))
    assert r.found and r.cost == 0.0 and r.path.tolist() == [[50.0, 76.0]]
    assert index.plan(np.array([50, 76]), (60, 13)).cost == pytest.approx(112.55634918)
    with pytest.raises(skyroute.QueryError, match=r"start .* outside"):
        index.plan((500, 1), (60, 13))
    with pytest.raises(skyroute.QueryError, match=r"goal .* blocked"):
        index.plan((50, 76), (0, 0))
    with pytest.raises(skyroute.OptionError, match="method"):
        skyroute.prepare(grid, method="cpd")
    for bad in ((50.5, 76), (1, 2, 3), None):
        with pytest.raises(skyroute.QueryError, match=r"start .* must be two integers"):
            index.plan(bad, (60, 13))
        with pytest.raises(skyroute.QueryError, match=r"start .* must be two integers"):
            skyroute.plan(grid, bad, (60, 13))


def test_save_load_round_trip_and_refusals(tmp_path):
    grid = skyroute.load_map("den312d")
    index = skyroute.prepare(grid)
    path = index.save(tmp_path / "den312d.idx")
    loaded = skyroute.load_index(path, grid)
    assert (loaded.subgoals, loaded.edges) == (index.subgoals, index.edges)
    a, b = index.plan((50, 76), (60, 13)), loaded.plan((50, 76), (60, 13))
    assert a.cost == b.cost and np.array_equal(a.path, b.path)
    # the same shape, one cell changed: stale
    changed = grid.blocked.copy()
    changed[76, 50] = True
    with pytest.raises(skyroute.InputFormatError,
                       match=r"den312d.idx: index does not match .*stale, another map, "
                             r"or another --safety"):
        skyroute.load_index(path, skyroute.Grid(changed))
    with pytest.raises(skyroute.InputFormatError, match="index is for a 65x81 map"):
        skyroute.load_index(path, skyroute.load_map("Berlin_1_256"))
    junk = tmp_path / "junk.idx"
    junk.write_text("not an index")
    with pytest.raises(skyroute.InputFormatError, match=r"junk.idx: not a skyroute index"):
        skyroute.load_index(junk, grid)
    with pytest.raises(skyroute.OptionError, match="grid must be a skyroute Grid, got str"):
        skyroute.load_index(path, "den312d")
    world = skyroute.World([], 0.0, 10.0, (), boundary=shapely.box(0, 0, 9, 9))
    with pytest.raises(skyroute.OptionError, match="got World; a World needs no prepare"):
        skyroute.prepare(world)
    with np.load(path) as z:
        data = dict(z)
    data["version"] = np.int64(FORMAT_VERSION + 1)
    old = tmp_path / "future.idx"
    with open(old, "wb") as f:
        np.savez(f, **data)
    with pytest.raises(skyroute.InputFormatError, match=r"future.idx: index format"):
        skyroute.load_index(old, grid)


@pytest.mark.parametrize("method", ["auto", "jump"])
def test_an_index_pickles_and_answers_alike(method):
    import pickle

    grid = skyroute.load_map("den312d")
    index = skyroute.prepare(grid, method=method)
    copy = pickle.loads(pickle.dumps(index))
    assert (copy.method, copy.accelerator, copy.pivots, copy.subgoals) == \
        (index.method, index.accelerator, index.pivots, index.subgoals)
    assert copy.build_seconds == index.build_seconds and copy.candidates == index.candidates
    scen = read_scen(skyroute.bundled_maps()["den312d"].with_suffix(".map.scen"))
    for i in range(0, len(scen), 37):
        s, t = tuple(scen.starts[i].tolist()), tuple(scen.goals[i].tolist())
        a, b = index.plan(s, t), copy.plan(s, t)
        assert a.cost == b.cost and np.array_equal(a.path, b.path)
        assert scen.matches(i, b.cost)


def _run(monkeypatch, capsys, *args):
    monkeypatch.setattr(sys, "argv", ["skyroute", *args])
    with pytest.raises(SystemExit) as exit_info:
        main()
    out, err = capsys.readouterr()
    return exit_info.value.code, out, err


def test_cli_prepare_then_plan_with_index(monkeypatch, capsys, tmp_path):
    idx = tmp_path / "den312d.idx"
    monkeypatch.setattr(sys, "argv", ["skyroute", "prepare", "den312d", "-o", str(idx)])
    with pytest.raises(SystemExit) as e:
        main()
    assert e.value.code in (0, None) and idx.exists()
    capsys.readouterr()
    query = ["den312d", "--start", "50,76", "--goal", "60,13"]
    code, out, err = _run(monkeypatch, capsys, "plan", *query, "--index", str(idx), "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["algorithm"] == "subgoal"
    assert doc["cost"] == pytest.approx(112.55634918, abs=1e-8)
    code, _, err = _run(monkeypatch, capsys, "plan", *query, "--index", str(idx),
                        "--algorithm", "jps")
    assert code == 2 and "--index" in err and "Traceback" not in err
    code, _, err = _run(monkeypatch, capsys, "plan", "Berlin_1_256", "--start", "1,1",
                        "--goal", "2,2", "--index", str(idx))
    assert code == 2 and err.strip().endswith(
        "Berlin_1_256.map is 256x256 (another map, or another --safety or --resolution); "
        "rebuild it with 'skyroute prepare'")
    assert len(err.strip().splitlines()) == 1


def test_cli_prepare_refuses_to_write_over_its_map(monkeypatch, capsys, tmp_path):
    victim = tmp_path / "den312d.map"
    victim.write_bytes(skyroute.bundled_maps()["den312d"].read_bytes())
    before = victim.read_bytes()
    code, _, err = _run(monkeypatch, capsys, "prepare", str(victim), "-o", str(victim))
    assert code == 2 and "is the map itself" in err and victim.read_bytes() == before
    # a map whose every cell is blocked builds, with a note that it refuses every query
    idx = tmp_path / "all.idx"
    code, _, err = _run(monkeypatch, capsys, "prepare", str(victim), "-o", str(idx),
                        "--safety", "1e9")
    assert code in (0, None) and idx.exists() and "every cell of den312d.map is blocked" in err


def test_cli_prepare_to_an_unwritable_path_is_one_line(monkeypatch, capsys, tmp_path):
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("x")
    out_path = blocker / "den312d.idx"
    code, _, err = _run(monkeypatch, capsys, "prepare", "den312d", "-o", str(out_path))
    assert code == 2 and "Traceback" not in err
    assert err.strip() == f"skyroute: error: {out_path}: cannot write: {blocker} is not a folder"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["not-a-folder"]


@pytest.mark.parametrize("seed", range(4))
def test_compiled_all_pairs_equal_scipy(seed):
    """The hierarchy's core table (subgoal_table.all_pairs) against scipy's Dijkstra on
    random directed graphs with unreachable pairs; predecessors lie on shortest paths."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import dijkstra

    from skyroute.search.subgoal_table import all_pairs

    rng = np.random.default_rng(seed)
    n = 60
    mat = csr_matrix(np.where(rng.random((n, n)) < 0.06, rng.integers(1, 9, (n, n)) +
                              rng.random((n, n)), 0.0))
    dist, pred = all_pairs(mat.indptr.astype(np.int64), mat.indices, mat.data)
    want = dijkstra(mat)
    assert np.isinf(want).any()
    np.testing.assert_allclose(dist, want, rtol=0, atol=1e-9)
    dense = mat.toarray()
    for s in range(n):
        for v in range(n):
            if v == s or np.isinf(want[s, v]):
                assert pred[s, v] == -1
            else:
                p = pred[s, v]
                assert dense[p, v] > 0 and dist[s, p] + dense[p, v] == pytest.approx(dist[s, v])
