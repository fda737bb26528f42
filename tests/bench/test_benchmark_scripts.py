"""The measuring scripts in benchmarks/ (the commands behind docs/benchmarks.md's figures)
run on tiny inputs: their output's shape, numbers positive and finite, and one-line
errors for a wrong tree or map."""

from __future__ import annotations

import importlib.util
import json
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import skyroute
from tests.conftest import MOVINGAI, ROOT

SCRIPTS = ROOT / "benchmarks"
SRC = Path(skyroute.__file__).resolve().parents[1]  # the skyroute under test


def script(name: str, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPTS / name), *args], capture_output=True,
                          text=True, env={**os.environ, "PYTHONPATH": str(SRC)}, timeout=600)


def positive(x) -> bool:
    return isinstance(x, float) and math.isfinite(x) and x > 0


def one_line_error(proc, name: str, words: str) -> None:
    assert proc.returncode == 2 and proc.stdout == "", proc.stderr
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert proc.stderr.startswith(f"{name}: error: ") and words in proc.stderr, proc.stderr


@pytest.mark.parametrize("name", ["plan_ab.py", "plan_overhead.py", "prepare_memory.py",
                                  "prepare_time.py", "world_queries.py", "hybrid_cpu.py",
                                  "flat_pair_ab.py", "step_cpu.py"])
def test_each_script_has_a_help(name):
    proc = script(name, "--help")
    assert proc.returncode == 0 and proc.stdout.startswith(f"usage: {name}"), proc.stderr


@pytest.mark.slow
def test_plan_ab_times_both_trees_on_the_same_queries(tmp_path):
    out = tmp_path / "ab.json"
    proc = script("plan_ab.py", str(SRC), str(SRC.parent), "--random", "24:0.1",
                  "--queries", "3", "--rounds", "2", "--processes", "1", "--algorithms",
                  "astar,jps,prepared", "--cold-mb", "1", "--json", str(out))
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(out.read_text())
    rows = doc["rows"]
    assert [(r["map"], r["runner"]) for r in rows] == [
        ("random-24-0.1-s0", "astar"), ("random-24-0.1-s0", "jps"),
        ("random-24-0.1-s0", "prepared")]
    for r in rows:
        assert len(r["a_ms"]) == len(r["b_ms"]) == 1 and r["same_lengths"]
        assert all(positive(x) for x in [*r["a_ms"], *r["b_ms"], r["b_over_a"]]), r
    for label in "AB":
        (run,) = doc["processes"][label]
        assert Path(run["skyroute"]).resolve().is_relative_to(SRC)
        for m in run["maps"]:
            for timing in m["runners"].values():
                assert len(timing["rounds_ms"]) == 2 and len(timing["costs"]) == 3
                assert all(positive(c) for c in timing["costs"])
    table = [line for line in proc.stdout.splitlines() if line.startswith("| random")]
    assert len(table) == 3 and all(line.endswith("| yes |") for line in table)


@pytest.mark.slow
@pytest.mark.shared_data
def test_plan_ab_on_a_movingai_map(tmp_path):
    out = tmp_path / "ab.json"
    proc = script("plan_ab.py", str(SRC), str(SRC), "--map",
                  str(MOVINGAI / "random-32-32-10.map"), "--queries", "2", "--rounds", "1",
                  "--processes", "1", "--algorithms", "jps", "--json", str(out))
    assert proc.returncode == 0, proc.stderr
    (row,) = json.loads(out.read_text())["rows"]
    assert row["map"] == "random-32-32-10.map" and positive(row["b_over_a"])


@pytest.mark.parametrize("args, words", [
    (["no/such/tree", "."], "tree 'no/such/tree': neither a folder nor a commit of "),
    (["docs", "."], "tree 'docs': the folder holds no skyroute package"),
    ([".", ".", "--map", "no/such.map"], "--map no/such.map: no such file"),
    ([".", ".", "--random", "512"], "--random '512': expected SIDE:SHARE"),
    ([".", ".", "--algorithms", "bfs"], "--algorithms 'bfs': choose from astar, jps, "
                                        "prepared"),
])
def test_plan_ab_refuses_a_wrong_tree_or_map(monkeypatch, args, words):
    monkeypatch.chdir(ROOT)
    one_line_error(script("plan_ab.py", *args), "plan_ab.py", words)


