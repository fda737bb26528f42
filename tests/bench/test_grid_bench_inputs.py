"""`bench grid` checks its input before any timing: one line naming the file, line or
option, exit 2, no traceback and no report written."""

import dataclasses
import json

import numpy as np
import pytest

from skyroute.bench import grid as grid_mod
from skyroute.bench import peers
from skyroute.bench.grid import check_runners, check_scenario, load_case
from skyroute.bench.random_maps import far_queries, parse_random, random_grid
from skyroute.errors import InputFormatError, OptionError
from skyroute.world.grid import Grid
from skyroute.world.movingai import read_map, read_scen
from tests.cli.test_cli import run
from tests.conftest import movingai_pairs

# 4x3, the middle column blocked on the first two rows: (1, 0) and (1, 1) are walls.
TINY_MAP = "type octile\nheight 3\nwidth 4\nmap\n.@..\n.@..\n....\n"


def scen_text(*lines, size=(4, 3), name="tiny.map"):
    """A version-1 scenario: each line (sx, sy, gx, gy, optimum) or "" for a blank line."""
    w, h = size
    rows = ["\t".join(map(str, (0, name, w, h, *ln))) if ln else "" for ln in lines]
    return "version 1\n" + "\n".join(rows) + "\n"


def write_pair(folder, stem="tiny", scen=None, map_text=TINY_MAP):
    (folder / f"{stem}.map").write_text(map_text)
    path = folder / f"{stem}.map.scen"
    path.write_text(scen or scen_text((0, 0, 3, 0, 4.82842712), name=f"{stem}.map"))
    return path


@pytest.fixture
def no_timing(monkeypatch):
    """Fail the test if any map reaches the timed part of the bench."""
    def timed(*args, **kwargs):
        raise AssertionError("a map was timed before the bad input was found")

    monkeypatch.setattr(grid_mod, "bench_queries", timed)


def assert_one_line(code, out, err, words):
    assert code == 2, err
    assert err.count("\n") == 1 and err.startswith("skyroute: error: "), err
    assert words in err and "Traceback" not in err and out == ""


@pytest.mark.parametrize("runners", [["--peers", ""], ["--peers", "networkx"],
                                     ["--peers", "pyastar2d", "--algorithms", ""]])
def test_scen_line_on_a_blocked_cell_names_file_and_line(monkeypatch, capsys, tmp_path,
                                                         no_timing, runners):
    # a blank line before the bad one: the file line, not the query's index, is named
    scen = write_pair(tmp_path, scen=scen_text((0, 0, 3, 0, 4.82842712), "",
                                               (0, 2, 1, 1, 1.0)))
    code, out, err = run(monkeypatch, capsys, "bench", "grid", "--maps", str(tmp_path),
                         "--per-map", "1", *runners)
    assert_one_line(code, out, err, f"{scen}:4: goal (1, 1) is on a blocked cell of tiny.map")


def test_wrong_size_scen_fails_before_the_good_map_is_timed(monkeypatch, capsys, tmp_path,
                                                            no_timing):
    write_pair(tmp_path, "a")
    bad = write_pair(tmp_path, "b", scen=scen_text((0, 0, 1, 0, 1.0), size=(5, 3),
                                                   name="b.map"))
    out_json = tmp_path / "r.json"
    code, out, err = run(monkeypatch, capsys, "bench", "grid", "--maps", str(tmp_path),
                         "--peers", "", "--json", str(out_json))
    assert_one_line(code, out, err, f"{bad}:2: scenario is for a 5x3 map, b.map is 4x3")
    assert not out_json.exists()


@pytest.mark.parametrize("named", ["other.map", "maps/dao/other.map"])
def test_scen_for_another_map_of_the_same_size_is_refused(monkeypatch, capsys, tmp_path,
                                                          no_timing, named):
    # the same size and free cells: only the scenario's map column tells the maps apart
    bad = write_pair(tmp_path, scen=scen_text((0, 0, 3, 0, 4.82842712), name=named))
    code, out, err = run(monkeypatch, capsys, "bench", "grid", "--maps", str(tmp_path),
                         "--peers", "")
    assert_one_line(code, out, err, f"{bad}:2: scenario is for other.map (its map column), "
                    "not tiny.map")
    write_pair(tmp_path, scen=scen_text((0, 0, 3, 0, 4.82842712), name="maps\\tiny.map"))
    assert load_case(tmp_path / "tiny.map", bad, per_map=0).queries == 1  # a folder is ignored


