"""Prepared "jump" indexes (JPS with pivot bounds) and prepare's "auto" choice: exact
optima against the MovingAI scenarios and Dijkstra, pivot distances against scipy, the
.npz round trip and the CLI."""

import sys

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings

import skyroute
from skyroute.bench.random_maps import octile_graph
from skyroute.cli.app import main
from skyroute.search import prepared, subgoal_contract, subgoal_table
from skyroute.search.pivots import DENSE_PIVOTS, PIVOTS, pivot_distances
from skyroute.search.prepared import region_labels
from skyroute.search.space import space_of
from skyroute.world.movingai import read_map, read_scen
from tests.conftest import movingai_pairs
from tests.search.test_prepared import _check_against_dijkstra, _check_scenario, random_query

PAIRS = movingai_pairs()


@pytest.mark.parametrize("name", sorted(skyroute.bundled_maps()))
def test_every_line_of_the_bundled_scenarios(name):
    path = skyroute.bundled_maps()[name]
    grid, scen = read_map(path), read_scen(path.with_name(path.name + ".scen"))
    index = _check_scenario(grid, scen, range(len(scen)), method="jump")
    assert index.accelerator == "jump" and index.pivots == DENSE_PIVOTS


@pytest.mark.shared_data
@pytest.mark.parametrize("map_path, scen_path", PAIRS, ids=[m.stem for m, _ in PAIRS])
def test_sampled_lines_of_the_shared_scenarios(map_path, scen_path):
    grid, scen = read_map(map_path), read_scen(scen_path)
    rng = np.random.default_rng(20261124)
    lines = rng.choice(len(scen), size=min(40, len(scen)), replace=False)
    _check_scenario(grid, scen, [*lines, len(scen) - 1], method="jump")


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_query())
def test_jump_costs_equal_dijkstra(q):
    # several free regions: pivots lie in the largest only, so queries elsewhere run on
    # the octile bound alone (a pivot's distance there is inf, its bound NaN)
    blocked, s, t = q
    index = skyroute.prepare(skyroute.Grid(blocked), method="jump")
    _check_against_dijkstra(index, blocked, s, t)
    got = index.plan(s, t)
    if not got.found:  # only across regions (the labels): at once, nothing expanded
        assert got.path.shape == (0, 2) and got.cost == np.inf and got.expanded == 0


