"""``skyroute deliver``, ``db`` and ``data`` from the command line: files, tables, errors."""

from __future__ import annotations

import json

import pytest

from tests.cli.test_cli import run
from tests.conftest import ROOT

EXAMPLE = str(ROOT / "examples" / "lunch")


def test_one_day_writes_its_files_and_table(monkeypatch, capsys, tmp_path, fly_once):
    db = f"sqlite:///{tmp_path / 'd.db'}"
    code, out, err = run(monkeypatch, capsys, "deliver", "2024-01-03", "--data", EXAMPLE,
                         "--db", db, "--out", str(tmp_path / "out"))
    assert code == 0, err
    assert "delivery day 2024-01-03" in out and "money delivered" in out
    files = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert files == ["drone-03-01-2024.geojson", "drone-03-01-2024.png",
                     "report-03-01-2024.json"]
    assert (tmp_path / "out" / "drone-03-01-2024.png").read_bytes()[:4] == b"\x89PNG"
    report = json.loads((tmp_path / "out" / "report-03-01-2024.json").read_text())
    assert report["orders_placed"] == 36 and 0 < report["moves"] <= 1500
    # a day without orders: nothing flown, no money to count
    code, out, err = run(monkeypatch, capsys, "deliver", "2024-02-01", "--data", EXAMPLE,
                         "--db", db, "--out", str(tmp_path / "out"), "--json")
    assert code == 0, err
    empty = json.loads(out)
    assert empty["orders_placed"] == 0 and empty["moves"] == 0 and empty["money_pct"] is None


def test_range_prints_a_monthly_table(monkeypatch, capsys, tmp_path, fly_once):
    code, out, err = run(monkeypatch, capsys, "deliver", "--from", "2024-01-01", "--to",
                         "2024-01-02", "--data", EXAMPLE, "--db",
                         f"sqlite:///{tmp_path / 'r.db'}", "--out", str(tmp_path))
    assert code == 0, err
    assert "2 days" in out and "2024-01" in out and "mean %" in out
    assert not list(tmp_path.glob("*.png"))  # no pictures for a range unless asked


def test_db_init_and_import(monkeypatch, capsys, tmp_path):
    db = f"sqlite:///{tmp_path / 'i.db'}"
    code, out, _ = run(monkeypatch, capsys, "db", "init", "--db", db)
    assert code == 0 and "revision 0002" in out
    code, out, _ = run(monkeypatch, capsys, "db", "import", EXAMPLE, "--db", db)
    assert code == 0 and "108 orders added" in " ".join(out.split())
    code, out, _ = run(monkeypatch, capsys, "db", "import", EXAMPLE, "--db", db)
    assert code == 0 and "0 orders added, 108 already there" in " ".join(out.split())


@pytest.mark.parametrize("args, words", [
    (["deliver", "2024-13-01", "--data", EXAMPLE], "DATE '2024-13-01': expected a date"),
    (["deliver", "--from", "2024-01-02", "--data", EXAMPLE], "give a DATE, or both --from"),
    (["deliver", "2024-01-01", "--from", "2024-01-01", "--to", "2024-01-02", "--data",
      EXAMPLE], "give a DATE, or both --from"),
    (["deliver", "--from", "2024-01-02", "--to", "2024-01-01", "--data", EXAMPLE],
     "is before --from"),
    (["deliver", "2024-01-01"], "give exactly one of --data DIR and --source URL"),
    (["deliver", "2024-01-01", "--source", "ftp://x"], "expected an http:// or https:// URL"),
    (["deliver", "2024-01-01", "--data", EXAMPLE, "--method", "magic"],
     "--method 'magic' is not valid"),
    (["deliver", "2024-01-01", "--data", EXAMPLE, "--db", "nonsense"], "not a database URL"),
    (["data", "serve", "/nonexistent"], "not a data folder"),
    (["data", "serve", EXAMPLE, "--port", "99999"], "is not in the range 0<=x<=65535"),
    (["data", "serve", EXAMPLE, "--port", "-1"], "is not in the range 0<=x<=65535"),
])
def test_bad_input_is_one_line(monkeypatch, capsys, tmp_path, args, words):
    monkeypatch.chdir(tmp_path)
    code, _out, err = run(monkeypatch, capsys, *args)
    assert code == 2
    assert words in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_source_needs_stored_orders(monkeypatch, capsys, tmp_path):
    from pathlib import Path

    from skyroute.delivery.serve import serve_in_thread

    server, url = serve_in_thread(Path(EXAMPLE))
    try:
        db = f"sqlite:///{tmp_path / 'e.db'}"
        code, _, err = run(monkeypatch, capsys, "deliver", "2024-01-01", "--source", url,
                           "--db", db, "--out", str(tmp_path))
        assert code == 2 and "no orders stored" in err and "skyroute db import" in err
        assert run(monkeypatch, capsys, "db", "import", EXAMPLE, "--db", db)[0] == 0
        code, out, err = run(monkeypatch, capsys, "deliver", "2024-01-01", "--source", url,
                             "--db", db, "--out", str(tmp_path), "--json", "--no-plot")
        assert code == 0, err
        assert json.loads(out)["orders_placed"] == 36
    finally:
        server.shutdown()
        server.server_close()