def test_check_scenario_start_outside_the_map(tmp_path):
    path = write_pair(tmp_path)
    grid, scen = read_map(tmp_path / "tiny.map"), read_scen(path)
    moved = dataclasses.replace(scen, starts=np.array([[7, 0]]))
    with pytest.raises(InputFormatError, match=r"tiny.map.scen:2: start \(7, 0\) lies outside "
                                               r"tiny.map \(4x3\)"):
        check_scenario(grid, moved, "tiny.map")


@pytest.mark.shared_data
def test_every_shared_scenario_line_is_on_free_cells():
    for map_path, scen_path in movingai_pairs():
        assert load_case(map_path, scen_path, per_map=0).queries == len(read_scen(scen_path))


@pytest.mark.parametrize("spec", ["2:0.9", "16:0.999"])
def test_random_map_without_two_free_cells_is_one_line(monkeypatch, capsys, spec):
    code, out, err = run(monkeypatch, capsys, "bench", "grid", "--random", spec,
                         "--per-map", "2", "--peers", "")
    assert_one_line(code, out, err, "fewer than two free cells; lower the blocked share")


def test_far_queries_on_an_all_blocked_map():
    with pytest.raises(OptionError, match="fewer than two free cells"):
        far_queries(Grid(np.ones((4, 4), dtype=bool)), 1)


def test_far_queries_optima_in_chunks_equal_one_call(monkeypatch):
    from skyroute.bench import random_maps

    grid = random_grid(40, 0.2, seed=4)
    whole = far_queries(grid, 7, seed=4)
    monkeypatch.setattr(random_maps, "ROWS_BYTES", 3 * 8 * 40 * 40)  # 3 rows a chunk
    np.testing.assert_array_equal(far_queries(grid, 7, seed=4).optimal, whole.optimal)


def test_random_error_comes_before_movingai_timing(monkeypatch, capsys, tmp_path, no_timing):
    write_pair(tmp_path)
    code, out, err = run(monkeypatch, capsys, "bench", "grid", "--maps", str(tmp_path),
                         "--random", "2:0.9", "--peers", "")
    assert_one_line(code, out, err, "random-2-0.9-s0: fewer than two free cells")


def test_unwritable_json_fails_before_timing(monkeypatch, capsys, tmp_path, no_timing):
    (tmp_path / "afile").write_text("")
    code, out, err = run(monkeypatch, capsys, "bench", "grid", "--map", "den312d",
                         "--peers", "", "--json", str(tmp_path / "afile" / "r.json"))
    assert_one_line(code, out, err, f"{tmp_path / 'afile'} is not a folder")


@pytest.mark.parametrize("algorithms", ["", ","])
def test_nothing_to_run_is_an_option_error(monkeypatch, capsys, no_timing, algorithms):
    code, out, err = run(monkeypatch, capsys, "bench", "grid", "--map", "den312d",
                         "--algorithms", algorithms, "--peers", "")
    assert_one_line(code, out, err, "nothing to run: give --algorithms, --peers or --prepared")


def test_only_missing_peers_is_nothing_to_run(monkeypatch, capsys, no_timing):
    monkeypatch.setattr(grid_mod, "available", lambda p: False)
    code, out, err = run(monkeypatch, capsys, "bench", "grid", "--map", "den312d",
                         "--algorithms", "", "--peers", "pathfinding")
    assert_one_line(code, out, err, "nothing to run: give --algorithms, --peers or --prepared "
                                    "(not installed: pathfinding)")