@pytest.mark.parametrize("share", [0.0, 0.2, 0.35])
def test_pivot_distances_equal_scipy(share):
    from scipy.sparse.csgraph import dijkstra

    blocked = np.random.default_rng(11).random((40, 60)) < share
    blocked[:, 30] = True  # two regions: pivots go to the larger
    blocked[5:, 30] = share > 0.3  # the wall has a gap unless the map is dense
    grid = skyroute.Grid(blocked)
    space = space_of(grid)
    label = region_labels(blocked)
    piv = pivot_distances(space.move_mask(8, False), label, space.Wp, 6)
    assert piv.shape == (space.n, 6)
    h, w = blocked.shape
    cells = np.arange(h * w)
    flat = (cells // w + 1) * space.Wp + cells % w + 1  # unpadded -> padded
    graph = octile_graph(blocked)
    sources = [int(np.flatnonzero(piv[:, j] == 0)[0]) for j in range(6)]
    assert len(set(sources)) == 6
    largest = np.argmax(np.bincount(label[label >= 0]))
    assert all(label[p] == largest for p in sources)
    for j, p in enumerate(sources):
        src = (p // space.Wp - 1) * w + p % space.Wp - 1
        want = dijkstra(graph, directed=False, indices=src)
        np.testing.assert_allclose(piv[flat, j], want, rtol=0, atol=1e-9)
        assert np.isinf(piv[space.blocked == 1, j]).all()


def test_auto_keeps_the_faster_and_the_table_without_timing(tmp_path):
    small = skyroute.load_map("den312d")
    index = skyroute.prepare(small)
    assert index.method == "subgoal" and index.accelerator == "table"
    assert index.candidates == {}
    path = skyroute.bundled_maps()["Paris_1_512"]
    grid, scen = read_map(path), read_scen(path.with_name(path.name + ".scen"))
    index = skyroute.prepare(grid)
    assert set(index.candidates) == {"subgoal", "jump"}
    assert index.candidates[index.method] == min(index.candidates.values())
    jump = skyroute.prepare(grid, method="jump")
    loaded = skyroute.load_index(jump.save(tmp_path / "paris.idx"), grid)
    assert loaded.method == "jump" and loaded.pivots == DENSE_PIVOTS and loaded.subgoals == 0
    for i in (0, len(scen) // 2, len(scen) - 1):
        s, t = tuple(scen.starts[i].tolist()), tuple(scen.goals[i].tolist())
        a, b = jump.plan(s, t), loaded.plan(s, t)
        assert a.algorithm == b.algorithm == "jump"
        assert a.cost == b.cost and np.array_equal(a.path, b.path)
        assert scen.matches(i, a.cost)


def test_a_foreign_method_in_an_index_is_refused(tmp_path):
    grid = skyroute.load_map("den312d")
    path = skyroute.prepare(grid, method="jump").save(tmp_path / "d.idx")
    with np.load(path) as z:
        data = dict(z)
    data["method"] = np.array("cpd")
    bad = tmp_path / "bad.idx"
    with open(bad, "wb") as f:
        np.savez(f, **data)
    with pytest.raises(skyroute.InputFormatError, match=r"bad.idx: not a skyroute index: "
                                                         r"method 'cpd'"):
        skyroute.load_index(bad, grid)


def test_cli_prepare_jump(monkeypatch, capsys, tmp_path):
    idx = tmp_path / "den.idx"
    monkeypatch.setattr(sys, "argv", ["skyroute", "prepare", "den312d", "-o", str(idx),
                                      "--method", "jump"])
    with pytest.raises(SystemExit) as e:
        main()
    out = capsys.readouterr().out
    assert e.value.code in (0, None) and "jump index, 24 pivots" in out
    monkeypatch.setattr(sys, "argv", ["skyroute", "plan", "den312d", "--start", "50,76",
                                      "--goal", "60,13", "--index", str(idx), "--json"])
    with pytest.raises(SystemExit) as e:
        main()
    out = capsys.readouterr().out
    assert e.value.code in (0, None) and '"algorithm": "jump"' in out
    assert '"cost": 112.556349' in out


def test_a_grid_without_free_cells_gets_no_pivots():
    grid = skyroute.Grid(np.ones((4, 5), bool))
    index = skyroute.prepare(grid, method="jump")
    assert index.pivots == 0
    with pytest.raises(skyroute.QueryError, match="blocked"):
        index.plan((0, 0), (4, 3))


@pytest.mark.parametrize("contracts, pivots", [(True, PIVOTS), (False, DENSE_PIVOTS)])
def test_auto_gives_the_jump_index_more_pivots_where_nothing_was_contracted(
        monkeypatch, contracts, pivots):
    # rooms and doors, 33 x 33: with no table, the subgoal graph contracts (its
    # hierarchy took the build's time: 16 pivots) or, with no contraction budget, only
    # the landmark A* answers it (24 pivots, a tenth faster on random maps)
    blocked = np.zeros((33, 33), bool)
    blocked[::8, :] = blocked[:, ::8] = True
    blocked[4::8, ::8] = blocked[::8, 4::8] = False
    monkeypatch.setattr(subgoal_table, "TABLE_MAX", 0)
    monkeypatch.setattr(subgoal_contract, "BUDGET",
                        subgoal_contract.BUDGET if contracts else -1)
    asked = []

    def recording(mask, label, Wp, count):
        asked.append(count)
        return pivot_distances(mask, label, Wp, count)

    monkeypatch.setattr(prepared, "pivot_distances", recording)
    index = skyroute.prepare(skyroute.Grid(blocked))
    assert asked == [pivots] and set(index.candidates) == {"subgoal", "jump"}
    if index.method == "subgoal":  # auto kept the graph: answered as the rule assumed
        assert index.accelerator == ("hierarchy" if contracts else "landmarks")
