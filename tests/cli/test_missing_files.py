"""A file or folder that is not there reads the same in every command: ``PATH: no such
file`` or ``PATH: no such folder``, naming the path as typed, one line, exit code 2,
nothing written. ``fleet simulate`` said "cannot read: No such file or directory", and
``db import nosuch`` named ``nosuch/database/orders.csv``, a file the user never typed."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.cli.test_cli import run

ROOT = Path(__file__).parents[2]
CITY = str(ROOT / "examples" / "city.csv")
CITY_POINTS = ["--start=-3.1890,55.9456", "--goal=-3.1850,55.9432"]
DB = ["--db", "sqlite:///store.db"]  # in the test's folder: it must not appear

CASES = [
    (["plan", "nosuch.map", "--start", "1,1", "--goal", "2,2"],
     "nosuch.map: no such file (bundled maps: "),
    (["prepare", "nosuch.map", "-o", "x.idx"], "nosuch.map: no such file (bundled maps: "),
    (["plan", "den312d", "--start", "50,76", "--goal", "60,13", "--index", "nosuch.idx"],
     "nosuch.idx: no such index file"),
    (["plan-world", "nosuch.csv", "--start", "0,0", "--goal", "1,1"], "nosuch.csv: no such file"),
    (["plan-world", CITY, *CITY_POINTS, "--boundary", "nosuch.geojson"],
     "nosuch.geojson: no such boundary file (or give MINLON,MINLAT,MAXLON,MAXLAT)"),
    (["fly", "nosuch.csv", "--start", "0,0", "--goal", "1,1"], "nosuch.csv: no such file"),
    (["fly", CITY, "--vehicle", "dubins", "--radius", "5", "--start=-3.1890,55.9456,0",
      "--targets", "nosuch.json"], "nosuch.json: no such file"),
    (["fleet", "simulate", "nosuch.yaml"], "nosuch.yaml: no such file"),
    (["fleet", "sweep", "nosuch.yaml"], "nosuch.yaml: no such file"),
    (["db", "import", "nosuch", *DB], "nosuch: no such folder"),
    (["deliver", "2024-01-01", "--data", "nosuch", *DB], "nosuch: no such folder"),
    (["data", "serve", "nosuch"], "nosuch: no such folder"),
    (["serve", "--data", "nosuch", *DB], "nosuch: no such folder"),
    (["serve", "--token-file", "nosuch.txt", *DB], "--token-file nosuch.txt: no such file"),
    (["bench", "grid", "--maps", "nosuch"], "nosuch: no such folder"),
    (["bench", "world", "--city", "nosuch.csv"], "nosuch.csv: no such file"),
    (["bench", "motion", "--data", "nosuch"], "--data nosuch: no such folder"),
    (["bench", "jobs", "--data", "nosuch"], "nosuch: no such folder"),
]


@pytest.mark.parametrize(("args", "says"), CASES, ids=[" ".join(a[:2]) + " " + a[-1]
                                                       if a[-1] != DB[-1] else
                                                       " ".join(a[:3]) for a, _ in CASES])
def test_a_missing_file_or_folder_is_named_alike(monkeypatch, capsys, tmp_path, args, says):
    monkeypatch.chdir(tmp_path)
    code, _out, err = run(monkeypatch, capsys, *args)
    assert code == 2
    assert err.startswith(f"skyroute: error: {says}") and err.count("\n") == 1, err
    assert list(tmp_path.iterdir()) == []  # no store, index or output begun


@pytest.mark.parametrize("args", [["fleet", "simulate", "."], ["fleet", "sweep", "."]])
def test_a_folder_given_for_a_file_is_named_so(monkeypatch, capsys, tmp_path, args):
    monkeypatch.chdir(tmp_path)
    code, _, err = run(monkeypatch, capsys, *args)
    assert code == 2 and err == "skyroute: error: .: a folder, not a file\n"


def test_a_file_given_for_a_folder_is_named_so(monkeypatch, capsys, tmp_path):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "orders").write_text("x")
    code, _, err = run(monkeypatch, capsys, "db", "import", "orders", *DB)
    assert code == 2 and err == "skyroute: error: orders: not a folder\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["orders"]


def test_a_folder_without_its_files_names_the_missing_file(monkeypatch, capsys, tmp_path):
    # the folder is there: then the file inside that is missing is the one to name
    monkeypatch.chdir(tmp_path)
    (tmp_path / "data").mkdir()
    code, _, err = run(monkeypatch, capsys, "db", "import", "data", *DB)
    assert code == 2
    assert err == f"skyroute: error: {Path('data') / 'database' / 'orders.csv'}: no such file\n"