def test_only_skipped_peers_is_nothing_to_run(monkeypatch, capsys, no_timing):
    small = dataclasses.replace(peers.PEERS["networkx"], max_cells=100)
    monkeypatch.setitem(peers.PEERS, "networkx", small)
    code, out, err = run(monkeypatch, capsys, "bench", "grid", "--random", "16:0.2",
                         "--per-map", "2", "--algorithms", "", "--peers", "networkx")
    assert_one_line(code, out, err, "nothing to run on random-16-0.2-s0: every peer is skipped")


def test_duplicates_run_once_in_the_order_given(monkeypatch, capsys, tmp_path):
    assert check_runners(["jps", "astar", "jps"], ["networkx", "networkx"])[:2] == (
        ["jps", "astar"], ["networkx"])
    write_pair(tmp_path)
    out_json = tmp_path / "r.json"
    code, _, err = run(monkeypatch, capsys, "bench", "grid", "--maps", str(tmp_path),
                       "--map", "tiny", "--map", "tiny.map", "--random", "16:0.2",
                       "--random", "16:0.20", "--per-map", "2", "--algorithms", "astar,astar",
                       "--peers", "", "--json", str(out_json))
    assert code == 0, err
    doc = json.loads(out_json.read_text())
    assert [m["map"] for m in doc["maps"]] == ["tiny.map", "random-16-0.2-s0"]
    assert all([r["runner"] for r in m["rows"]] == ["astar"] for m in doc["maps"])
    assert doc["settings"]["algorithms"] == ["astar"] and doc["settings"]["random"] == ["16:0.2"]
    # the maps named, as given: the report kept only the folder, as if all of it had run
    assert doc["settings"]["map"] == ["tiny", "tiny.map"]
    assert doc["settings"]["maps"] == str(tmp_path)


@pytest.mark.parametrize("args, words", [
    (["--peers", "bogus"], "--peers 'bogus' is not valid; choose one of 'pyastar2d'"),
    (["--algorithms", "bogus", "--peers", ""], "--algorithms 'bogus' is not valid; choose"),
    (["--random", "16:0.2", "--per-map", "0", "--peers", ""],
     "--per-map 0 (every scenario line) has no meaning for random maps"),
    (["--seed", "-1", "--peers", ""], "'--seed': -1 is not in the range 0<=x<=4294967295"),
])
def test_bad_options_name_the_real_flag(monkeypatch, capsys, no_timing, args, words):
    code, out, err = run(monkeypatch, capsys, "bench", "grid", *args)
    assert_one_line(code, out, err, words)


@pytest.mark.parametrize("args, words", [
    (["--per-map", "10001"], "--per-map 10,001 is over the limit of 10,000 queries a map (0 "
                             "runs every scenario line)"),
    (["--random", "16:0.2", "--per-map", "1000000000"], "--per-map 1,000,000,000 is over the "
                                                        "limit of 10,000"),
    (["--random", "512:0.2", "--random", "4096:0.2", "--per-map", "33"],
     "--per-map 33 far queries on a 4096x4096 random map would each search its 16,777,216 "
     "cells for the optimum; at most 32 on a map that size"),
])
def test_too_many_queries_are_refused_before_any_map_is_made(monkeypatch, capsys, no_timing,
                                                             args, words):
    def made(*_args, **_kwargs):
        raise AssertionError("a map or its queries were made before --per-map was checked")

    for name in ("random_grid", "far_queries", "read_map"):
        monkeypatch.setattr(grid_mod, name, made)
    code, out, err = run(monkeypatch, capsys, "bench", "grid", "--peers", "", *args)
    assert_one_line(code, out, err, words)


def test_random_case_checks_its_queries_before_making_the_map(monkeypatch):
    def made(*_args, **_kwargs):
        raise AssertionError("the map was made")

    monkeypatch.setattr(grid_mod, "random_grid", made)
    with pytest.raises(OptionError, match=r"^per_map=2,049 far queries on a 512x512 random map"):
        grid_mod.random_case("512:0.2", per_map=2049, seed=0)
    assert grid_mod.MAX_RANDOM_CELL_QUERIES // (512 * 512) == 2048