def test_plan_ab_names_the_line_of_a_broken_map(tmp_path):
    (tmp_path / "bad.map").write_text("type octile\nheight 2\nwidth x\nmap\n..\n..\n")
    (tmp_path / "bad.map.scen").write_text("version 1\n")
    proc = script("plan_ab.py", str(SRC), str(SRC), "--map", str(tmp_path / "bad.map"))
    one_line_error(proc, "plan_ab.py", "bad.map:3: width")


@pytest.mark.skipif(shutil.which("git") is None or not (ROOT / ".git").exists(),
                    reason="needs git and a checkout")
def test_a_tree_given_as_a_commit_is_its_archived_src():
    spec = importlib.util.spec_from_file_location("bench_common", SCRIPTS / "_common.py")
    common = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(common)
    keep: list = []
    tree = common.resolve_tree("HEAD", keep, ROOT)
    assert (tree / "skyroute" / "__init__.py").is_file() and tree.name == "src"
    assert common.resolve_tree(str(ROOT), keep) == (ROOT / "src").resolve()
    for tmp in keep:
        tmp.cleanup()
    # and the random maps are the bench's
    from skyroute.bench.random_maps import random_grid

    assert (common.random_blocked(40, 0.3, 5) == random_grid(40, 0.3, 5).blocked).all()


def test_flat_pair_ab_times_both_trees_in_one_process(tmp_path):
    (tmp_path / "tiny.map").write_text("type octile\nheight 3\nwidth 4\nmap\n@...\n....\n"
                                       "..@.\n")
    proc = script("flat_pair_ab.py", str(SRC), str(SRC.parent), "--map",
                  str(tmp_path / "tiny.map"), "--number", "20", "--rounds", "2")
    assert proc.returncode == 0, proc.stderr
    assert "tiny.map, (1, 0) -> (2, 0)" in proc.stdout
    rows = [line.split(" | ") for line in proc.stdout.splitlines() if line.startswith("| ")]
    assert [r[0] for r in rows[1:]] == ["| plan() astar (us)", "| plan() jps (us)",
                                        "| flat_pair alone (ns)"]
    for r in rows[1:]:
        assert all(positive(float(x)) for cell in r[1:3] for x in cell.split(" / ")), r
        assert r[4].endswith(" of 2 |")


@pytest.mark.parametrize("args, words", [
    (["no/such/tree", ".", "--map", "README.md"], "tree 'no/such/tree': neither a folder "
                                                  "nor a commit of "),
    (["docs", ".", "--map", "README.md"], "tree 'docs': the folder holds no skyroute"),
    ([".", ".", "--map", "no/such.map"], "--map no/such.map: no such file"),
    ([".", ".", "--map", "README.md", "--rounds", "0"], "--rounds 0: expected 1 to 1000"),
])
def test_flat_pair_ab_refuses_a_wrong_tree_or_map(monkeypatch, args, words):
    monkeypatch.chdir(ROOT)
    one_line_error(script("flat_pair_ab.py", *args), "flat_pair_ab.py", words)


@pytest.mark.slow
def test_plan_overhead_splits_a_call(tmp_path):
    out = tmp_path / "overhead.json"
    proc = script("plan_overhead.py", "--random", "16:0.1", "--algorithms", "astar,jps",
                  "--repeat", "2", "--number", "200", "--json", str(out))
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(out.read_text())
    assert doc["start"] == [0, 0] and doc["goal"] == [1, 0]
    for alg in ("astar", "jps"):
        row = doc["algorithms"][alg]
        parts = ["plan", "option set", "space_of", "flat_pair", "runner lookup",
                 "compiled call", "of_search"]
        # a part is its calls less an empty call's: only the larger ones are surely > 0
        assert all(math.isfinite(row[p]) for p in parts), row
        assert all(positive(row[p]) for p in ("plan", "compiled call", "of_search")), row
        assert math.isfinite(row["rest"]) and row["cost"] == 1.0
        assert sum(row[p] for p in parts[1:]) + row["rest"] == pytest.approx(row["plan"])
    assert "| compiled call |" in proc.stdout and "| plan() (whole) |" in proc.stdout


