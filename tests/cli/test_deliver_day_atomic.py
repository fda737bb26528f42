"""``skyroute deliver``: a day's rows in the store and its files on disk change together.

The rows were committed before the files were renamed into place, so a rename that
failed (a full disk, a permission) left the new flight stored beside the earlier run's
files. Now the rows are committed after the renames, before the earlier files' backups
are dropped: a failed rename rolls the rows back, a failed commit puts the files back.
"""

from __future__ import annotations

import json
from contextlib import contextmanager
from pathlib import Path

import pytest
import sqlalchemy as sa

from tests.cli.test_cli import run
from tests.conftest import ROOT
from tests.rename_failures import failing_rename

EXAMPLE = str(ROOT / "examples" / "lunch")
DAY = "2024-01-03"


@pytest.fixture(params=["sqlite", "postgresql"])
def db(request, tmp_path) -> str:
    if request.param == "sqlite":
        return f"sqlite:///{tmp_path / 'd.db'}"
    return request.getfixturevalue("fresh_pg")


def stored(url: str, day: str) -> tuple | None:
    """The day's stored run (method, moves), with its counts of deliveries and moves;
    None for a day not stored."""
    engine = sa.create_engine(url)
    try:
        with engine.connect() as c:
            run_ = c.execute(sa.text("select settings, moves from runs where delivery_date "
                                     "= :d"), {"d": day}).first()
            if run_ is None:
                return None
            n = {t: c.scalar(sa.text(f"select count(*) from {t} where delivery_date = :d"),
                             {"d": day}) for t in ("deliveries", "flightpath")}
    finally:
        engine.dispose()
    return json.loads(run_[0])["method"], run_[1], n["deliveries"], n["flightpath"]


def on_disk(out: Path) -> dict[str, bytes]:
    """Every file under ``out`` (temporary and backup files too) with its bytes."""
    if not out.exists():
        return {}
    return {p.relative_to(out).as_posix(): p.read_bytes() for p in out.rglob("*")}


def deliver(monkeypatch, capsys, db: str, out: Path, *args: str) -> tuple[int, str]:
    code, _, err = run(monkeypatch, capsys, "deliver", *args, "--data", EXAMPLE, "--db", db,
                       "--out", str(out), "--no-plot")
    return code, err


@contextmanager
def failing(how: str, at: int = 2):
    """In the block, the ``at``-th rename of a staged file into place (from 1) fails (a
    full disk), or (``how`` "commit") the commit of a transaction that wrote flight path
    rows does (the server gone, a disk error: as SQLAlchemy reports a driver's error)."""

    def wrote(conn, _cursor, statement, *_args):
        if statement.lstrip().upper().startswith("INSERT INTO FLIGHTPATH"):
            conn.info["flown"] = True

    def commit(conn):
        if conn.info.pop("flown", False):
            raise sa.exc.OperationalError("COMMIT", {}, Exception("disk I/O error"))

    if how == "rename":
        with pytest.MonkeyPatch.context() as mp:
            failing_rename(mp, at)
            yield
        return
    events = [("before_cursor_execute", wrote), ("commit", commit)]
    for name, fn in events:
        sa.event.listen(sa.engine.Engine, name, fn)
    try:
        yield
    finally:
        for name, fn in events:
            sa.event.remove(sa.engine.Engine, name, fn)


@pytest.mark.parametrize("flown_before", [True, False])
@pytest.mark.parametrize("how", ["rename", "commit"])
def test_a_day_whose_rename_or_commit_fails_keeps_its_rows_and_files(
        monkeypatch, capsys, tmp_path, fly_once, db, flown_before, how):
    out = tmp_path / "out"
    if flown_before:  # the day stored with its files by an earlier run, another method
        code, err = deliver(monkeypatch, capsys, db, out, DAY, "--method", "greedy")
        assert code == 0, err
    else:  # a first-time day: its orders stored, nothing flown
        code, _, err = run(monkeypatch, capsys, "db", "import", EXAMPLE, "--db", db)
        assert code == 0, err
    rows, files = stored(db, DAY), on_disk(out)
    assert (rows is not None and rows[0] == "greedy") == flown_before
    assert len(files) == (2 if flown_before else 0)
    with failing(how, at=2):  # the report's rename: the GeoJSON's is done, then undone
        if how == "rename":
            code, err = deliver(monkeypatch, capsys, db, out, DAY)
            assert code == 2 and len(err.strip().splitlines()) == 1, err
            assert "report-03-01-2024.json: cannot write: No space left on device" in err
        else:  # the driver's error: one line, exit 2 (it was a traceback)
            code, err = deliver(monkeypatch, capsys, db, out, DAY)
            assert code == 2 and len(err.strip().splitlines()) == 1, err
            assert err.startswith("skyroute: error: the store's database failed: disk I/O "
                                  "error"), err
    # the store's day and the files as they were: the earlier flight, or none
    assert stored(db, DAY) == rows
    assert on_disk(out) == files
    # a normal run writes both
    code, err = deliver(monkeypatch, capsys, db, out, DAY)
    assert code == 0, err
    method, moves, delivered, path_rows = stored(db, DAY)
    report = json.loads((out / "report-03-01-2024.json").read_text())
    assert (method, moves, delivered) == (report["settings"]["method"], report["moves"],
                                          report["orders_delivered"]) == \
        ("milp", path_rows, delivered)
    line = json.loads((out / "drone-03-01-2024.geojson").read_text())
    assert len(line["features"][0]["geometry"]["coordinates"]) == moves + 1


def test_a_range_stops_at_the_day_whose_rename_fails_with_that_day_as_it_was(
        monkeypatch, capsys, tmp_path, fly_once, db):
    out = tmp_path / "out"
    code, err = deliver(monkeypatch, capsys, db, out, "--from", "2024-01-02", "--to", DAY,
                        "--method", "greedy")
    assert code == 0, err
    before = stored(db, DAY), on_disk(out)
    with failing("rename", at=4):  # the second day's report (two files a day)
        code, err = deliver(monkeypatch, capsys, db, out, "--from", "2024-01-02", "--to",
                            DAY)
    assert code == 2 and "report-03-01-2024.json: cannot write: No space left" in err, err
    # the first day stored anew with its files, the second as it was, rows and files
    assert stored(db, "2024-01-02")[0] == "milp"
    assert json.loads((out / "report-02-01-2024.json").read_text())["settings"][
        "method"] == "milp"
    assert stored(db, DAY) == before[0]
    assert {k: v for k, v in on_disk(out).items() if "03-01" in k} == \
        {k: v for k, v in before[1].items() if "03-01" in k}