def test_networkx_is_skipped_with_a_note_on_a_large_map(monkeypatch, capsys, tmp_path):
    small = dataclasses.replace(peers.PEERS["networkx"], max_cells=100)
    monkeypatch.setitem(peers.PEERS, "networkx", small)
    out_json = tmp_path / "r.json"
    code, out, err = run(monkeypatch, capsys, "bench", "grid", "--random", "16:0.2",
                         "--per-map", "2", "--algorithms", "astar", "--peers", "networkx",
                         "--json", str(out_json))
    assert code == 0, err
    assert "peer networkx skipped on random-16-0.2-s0: 16x16 is over its limit of 100" in err
    assert "networkx" not in out  # no column for a peer that did not run
    report, = json.loads(out_json.read_text())["maps"]
    assert [r["runner"] for r in report["rows"]] == ["astar"]
    assert "16x16 is over its limit" in report["skipped_peers"]["networkx"]


def test_networkx_limit_is_2048_squared():
    parse_random("4096:0.2")  # still a valid map: skyroute and the other peers run on it
    assert peers.skip_reason("networkx", Grid(np.zeros((2048, 2048), dtype=bool))) is None
    why = peers.skip_reason("networkx", Grid(np.zeros((2048, 2049), dtype=bool)))
    assert "over its limit of 4,194,304 cells" in why
    assert peers.skip_reason("pyastar2d", Grid(np.zeros((4096, 4096), dtype=bool))) is None


def test_json_report_records_what_a_rerun_needs(monkeypatch, capsys, tmp_path):
    """The seed, the versions (skyroute, numpy, numba, the peers) and the CPU: two
    reports are only comparable with them (it held Python's version and "x86_64")."""
    write_pair(tmp_path)
    out_json = tmp_path / "report.json"
    code, _, err = run(monkeypatch, capsys, "bench", "grid", "--maps", str(tmp_path),
                       "--algorithms", "astar", "--peers", "networkx", "--seed", "7",
                       "--json", str(out_json))
    assert code == 0, err
    doc = json.loads(out_json.read_text())
    m = doc["machine"]
    import skyroute
    assert doc["settings"]["seed"] == 7 and m["skyroute"] == skyroute.__version__
    assert m["packages"]["numpy"] == np.__version__ and m["packages"]["numba"]
    assert "networkx" in m["packages"] and m["cpu"] and m["cores"] >= 1 and m["date"]


def test_dubins_json_records_its_seed_and_machine(monkeypatch, capsys, tmp_path):
    from skyroute.bench import motion

    fake = {"radius": 1.7, "seed": 0, "repeats": 7, "ompl_calls": 5000,
            "threading_layer": "omp", "rows": []}
    monkeypatch.setattr(motion, "dubins_speed", lambda: fake)
    # the command leaves with os._exit once OMPL is imported (its leak report at exit)
    monkeypatch.setattr("skyroute.cli.bench_world_cmd._exit_past_ompl", lambda: None)
    out_json = tmp_path / "dubins.json"
    code, _, err = run(monkeypatch, capsys, "bench", "motion", "--dubins",
                       "--json", str(out_json))
    assert code == 0, err
    doc = json.loads(out_json.read_text())
    assert doc["dubins"] == fake and doc["machine"]["packages"]["numba"]
    assert "ompl" in doc["machine"]["packages"]


def test_cpu_model_names_family_and_model():
    """A VM's model name can be the bare vendor's, shared by two generations: the
    family and model numbers tell them apart (Zen 4 and Zen 5 are both "AMD EPYC")."""
    from skyroute.bench.machine import cpu_model

    two = ("processor\t: 0\nvendor_id\t: AuthenticAMD\ncpu family\t: 26\nmodel\t\t: 2\n"
           "model name\t: AMD EPYC\n\nprocessor\t: 1\ncpu family\t: 25\nmodel\t\t: 17\n"
           "model name\t: other\n")
    assert cpu_model(two) == "AMD EPYC (family 26, model 2)"
    assert cpu_model("Processor\t: ARMv8 rev 1\nHardware\t: BCM2835\n") == "ARMv8 rev 1"
    assert cpu_model("") != ""  # platform's answer