@pytest.mark.parametrize("args, words", [
    (["--map", "no/such.map"], "--map no/such.map: no such file"),
    (["--start", "1,2"], "give --start and --goal together"),
    (["--start", "a", "--goal", "1,1"], "--start 'a': expected X,Y"),
    (["--random", "32:2"], "--random '32:2': expected SIDE:SHARE"),
])
def test_plan_overhead_refuses_a_wrong_map_or_query(args, words):
    one_line_error(script("plan_overhead.py", *args, "--number", "10"), "plan_overhead.py",
                   words)


def test_plan_overhead_names_a_cell_off_the_map():
    proc = script("plan_overhead.py", "--random", "8:0.0", "--start", "0,0", "--goal",
                  "9,0", "--number", "10")
    one_line_error(proc, "plan_overhead.py", "goal")


@pytest.mark.slow
def test_prepare_memory_reports_each_share(tmp_path):
    out = tmp_path / "memory.json"
    proc = script("prepare_memory.py", "--side", "48", "--share", "0.1", "0.3",
                  "--warm-side", "16", "--json", str(out))
    assert proc.returncode == 0, proc.stderr
    rows = json.loads(out.read_text())
    assert [r["map"] for r in rows] == ["random-48-0.1-s0", "random-48-0.3-s0"]
    for r in rows:
        assert positive(r["seconds"]) and r["index_bytes"] > 0 and r["added_bytes"] >= 0
        assert r["maxrss_after_bytes"] >= r["maxrss_before_bytes"] > 0
        assert r["accelerator"] in ("table", "hierarchy", "landmarks", "jump")
    assert sum(line.startswith("| random-48-") for line in proc.stdout.splitlines()) == 2


@pytest.mark.parametrize("args, words", [
    (["--side", "4"], "--side 4 must be 8..4096"),
    (["--share", "1.5"], "--share 1.5 must be 0 <= SHARE < 1"),
    (["--side", "64", "--warm-side", "128"], "--warm-side 128 must be 8..--side (64)"),
])
def test_prepare_memory_refuses_a_wrong_map(args, words):
    one_line_error(script("prepare_memory.py", *args), "prepare_memory.py", words)


@pytest.mark.slow
def test_prepare_time_times_each_tree_in_turn(tmp_path):
    out = tmp_path / "time.json"
    proc = script("prepare_time.py", str(SRC), str(SRC.parent), "--side", "48", "--builds",
                  "2", "--rounds", "1", "--json", str(out))
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(out.read_text())
    assert [r["tree"] for r in doc["runs"]] == [str(SRC), str(SRC.parent)]
    for r in doc["runs"]:
        assert len(r["seconds"]) == 2 and all(positive(x) for x in r["seconds"])
        assert all(k in ("table", "hierarchy", "landmarks", "jump") for k in r["accelerator"])
        assert r["load"].startswith("load ")
    assert [line.split(": ")[0] for line in proc.stdout.splitlines()] == [str(SRC), str(SRC.parent)]


@pytest.mark.parametrize("args, words", [
    (["src", "--side", "4"], "--side 4: expected 16 to 4096"),
    (["src", "--share", "1.5"], "--share 1.5: expected 0 <= SHARE < 1"),
    (["src", "--builds", "0"], "--builds 0: expected 1 to 100"),
    (["no-such-tree-or-commit"], "neither a folder nor a commit"),
])
def test_prepare_time_refuses_wrong_input(args, words):
    one_line_error(script("prepare_time.py", *args), "prepare_time.py", words)


def test_world_queries_counts_segments_through_shared_faces(tmp_path):
    # two boxes sharing the face north = 5 (and a lone one): the segment along it, run
    # past both ends, passes through the building; this tree calls none of them free
    city, out = tmp_path / "two.csv", tmp_path / "wq.json"
    city.write_text("lat0 37.792480, lon0 -122.397450\n"
                    "posX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n"
                    "0,0,10,5,10,10\n10,0,10,5,10,10\n60,60,10,5,5,10\n")
    proc = script("world_queries.py", str(SRC), "--city", str(city), "--safety", "0",
                  "--rounds", "1", "--repeats", "1", "--json", str(out))
    assert proc.returncode == 0, proc.stderr
    (run,) = json.loads(out.read_text())["runs"]
    assert run["shared_faces"] == 1 and run["through"] == 1
    assert run["through_called_free"] == 0
    assert positive(run["load_ms"]) and all(positive(v) for v in run["ms"].values())


@pytest.mark.parametrize("args, words", [
    (["src", "--city", "no-such.csv"], "--city no-such.csv: no such file"),
    (["src", "--city", __file__, "--rounds", "0"], "--rounds 0: expected 1 to 100"),
])
def test_world_queries_refuses_wrong_input(args, words):
    one_line_error(script("world_queries.py", *args), "world_queries.py", words)


def one_box(tmp_path) -> Path:
    """A colliders.csv city of one box, 10 m square round (30, 0) north, east."""
    city = tmp_path / "one.csv"
    city.write_text("lat0 37.792480, lon0 -122.397450\n"
                    "posX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n30,0,10,5,5,10\n")
    return city


def test_hybrid_cpu_reports_each_query(tmp_path):
    # the box between start and goal: a path round it, longer than the straight 60 m; the
    # start's north is negative, typed as is (argparse took it for an unknown option)
    proc = script("hybrid_cpu.py", str(one_box(tmp_path)), "-10,0,0;50,0", "--radius", "5",
                  "--reps", "2")
    assert proc.returncode == 0, proc.stderr
    (line,) = proc.stdout.splitlines()
    row = json.loads(line)
    assert row["query"] == "-10,0,0;50,0" and row["status"] == "found"
    assert row["expanded"] > 0 and 60 < row["length"] < 80 and len(row["sha1"]) == 10
    assert len(row["cpu"]) == 2 and all(c >= 0 for c in row["cpu"])


@pytest.mark.parametrize("args, words", [
    (["no-such.csv", "0,0;1,1"], "no-such.csv: no such file"),
    ([__file__, "0,0"], "query '0,0': expected START;GOAL"),
    ([__file__, "0,0;a,1"], "query '0,0;a,1': 'a,1' is not N,E or N,E,HEADING"),
    ([__file__, "-1.5,0;a,1"], "query '-1.5,0;a,1': 'a,1' is not N,E or N,E,HEADING"),
    ([__file__, "-.5,0;1,1", "--reps", "0"], "--reps 0: expected 1 to 100"),
])
def test_hybrid_cpu_refuses_wrong_input(args, words):
    one_line_error(script("hybrid_cpu.py", *args), "hybrid_cpu.py", words)


def test_step_cpu_reports_each_query_and_the_totals(tmp_path):
    # round the box from south of it to north of it (the step is 0.00015 degrees, about
    # 17 m north), a start with a negative north
    proc = script("step_cpu.py", "--city", str(one_box(tmp_path)), "-10,0;70,0", "0,20;0,-20",
                  "--reps", "2")
    assert proc.returncode == 0, proc.stderr
    *rows, total = [json.loads(line) for line in proc.stdout.splitlines()]
    assert [r["query"] for r in rows] == ["-10,0;70,0", "0,20;0,-20"]
    for r in rows:
        assert r["status"] == "found" and r["moves"] >= 2 and r["expanded"] >= r["moves"]
        assert len(r["sha1"]) == 10 and len(r["cpu"]) == 2 and all(c >= 0 for c in r["cpu"])
    assert rows[0]["moves"] >= 4  # 80 m north, ending within a step: ceil(80 / 16.7 - 1)
    assert total["total"] == 2 and len(total["sha1"]) == 10
    assert total["cpu"] == pytest.approx([sum(r["cpu"][k] for r in rows) for k in (0, 1)],
                                         abs=1e-3)


@pytest.mark.parametrize("args, words", [
    (["--city", "no-such.csv", "0,0;1,1"], "no-such.csv: no such file"),
    (["--city", __file__], "--city: give one or more queries 'N,E;N,E'"),
    (["--city", __file__, "-3,0;1,1,90"], "query '-3,0;1,1,90': '1,1,90' is not N,E"),
    (["--ilp", "no/such"], "--ilp no/such: no such folder"),
    (["--ilp", ".", "0,0;1,1"], "--ilp: the queries are the ILP places' pairs"),
    (["--city", __file__, "0,0;1,1", "--reps", "0"], "--reps 0: expected 1 to 100"),
])
def test_step_cpu_refuses_wrong_input(args, words):
    one_line_error(script("step_cpu.py", *args), "step_cpu.py", words)
