"""``skyroute deliver``, ``db`` and ``data`` from the command line: files, tables, errors."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from tests.cli.test_cli import out_blocked_by, run
from tests.conftest import ROOT
from tests.jobs.failing import failing_workers

EXAMPLE = str(ROOT / "examples" / "lunch")


def _files_row(out: str) -> list[str]:
    """The cells of the table's "files" row, one file a line."""
    rows = [line.split("│") for line in out.splitlines() if line.count("│") == 3]
    start = next(k for k, r in enumerate(rows) if r[1].strip() == "files")
    return [r[2].strip() for r in rows[start:]]


def test_one_day_writes_its_files_and_table(monkeypatch, capsys, tmp_path, fly_once):
    monkeypatch.setenv("COLUMNS", "400")  # whole paths in the table, not folded
    db = f"sqlite:///{tmp_path / 'd.db'}"
    code, out, err = run(monkeypatch, capsys, "deliver", "2024-01-03", "--data", EXAMPLE,
                         "--db", db, "--out", str(tmp_path / "out"))
    assert code == 0, err
    assert "delivery day 2024-01-03" in out and "money delivered" in out
    files = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert files == ["drone-03-01-2024.geojson", "drone-03-01-2024.png",
                     "report-03-01-2024.json"]
    # the table named only the GeoJSON
    assert _files_row(out) == [str(tmp_path / "out" / f) for f in (
        "drone-03-01-2024.geojson", "report-03-01-2024.json", "drone-03-01-2024.png")]
    code, out, err = run(monkeypatch, capsys, "deliver", "2024-01-03", "--data", EXAMPLE,
                         "--db", db, "--out", str(tmp_path / "bare"), "--no-plot")
    assert code == 0, err
    assert _files_row(out) == [str(tmp_path / "bare" / f) for f in (
        "drone-03-01-2024.geojson", "report-03-01-2024.json")]
    assert sorted(p.name for p in (tmp_path / "bare").iterdir()) == [
        "drone-03-01-2024.geojson", "report-03-01-2024.json"]
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
    # the summary is one line (as the monthly table's title it wrapped at the table's
    # width: "2 days, 1.2 s with 1 job(s): money" over "delivered mean 99.24%, worst")
    summary = (r"2 days, [\d.]+ s with 1 job\(s\): money delivered mean [\d.]+%, "
               r"worst [\d.]+% on 2024-01-0[12]")
    assert any(re.fullmatch(summary, line.strip()) for line in out.splitlines()), out
    assert not list(tmp_path.glob("*.png"))  # no pictures for a range unless asked
    # where the files went (a range said nothing of them): a GeoJSON and a report a day
    assert len(list(tmp_path.glob("*-0?-01-2024.*"))) == 4
    assert f"wrote 4 files to {tmp_path}" in " ".join(out.split())


def test_db_init_and_import(monkeypatch, capsys, tmp_path):
    db = f"sqlite:///{tmp_path / 'i.db'}"
    code, out, _ = run(monkeypatch, capsys, "db", "init", "--db", db)
    assert code == 0 and "revision 0006" in out
    code, out, _ = run(monkeypatch, capsys, "db", "import", EXAMPLE, "--db", db)
    assert code == 0 and "108 orders added" in " ".join(out.split())
    code, out, _ = run(monkeypatch, capsys, "db", "import", EXAMPLE, "--db", db)
    assert code == 0 and "0 orders added, 108 already there" in " ".join(out.split())


@pytest.mark.parametrize("args, words", [
    # a day the calendar lacks says so: "expected a date YYYY-MM-DD" named the form it has
    (["deliver", "2024-13-01", "--data", EXAMPLE],
     "DATE '2024-13-01': no such day (month must be in 1..12)"),
    (["deliver", "2024-02-30", "--data", EXAMPLE],
     "DATE '2024-02-30': no such day (day is out of range for month)"),
    (["deliver", "03-01-2024", "--data", EXAMPLE], "DATE '03-01-2024': expected a date "
                                                   "YYYY-MM-DD"),
    (["data", "synth", "x", "--start", "2023-02-29"], "--start '2023-02-29': no such day"),
    # YYYY-MM-DD only, as the service reads dates: Python 3.11's fromisoformat took the
    # basic form and a week date as days, and other scripts' digits (Arabic-Indic here)
    # were "no such day (Invalid isoformat string ...)"
    (["data", "synth", "x", "--start", "20240103"], "--start '20240103': expected a date "
                                                    "YYYY-MM-DD"),
    (["data", "synth", "x", "--start", "2024-W01-3"], "--start '2024-W01-3': expected a "
                                                      "date YYYY-MM-DD"),
    (["deliver", "\u0662\u0660\u0662\u0664-\u0660\u0661-\u0660\u0663", "--data", EXAMPLE],
     "DATE '\u0662\u0660\u0662\u0664-\u0660\u0661-\u0660\u0663': expected a date YYYY-MM-DD"),
    (["deliver", "--from", "2024-01-02", "--data", EXAMPLE], "give a DATE, or both --from"),
    (["deliver", "2024-01-01", "--from", "2024-01-01", "--to", "2024-01-02", "--data",
      EXAMPLE], "give a DATE, or both --from"),
    (["deliver", "--from", "2024-01-02", "--to", "2024-01-01", "--data", EXAMPLE],
     "is before --from"),
    (["deliver", "--from", "2000-01-01", "--to", "2999-12-31", "--data", EXAMPLE],
     "--from 2000-01-01 --to 2999-12-31 is 365,243 days, over the limit of 3,660"),
    (["deliver", "2024-01-01"], "give exactly one of --data DIR and --source URL"),
    (["deliver", "2024-01-01", "--source", "ftp://x"], "expected an http:// or https:// URL"),
    (["deliver", "2024-01-01", "--data", EXAMPLE, "--method", "magic"],
     "--method 'magic' is not valid"),
    (["deliver", "2024-01-01", "--data", EXAMPLE, "--db", "nonsense"], "not a database URL"),
    # Heroku's and psql's spelling: a URL, of a kind SQLAlchemy does not know (it said
    # "not a database URL")
    (["deliver", "2024-01-01", "--data", EXAMPLE, "--db", "postgres://u@127.0.0.1/db"],
     "--db 'postgres://u@127.0.0.1/db': SQLAlchemy knows no database 'postgres' (e.g. "),
    # a driver it does not know, of a database it knows: not "knows no database
    # 'postgresql'"
    (["deliver", "2024-01-01", "--data", EXAMPLE, "--db", "postgresql+psycopg3://u@h/db"],
     "--db 'postgresql+psycopg3://u@h/db': SQLAlchemy has no driver 'psycopg3' for "
     "postgresql (e.g. "),
    (["data", "serve", "/nonexistent"], "/nonexistent: no such folder"),
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
        assert not (tmp_path / "e.db").exists()  # refused: no new empty store left
        assert run(monkeypatch, capsys, "db", "import", EXAMPLE, "--db", db)[0] == 0
        code, out, err = run(monkeypatch, capsys, "deliver", "2024-01-01", "--source", url,
                             "--db", db, "--out", str(tmp_path), "--json", "--no-plot")
        assert code == 0, err
        assert json.loads(out)["orders_placed"] == 36
    finally:
        server.shutdown()
        server.server_close()


def _stored_rows(path) -> dict[str, int]:
    """Rows per table of the SQLite store at ``path`` (none when there is no file)."""
    import sqlite3

    if not path.exists():
        return {}
    with sqlite3.connect(path) as c:
        names = [r[0] for r in c.execute("select name from sqlite_master where type='table'"
                                         " and name != 'alembic_version'")]
        return {n: c.execute(f'select count(*) from "{n}"').fetchone()[0] for n in names}


def _no_flying(*_args, **_kwargs):
    raise AssertionError("a day was flown before its output files were checked")


@pytest.mark.parametrize("dates, blocker, words", [
    (["2024-01-01"], "file", "is not a folder"),  # --out names a regular file
    (["2024-01-01"], "report-01-01-2024.json", "it is a folder"),
    (["2024-01-01"], "drone-01-01-2024.png", "it is a folder"),
    # a range: the second day's file is bad, so the first day is neither stored nor written
    (["--from", "2024-01-01", "--to", "2024-01-02"], "report-02-01-2024.json",
     "it is a folder"),
    (["--from", "2024-01-01", "--to", "2024-01-02", "--plot"], "drone-02-01-2024.png",
     "it is a folder"),
])
def test_bad_out_fails_before_flying_or_storing(monkeypatch, capsys, tmp_path, dates,
                                                blocker, words):
    monkeypatch.setattr("skyroute.jobs.deliver.plan_day", _no_flying)
    out = out_blocked_by(tmp_path, blocker)
    before = sorted(p.name for p in tmp_path.rglob("*"))
    code, _, err = run(monkeypatch, capsys, "deliver", *dates, "--data", EXAMPLE,
                       "--db", f"sqlite:///{tmp_path / 'o.db'}", "--out", str(out))
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1, err
    assert not any(_stored_rows(tmp_path / "o.db").values())
    assert sorted(p.name for p in tmp_path.rglob("*")) == before  # no file left behind
    if blocker == "file":
        assert out.read_text() == "keep me"


@pytest.mark.skipif(not Path("/proc/sys").is_dir(), reason="needs Linux /proc")
def test_out_that_cannot_be_made_fails_before_storing(monkeypatch, capsys, tmp_path):
    monkeypatch.setattr("skyroute.jobs.deliver.plan_day", _no_flying)
    code, _, err = run(monkeypatch, capsys, "deliver", "2024-01-01", "--data", EXAMPLE,
                       "--db", f"sqlite:///{tmp_path / 'o.db'}", "--out", "/proc/sys/foo")
    assert code == 2 and "/proc/sys/foo/" in err and "cannot write" in err, err
    assert not any(_stored_rows(tmp_path / "o.db").values())


@pytest.mark.parametrize("data", ["missing", "empty"])
def test_a_failed_deliver_leaves_no_out_folder_behind(monkeypatch, capsys, tmp_path, data):
    (tmp_path / "empty").mkdir()
    out = tmp_path / "new" / "out"
    code, _, err = run(monkeypatch, capsys, "deliver", "2024-01-01", "--data",
                       str(tmp_path / data), "--db", f"sqlite:///{tmp_path / 'o.db'}",
                       "--out", str(out))
    assert code == 2 and data in err and len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "new").exists()  # the check made it, the failure left it


def test_bad_out_leaves_earlier_runs_stored(monkeypatch, capsys, tmp_path, fly_once):
    db = tmp_path / "k.db"
    code, _, err = run(monkeypatch, capsys, "deliver", "2024-01-01", "--data", EXAMPLE,
                       "--db", f"sqlite:///{db}", "--out", str(tmp_path / "good"),
                       "--no-plot", "--json")
    assert code == 0, err
    rows = _stored_rows(db)
    assert rows["runs"] == 1 and rows["deliveries"] > 0
    # --no-plot: the PNG's place is not checked (nothing will be written there)
    (tmp_path / "bad" / "drone-01-01-2024.png").mkdir(parents=True)
    code, _, err = run(monkeypatch, capsys, "deliver", "2024-01-01", "--data", EXAMPLE,
                       "--db", f"sqlite:///{db}", "--out", str(tmp_path / "bad"),
                       "--no-plot", "--json")
    assert code == 0, err
    (tmp_path / "bad" / "report-01-01-2024.json").unlink()
    (tmp_path / "bad" / "report-01-01-2024.json").mkdir()
    code, _, err = run(monkeypatch, capsys, "deliver", "2024-01-01", "--data", EXAMPLE,
                       "--db", f"sqlite:///{db}", "--out", str(tmp_path / "bad"))
    assert code == 2 and "report-01-01-2024.json: cannot write: it is a folder" in err
    assert _stored_rows(db) == rows


def test_an_order_number_too_long_for_the_store_is_one_line(monkeypatch, capsys, tmp_path):
    # orders.order_no holds 8 characters: PostgreSQL raised a DataError traceback,
    # SQLite stored the order (and flew it) as given
    import shutil

    data = tmp_path / "data"
    shutil.copytree(EXAMPLE, data)
    with (data / "database" / "orders.csv").open("a") as f:
        f.write("123456789,2024-01-01,s2400001,brook.boat.brick\n")
    monkeypatch.setattr("skyroute.jobs.deliver.plan_day", _no_flying)
    code, _, err = run(monkeypatch, capsys, "deliver", "2024-01-01", "--data", str(data),
                       "--db", f"sqlite:///{tmp_path / 'o.db'}", "--out", str(tmp_path / "o"))
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    # named by file and line as it is read, before a store is made (a new store, its
    # tables empty, was left behind)
    assert "orders.csv:110: orderNo '123456789' is 9 characters; the store keeps at " \
           "most 8" in err
    assert not (tmp_path / "o.db").exists() and not (tmp_path / "o").exists()


def test_each_invalid_order_is_one_line_on_a_narrow_stderr(monkeypatch, capsys, tmp_path):
    # Rich wrapped the line at 80 columns (a pipe, a log), splitting the file in a reason
    import shutil

    data = tmp_path / ("a-long-folder-name-" * 4)
    shutil.copytree(EXAMPLE, data)
    (data / "website" / "words" / "heron" / "tulip" / "wren" / "details.json").unlink()
    monkeypatch.setenv("COLUMNS", "60")
    code, _, err = run(monkeypatch, capsys, "deliver", "2024-01-01", "--data", str(data),
                       "--db", f"sqlite:///{tmp_path / 'o.db'}", "--out", str(tmp_path / "o"),
                       "--no-plot")
    assert code == 0, err
    lines = [x for x in err.splitlines() if "invalid order" in x]
    assert len(lines) == 3 and all(x.endswith("details.json: no such file") for x in lines)



def test_db_lines_do_not_wrap(monkeypatch, capsys, tmp_path):
    # a long URL was split over two lines at 80 columns (a pipe, a log)
    monkeypatch.setenv("COLUMNS", "40")
    db = f"sqlite:///{tmp_path / ('long-store-name-' * 4)}.db"
    code, out, err = run(monkeypatch, capsys, "db", "init", "--db", db)
    assert code == 0 and out.strip() == f"{db}: schema at revision 0006", err
    code, out, err = run(monkeypatch, capsys, "db", "import", EXAMPLE, "--db", db)
    assert code == 0 and len(out.strip().splitlines()) == 1, err
    assert out.startswith(f"{db}: 108 orders added")


def test_a_corrected_csv_is_refused_until_replace(monkeypatch, capsys, tmp_path):
    # the stored (wrong) orders were kept and flown, and nothing said so
    import shutil

    data = tmp_path / "lunch"
    shutil.copytree(EXAMPLE, data)
    db = f"sqlite:///{tmp_path / 'c.db'}"
    assert run(monkeypatch, capsys, "db", "import", str(data), "--db", db)[0] == 0
    orders = data / "database" / "orders.csv"
    original = orders.read_text()
    lines = original.splitlines(keepends=True)
    no, day, customer, _ = lines[1].strip().split(",")
    lines[1] = f"{no},{day},{customer},fixed.place.here\n"
    fixed = "".join(lines)
    orders.write_text(fixed)
    refused = (f"{orders}: the orders of {day} differ from the stored ones (order {no}: "
               "deliverTo 'fixed.place.here', stored ")
    for args in (["db", "import", str(data)],
                 ["deliver", day, "--data", str(data), "--out", str(tmp_path / "out")]):
        code, out, err = run(monkeypatch, capsys, *args, "--db", db)
        assert code == 2 and refused in err and "--replace stores the file's orders of " \
            "that day" in err and len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "out").exists()
    orders.write_text(original)
    details = data / "database" / "orderDetails.csv"
    details.write_text("".join(details.read_text().splitlines(keepends=True)[:-1]))
    last = original.splitlines()[-1].split(",")
    code, out, err = run(monkeypatch, capsys, "db", "import", str(data), "--db", db)
    assert code == 2 and f"{details}: the orders of {last[1]} differ from the stored ones " \
        f"(order {last[0]}: items [" in err, err
    orders.write_text(fixed)  # both corrections: two days
    code, out, err = run(monkeypatch, capsys, "db", "import", str(data), "--db", db,
                         "--replace")
    assert code == 0, err
    assert f"replaced the stored orders of {day}, {last[1]} (what was flown from them is " \
        "deleted)" in " ".join(out.split())
    code, out, err = run(monkeypatch, capsys, "db", "import", str(data), "--db", db)
    assert code == 0 and "0 orders added, 108 already there" in " ".join(out.split())


def test_days_without_orders_say_so_and_exit_0(monkeypatch, capsys, tmp_path, fly_once):
    # one such day printed a table of zeros and nothing more; a range of them ended in
    # "error: no orders on any of these days" and exit 2 after storing the days and
    # writing their files (exit 0 with --json)
    db = ["--data", EXAMPLE, "--db", f"sqlite:///{tmp_path / 'e.db'}", "--out", str(tmp_path)]
    code, out, err = run(monkeypatch, capsys, "deliver", "2024-02-01", "--no-plot", *db)
    assert code == 0 and "orders placed" in out, err
    assert "2024-02-01: no orders stored for this day; nothing was flown" in err
    for extra in ([], ["--json"]):
        code, out, err = run(monkeypatch, capsys, "deliver", "--from", "2024-02-01", "--to",
                             "2024-02-03", *db, *extra)
        assert code == 0, err
        assert "nothing was flown: none of the 3 days from 2024-02-01 to 2024-02-03 had " \
            "orders stored" in " ".join(err.split())
    assert json.loads(out)["days_with_orders"] == 0
    code, out, err = run(monkeypatch, capsys, "deliver", "--from", "2024-01-03", "--to",
                         "2024-01-04", *db)
    assert code == 0 and "2 days" in out, err
    assert "1 of the 2 days had no orders stored (2024-01-04); nothing was flown on it" \
        in " ".join(err.split())


def _other_site(dst: Path, *, places: bool = True) -> Path:
    """``examples/lunch`` copied to ``dst`` with every menu item renamed ('Club sandwich
    (Small)' -> 'Other club sandwich (Small)'); with ``places`` as another site whose
    orders are its own: every place renamed too (each address's first word gains an
    'x'), and its orders' items, places, numbers ('z' for the first hex digit) and
    dates (a year earlier) to match; without, the same orders as the example's."""
    import shutil

    shutil.copytree(EXAMPLE, dst)
    web, db = dst / "website", dst / "database"

    def item(name: str) -> str:
        return "Other " + name[0].lower() + name[1:]

    def place(words: str) -> str:
        return words.replace(".", "x.", 1) if places else words

    if places:
        for d in list((web / "words").iterdir()):
            d.rename(d.with_name(d.name + "x"))
        area = json.loads((web / "area.json").read_text())
        area["home"] = place(area["home"])
        (web / "area.json").write_text(json.dumps(area))
    menus = json.loads((web / "menus" / "menus.json").read_text())
    for shop in menus:
        shop["location"] = place(shop["location"])
        for it in shop["menu"]:
            it["item"] = item(it["item"])
    (web / "menus" / "menus.json").write_text(json.dumps(menus))
    if not places:
        return dst
    lines = (db / "orders.csv").read_text().splitlines()
    rows = [r.split(",") for r in lines[1:]]
    (db / "orders.csv").write_text("\n".join([lines[0], *(
        f"z{no[1:]},{day.replace('2024', '2023')},{who},{place(to)}"
        for no, day, who, to in rows)]) + "\n")
    lines = (db / "orderDetails.csv").read_text().splitlines()
    (db / "orderDetails.csv").write_text("\n".join([lines[0], *(
        f"z{no[1:]},{item(it)}" for no, it in (r.split(",", 1) for r in lines[1:]))]) + "\n")
    return dst


def _stored_day(path, day: str) -> tuple:
    """The day's run (delivered, invalid), deliveries, moves and the orders stored."""
    import sqlite3

    with sqlite3.connect(path) as c:
        return (c.execute("select orders_delivered, orders_invalid from runs where "
                          "delivery_date = ?", (day,)).fetchall(),
                c.execute("select count(*) from deliveries where delivery_date = ?",
                          (day,)).fetchone()[0],
                c.execute("select count(*) from flightpath where delivery_date = ?",
                          (day,)).fetchone()[0],
                c.execute("select count(*) from orders").fetchone()[0])


def _lunch_day_stored(monkeypatch, capsys, tmp_path):
    """A store at ``tmp_path/s.db`` with the README's day flown: (its path, the day as
    :func:`_stored_day` reads it)."""
    db = tmp_path / "s.db"
    code, _, err = run(monkeypatch, capsys, "deliver", "2024-01-03", "--data", EXAMPLE,
                       "--db", f"sqlite:///{db}", "--out", str(tmp_path / "good"), "--no-plot")
    assert code == 0, err
    return db, _stored_day(db, "2024-01-03")


def test_another_sites_folder_is_refused_before_anything_is_written(monkeypatch, capsys,
                                                                    tmp_path, fly_once):
    # a store of the lunch orders flown with another site's --data folder: its orders
    # were imported, the day flown with every order 'unknown item' and stored over the
    # day's real flight, exit 0
    db, good = _lunch_day_stored(monkeypatch, capsys, tmp_path)
    assert good[0][0][0] > 0 and good[1] > 0 and good[3] == 108
    other = _other_site(tmp_path / "other")
    menus = other / "website" / "menus" / "menus.json"
    for dates, more in ((["2024-01-03"], ""),
                        (["--from", "2024-01-01", "--to", "2024-01-03"],
                         " (and 2 more of the days)")):
        first = dates[0] if len(dates) == 1 else dates[1]
        code, _, err = run(monkeypatch, capsys, "deliver", *dates, "--data", str(other),
                           "--db", f"sqlite:///{db}", "--out", str(tmp_path / "o"))
        assert code == 2 and len(err.strip().splitlines()) == 1, err
        assert f"{menus}: none of the 36 orders stored for {first} in sqlite:///{db}{more} " \
            "is on these menus or goes to a place of this site (e.g. item '" in err, err
        assert "they are another site's orders: give the --data folder they were " \
            "imported from; nothing was imported or flown" in err
        assert _stored_day(db, "2024-01-03") == good  # the day, and no orders imported
        assert not (tmp_path / "o").exists()
    # a folder whose own orders are of another site than its website
    import shutil

    mixed = tmp_path / "mixed"
    shutil.copytree(EXAMPLE, mixed)
    shutil.rmtree(mixed / "database")
    shutil.copytree(other / "database", mixed / "database")
    code, _, err = run(monkeypatch, capsys, "deliver", "2023-01-02", "--data", str(mixed),
                       "--db", f"sqlite:///{db}", "--out", str(tmp_path / "o"))
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert f"none of the 36 orders of 2023-01-02 in {mixed / 'database' / 'orders.csv'} is " \
        "on these menus" in err and "the folder's orders and website are not of one " \
        "site" in err, err
    assert _stored_day(db, "2024-01-03") == good
    # the other site with its own orders is flown as before
    # (reaching the flight: a day's error is that day's failure, said with its traceback)
    monkeypatch.setattr("skyroute.jobs.deliver.plan_day", _no_flying)
    code, _, err = run(monkeypatch, capsys, "deliver", "2023-01-02", "--data", str(other),
                       "--db", f"sqlite:///{tmp_path / 'o.db'}", "--out", str(tmp_path / "o"))
    assert code == 1 and err.endswith("skyroute: error: 2023-01-02: AssertionError: a day "
                                      "was flown before its output files were checked\n"), err


def test_a_refused_deliver_leaves_no_new_store_behind(monkeypatch, capsys, tmp_path):
    # a folder whose orders are another site's than its website, into a store that is
    # not there yet: refused before anything was imported or flown, but the store had
    # been made first, and its folder, file and empty tables stayed behind
    import shutil
    import sqlite3

    other = _other_site(tmp_path / "other")
    mixed = tmp_path / "mixed"
    shutil.copytree(EXAMPLE, mixed)
    shutil.rmtree(mixed / "database")
    shutil.copytree(other / "database", mixed / "database")
    new = tmp_path / "new" / "s.db"
    for dates in (["2023-01-02"], ["--from", "2023-01-01", "--to", "2023-01-03"]):
        code, out, err = run(monkeypatch, capsys, "deliver", *dates, "--data", str(mixed),
                             "--db", f"sqlite:///{new}", "--out", str(tmp_path / "o"))
        assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, err
        assert "the folder's orders and website are not of one site" in err, err
        assert not (tmp_path / "new").exists() and not (tmp_path / "o").exists()
    # a store that was there (made by db init, no orders yet) is refused the same and
    # kept as it was
    kept = tmp_path / "kept.db"
    assert run(monkeypatch, capsys, "db", "init", "--db", f"sqlite:///{kept}")[0] == 0

    def tables() -> list:
        with sqlite3.connect(kept) as c:
            return c.execute("select name from sqlite_master where type = 'table' "
                             "order by name").fetchall()

    made = tables()
    assert ("orders",) in made
    code, _, err = run(monkeypatch, capsys, "deliver", "2023-01-02", "--data", str(mixed),
                       "--db", f"sqlite:///{kept}", "--out", str(tmp_path / "o"))
    assert code == 2 and "not of one site" in err, err
    assert tables() == made
    # and the folder's site with its own orders goes on to make the new store
    monkeypatch.setattr("skyroute.jobs.deliver.plan_day", _no_flying)
    code, _, err = run(monkeypatch, capsys, "deliver", "2023-01-02", "--data", str(other),
                       "--db", f"sqlite:///{new}", "--out", str(tmp_path / "o"))
    assert code == 1 and "a day was flown before its output files" in err, err
    assert _stored_day(new, "2023-01-02")[3] == 108  # imported: the store was made


@pytest.mark.shared_data
def test_the_ilp_folder_with_a_store_of_lunch_orders_is_refused(monkeypatch, capsys,
                                                               tmp_path, fly_once):
    # the README's day flown into a store, then --data pointed at the ILP folder: 11,334
    # ILP orders were imported and the day's 36 lunch orders flown as 'unknown item'
    # (two lunch items share their names with ILP items: one item is not enough)
    from tests.conftest import SHARED

    db = tmp_path / "s.db"
    code, _, err = run(monkeypatch, capsys, "deliver", "2024-01-03", "--data", EXAMPLE,
                       "--db", f"sqlite:///{db}", "--out", str(tmp_path), "--no-plot")
    assert code == 0, err
    good = _stored_day(db, "2024-01-03")
    ilp = SHARED / "ilp2021"
    code, _, err = run(monkeypatch, capsys, "deliver", "2024-01-03", "--data", str(ilp),
                       "--db", f"sqlite:///{db}", "--out", str(tmp_path / "o"))
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert f"{ilp / 'website' / 'menus' / 'menus.json'}: none of the 36 orders stored for " \
        "2024-01-03" in err
    assert _stored_day(db, "2024-01-03") == good


def test_a_day_of_invalid_orders_keeps_the_stored_flight_until_replace(monkeypatch, capsys,
                                                                       tmp_path, fly_once):
    # the site's items renamed (its places are its own): every order is 'unknown item';
    # that day replaced the stored flight with nothing and said so only order by order
    db, good = _lunch_day_stored(monkeypatch, capsys, tmp_path)
    renamed = _other_site(tmp_path / "renamed", places=False)
    to = ["--db", f"sqlite:///{db}", "--out", str(tmp_path / "o"), "--no-plot"]
    for args in (["2024-01-03"], ["--from", "2024-01-03", "--to", "2024-01-03"]):
        code, _, err = run(monkeypatch, capsys, "deliver", *args, "--data", str(renamed), *to)
        assert code == 2 and len(err.strip().splitlines()) == 1, err
        assert "2024-01-03: every one of the day's 36 orders is invalid (order " in err
        assert ": unknown item '" in err
        assert f"so the day's stored flight, which delivered {good[0][0][0]} orders, is " \
            "kept (nothing was written for the day); --replace stores the day as flown " \
            "now" in err, err
        assert _stored_day(db, "2024-01-03") == good
        assert not list((tmp_path / "o").glob("*03-01-2024*"))
    code, out, err = run(monkeypatch, capsys, "deliver", "2024-01-03", "--data",
                         str(renamed), *to, "--replace", "--json")
    assert code == 0, err
    assert json.loads(out)["orders_invalid"] == 36
    assert _stored_day(db, "2024-01-03") == ([(0, 36)], 0, 0, 108)


def _full_disk_png(fig, path, **_kw):
    """``save_figure`` on a disk that fills up while the PNG is written."""
    import errno

    import matplotlib.pyplot as plt

    from skyroute.files import open_atomic

    plt.close(fig)
    with open_atomic(path):
        raise OSError(errno.ENOSPC, "No space left on device")


def _interrupted_png(fig, _path, **_kw):
    """``save_figure`` interrupted by Ctrl-C."""
    import matplotlib.pyplot as plt

    plt.close(fig)
    raise KeyboardInterrupt


@pytest.mark.parametrize("save, code, words", [
    (_full_disk_png, 2, "drone-01-01-2024.png: cannot write: No space left on device"),
    (_interrupted_png, 130, "interrupted"),
])
def test_a_day_whose_files_fail_is_not_stored(monkeypatch, capsys, tmp_path, fly_once, save,
                                              code, words):
    # the day was stored first, then its files written: a full disk or a Ctrl-C while
    # the PNG was drawn left the day in the store without its files
    db = tmp_path / "f.db"
    code_, _, err = run(monkeypatch, capsys, "db", "import", EXAMPLE, "--db", f"sqlite:///{db}")
    assert code_ == 0, err
    monkeypatch.setattr("skyroute.io.plot.save_figure", save)
    got, _, err = run(monkeypatch, capsys, "deliver", "2024-01-01", "--data", EXAMPLE,
                      "--db", f"sqlite:///{db}", "--out", str(tmp_path / "out"))
    assert got == code and words in err and len(err.strip().splitlines()) == 1, err
    assert _stored_day(db, "2024-01-01") == ([], 0, 0, 108)  # the orders, no run
    assert not (tmp_path / "out").exists()  # nor a file, nor the folder made for them


def test_a_range_stopped_by_a_full_disk_says_which_days_are_stored(monkeypatch, capsys,
                                                                  tmp_path, fly_once):
    # the disk fills while the second day's PNG is written: the range stops, keeping the
    # first day with its files; the one line said only "...png: cannot write: No space
    # left on device", not whether 2024-01-01 was kept or 2024-01-03 flown
    calls = []

    def save(fig, path, **kw):
        calls.append(path)
        if len(calls) == 2:
            return _full_disk_png(fig, path)
        import matplotlib.pyplot as plt

        plt.close(fig)
        Path(path).write_bytes(b"png")

    monkeypatch.setattr("skyroute.io.plot.save_figure", save)
    db, out = tmp_path / "r.db", tmp_path / "out"
    code, _, err = run(monkeypatch, capsys, "deliver", "--from", "2024-01-01", "--to",
                       "2024-01-03", "--data", EXAMPLE, "--db", f"sqlite:///{db}", "--out",
                       str(out), "--plot")
    assert code == 2 and err.count("error") == 1, err  # after the "imported" line
    assert err.strip().endswith(
        "drone-02-01-2024.png: cannot write: No space left on device; the range stopped "
        "there: 1 of its 3 days is stored with its files (2024-01-01), the other 2 not"), err
    assert _stored_day(db, "2024-01-01")[0] and not _stored_day(db, "2024-01-02")[0]
    assert _files_of(out) == ["drone-01-01-2024.geojson", "drone-01-01-2024.png",
                              "report-01-01-2024.json"]


def _files_of(out: Path) -> list[str]:
    return sorted(p.name for p in out.iterdir())


def test_a_range_with_failed_days_stores_every_other_day(monkeypatch, capsys, tmp_path):
    # --jobs 2 on a real pool, two days failing in their workers: the range stopped at
    # the first failure it read and dropped the days the workers had flown meanwhile
    # (here 2024-01-02, flown after the failed 2024-01-01); a month with one bad day
    # was flown again whole. Now every other day is stored with its files, then each
    # failed day is one line, and the exit is 2.
    failing_workers(monkeypatch, {"2024-01-01": "skyroute", "2024-01-03": "skyroute"})
    db, out = tmp_path / "r.db", tmp_path / "out"
    code, stdout, err = run(monkeypatch, capsys, "deliver", "--from", "2023-12-31", "--to",
                            "2024-01-03", "--data", EXAMPLE, "--db", f"sqlite:///{db}",
                            "--out", str(out), "--jobs", "2")
    # the days that did not fail: stored with their files, and summed up on stdout
    assert _stored_day(db, "2024-01-02")[0] and _stored_day(db, "2023-12-31")[0] == [(0, 0)]
    assert _stored_day(db, "2024-01-01")[0] == _stored_day(db, "2024-01-03")[0] == []
    assert _files_of(out) == ["drone-02-01-2024.geojson", "drone-31-12-2023.geojson",
                              "report-02-01-2024.json", "report-31-12-2023.json"]
    assert code == 2, err
    assert err.strip().splitlines()[-3:] == [
        "skyroute: error: 2024-01-01: the planner failed",
        "skyroute: error: 2024-01-03: the planner failed",
        "skyroute: error: 2 of the 4 days failed and were not stored; the other 2 are "
        "stored, with their files"], err
    assert re.search(r"^2 of 4 days, [\d.]+ s with 2 job\(s\): money delivered mean "
                     r"[\d.]+%, worst [\d.]+% on 2024-01-02$", stdout, re.M), stdout


def test_a_worker_error_that_does_not_unpickle_is_one_line(monkeypatch, capsys, tmp_path):
    # an InputFormatError raised in a pool worker does not unpickle in the command: the
    # pool broke, a traceback ending "A process in the process pool was terminated
    # abruptly", and the day that named the file was not said
    failing_workers(monkeypatch, {"2024-01-01": "file"})
    db, out = tmp_path / "p.db", tmp_path / "out"
    code, _, err = run(monkeypatch, capsys, "deliver", "--from", "2023-12-31", "--to",
                       "2024-01-01", "--data", EXAMPLE, "--db", f"sqlite:///{db}", "--out",
                       str(out), "--jobs", "2")
    assert code == 2, err
    assert "Traceback" not in err and err.strip().splitlines()[-2:] == [
        "skyroute: error: 2024-01-01: website/menus/menus.json: cannot read: gone",
        "skyroute: error: 1 of the 2 days failed and was not stored; the other 1 is "
        "stored, with its files"], err
    assert _stored_day(db, "2023-12-31")[0] == [(0, 0)]
    assert _files_of(out) == ["drone-31-12-2023.geojson", "report-31-12-2023.json"]


OOM = "killed by SIGKILL, as the out-of-memory killer does"


def test_a_worker_that_dies_loses_only_its_own_day(monkeypatch, capsys, tmp_path):
    # a pool worker killed (here by itself, SIGKILL, as the out-of-memory killer does)
    # on 2024-01-01: the range ended in a BrokenProcessPool traceback, and every day not
    # yet stored was lost (also those flown meanwhile by the other worker). Now the
    # range goes on in a fresh pool, the days the broken pool held are flown again each
    # alone, and only the day that kills its worker again fails, in one line
    failing_workers(monkeypatch, {"2024-01-01": "die"})
    db, out = tmp_path / "d.db", tmp_path / "out"
    code, stdout, err = run(monkeypatch, capsys, "deliver", "--from", "2023-12-31", "--to",
                            "2024-01-03", "--data", EXAMPLE, "--db", f"sqlite:///{db}",
                            "--out", str(out), "--jobs", "2")
    assert code == 2 and "Traceback" not in err, err
    assert f"skyroute: a worker process died ({OOM}); the " in err
    assert err.strip().splitlines()[-2:] == [
        f"skyroute: error: 2024-01-01: its worker process died ({OOM}), also when run "
        "again alone",
        "skyroute: error: 1 of the 4 days failed and was not stored; the other 3 are "
        "stored, with their files"], err
    assert _stored_day(db, "2024-01-01")[0] == []
    assert _stored_day(db, "2024-01-02")[0] and _stored_day(db, "2024-01-03")[0]
    assert _stored_day(db, "2023-12-31")[0] == [(0, 0)]
    assert _files_of(out) == sorted(f"{k}-{d}.{e}" for d in ("02-01-2024", "03-01-2024",
                                                             "31-12-2023")
                                    for k, e in (("drone", "geojson"), ("report", "json")))
    assert re.search(r"^3 of 4 days, ", stdout, re.M), stdout


def test_a_worker_killed_once_loses_no_day(monkeypatch, capsys, tmp_path):
    # killed from outside once (an operator's kill; the out-of-memory killer taking
    # the biggest process while another program ate the memory): flown again, stored
    failing_workers(monkeypatch, {"2024-01-01": "die-once"}, marks=tmp_path)
    db, out = tmp_path / "o.db", tmp_path / "out"
    code, stdout, err = run(monkeypatch, capsys, "deliver", "--from", "2024-01-01", "--to",
                            "2024-01-02", "--data", EXAMPLE, "--db", f"sqlite:///{db}",
                            "--out", str(out), "--jobs", "2")
    assert code == 0 and f"skyroute: a worker process died ({OOM})" in err, err
    assert (tmp_path / "2024-01-01").exists()  # it did die once
    assert _stored_day(db, "2024-01-01")[0] and _stored_day(db, "2024-01-02")[0]
    assert re.search(r"^2 days, ", stdout, re.M), stdout


def test_failed_days_in_json_and_a_defect_shows_its_traceback(monkeypatch, capsys,
                                                               tmp_path, fly_once):
    # in the command's process (--jobs 1): a defect on one day is that day's failure
    # too; its traceback is printed (as an uncaught error's was) and the exit is 1
    from skyroute.errors import SkyrouteError

    def planner(site, date, orders, **kw):
        if str(date) == "2024-01-01":
            return 1 / 0
        if str(date) == "2024-01-02":
            raise SkyrouteError("2024-01-02: the flight failed validation: move 3")
        return fly_once(site, date, orders, **kw)

    monkeypatch.setattr("skyroute.jobs.deliver.plan_day", planner)
    db, out = tmp_path / "j.db", tmp_path / "out"
    code, stdout, err = run(monkeypatch, capsys, "deliver", "--from", "2024-01-01", "--to",
                            "2024-01-04", "--data", EXAMPLE, "--db", f"sqlite:///{db}",
                            "--out", str(out), "--json")
    assert code == 1, err
    summary = json.loads(stdout)
    assert summary["days"] == 2 and summary["days_with_orders"] == 1
    assert summary["failed"] == [
        {"date": "2024-01-01", "error": "2024-01-01: ZeroDivisionError: division by zero"},
        {"date": "2024-01-02", "error": "2024-01-02: the flight failed validation: move 3"}]
    assert "Traceback (most recent call last)" in err and "return 1 / 0" in err
    assert err.strip().splitlines()[-3:] == [
        "skyroute: error: 2024-01-01: ZeroDivisionError: division by zero",
        "skyroute: error: 2024-01-02: the flight failed validation: move 3",
        "skyroute: error: 2 of the 4 days failed and were not stored; the other 2 are "
        "stored, with their files"]
    assert _stored_day(db, "2024-01-03")[0] and _stored_day(db, "2024-01-04")[0]
    assert _files_of(out) == ["drone-03-01-2024.geojson", "drone-04-01-2024.geojson",
                              "report-03-01-2024.json", "report-04-01-2024.json"]
    # one day: its error alone, as before, exit 2
    code, stdout, err = run(monkeypatch, capsys, "deliver", "2024-01-02", "--data", EXAMPLE,
                            "--db", f"sqlite:///{db}", "--out", str(out))
    assert (code, stdout) == (2, "")
    assert err == "skyroute: error: 2024-01-02: the flight failed validation: move 3\n"



@pytest.mark.parametrize("as_json", [False, True])
def test_a_range_whose_every_day_fails_says_none_was_stored(monkeypatch, capsys, tmp_path,
                                                            as_json):
    # the last line said "2 of the 2 days failed and were not stored; the other 0 are
    # stored, with their files", of files and days there were none of
    from skyroute.errors import SkyrouteError

    def planner(site, date, orders, **kw):
        raise SkyrouteError(f"{date}: the planner failed")

    monkeypatch.setattr("skyroute.jobs.deliver.plan_day", planner)
    db, out = tmp_path / "n.db", tmp_path / "out"
    code, stdout, err = run(monkeypatch, capsys, "deliver", "--from", "2024-01-01", "--to",
                            "2024-01-02", "--data", EXAMPLE, "--db", f"sqlite:///{db}",
                            "--out", str(out), *(["--json"] if as_json else []))
    assert code == 2, err
    assert err.strip().splitlines()[-3:] == [
        "skyroute: error: 2024-01-01: the planner failed",
        "skyroute: error: 2024-01-02: the planner failed",
        "skyroute: error: all 2 days failed and none was stored"], err
    if as_json:
        assert json.loads(stdout)["days"] == 0
    else:
        assert stdout == ""
    assert _stored_day(db, "2024-01-01")[0] == _stored_day(db, "2024-01-02")[0] == []
    assert not out.exists()


def _ctrl_c():
    raise KeyboardInterrupt


def _ctrl_c_in_a_kernel():
    # how a Ctrl-C that came while a compiled kernel ran reaches Python
    try:
        raise KeyboardInterrupt
    except KeyboardInterrupt as exc:
        raise SystemError("CPUDispatcher(...) returned a result with an exception set") \
            from exc


@pytest.mark.parametrize("interrupt", [_ctrl_c, _ctrl_c_in_a_kernel])
def test_ctrl_c_on_a_day_still_stops_the_range(monkeypatch, capsys, tmp_path, fly_once,
                                              interrupt):
    # a day's error no longer stops the range; a Ctrl-C while a day is flown still does
    # (also when it surfaces as another error, as from a numba kernel): not a failed day
    flown = []

    def planner(site, date, orders, **kw):
        flown.append(str(date))
        if str(date) == "2024-01-02":
            interrupt()
        return fly_once(site, date, orders, **kw)

    monkeypatch.setattr("skyroute.jobs.deliver.plan_day", planner)
    db, out = tmp_path / "c.db", tmp_path / "out"
    code, _, err = run(monkeypatch, capsys, "deliver", "--from", "2024-01-01", "--to",
                       "2024-01-03", "--data", EXAMPLE, "--db", f"sqlite:///{db}", "--out",
                       str(out))
    assert (code, err.strip().splitlines()[-1]) == (130, "skyroute: interrupted"), err
    assert flown == ["2024-01-01", "2024-01-02"]  # the range stopped there
    assert _stored_day(db, "2024-01-01")[0] and not _stored_day(db, "2024-01-02")[0]
    assert _files_of(out) == ["drone-01-01-2024.geojson", "report-01-01-2024.json"]


def _lunch_with(tmp_path, name: str, edit) -> Path:
    """A copy of the lunch example whose database/``name`` is ``edit(text)``."""
    import shutil

    data = tmp_path / "lunch"
    shutil.copytree(EXAMPLE, data)
    p = data / "database" / name
    p.write_text(edit(p.read_text()))
    return data


@pytest.mark.parametrize("command", ["deliver", "import"])
@pytest.mark.parametrize("name, edit, words", [
    ("orders.csv", lambda t: t.replace(",2024-01-01,", ",2024-13-01,", 1),
     "orders.csv:2: deliveryDate '2024-13-01' is not YYYY-MM-DD"),
    ("orders.csv", lambda t: "", "orders.csv:1: the file is empty; expected the header "
     "orderNo,deliveryDate,customer,deliverTo"),
    ("orderDetails.csv", lambda t: t + "zzzz,Club sandwich (Small)\n",
     "is not in orders.csv"),
    # a value too long for its store column: one line naming the store's column, no
    # file or line, after the new store was made
    ("orders.csv", lambda t: t.replace(",s2433825,", ",cust-00012,", 1),
     "orders.csv:2: customer 'cust-00012' is 10 characters; the store keeps at most 8"),
    ("orders.csv", lambda t: t.replace(",brook.boat.brick", "," + "a" * 65, 1),
     f"orders.csv:2: deliverTo '{'a' * 65}' is 65 characters; the store keeps at most 64"),
    ("orderDetails.csv", lambda t: t.replace("Club sandwich (Small)", "C" * 101, 1),
     "is 101 characters; the store keeps at most 100"),
])
def test_malformed_order_files_leave_no_new_store_behind(monkeypatch, capsys, tmp_path,
                                                         command, name, edit, words):
    # the store was opened (its folder, file and tables made) before the CSVs were read
    data = _lunch_with(tmp_path, name, edit)
    store = tmp_path / "new" / "s.db"
    args = (["deliver", "2024-01-01", "--data", str(data), "--out", str(tmp_path / "out")]
            if command == "deliver" else ["db", "import", str(data)])
    code, out, err = run(monkeypatch, capsys, *args, "--db", f"sqlite:///{store}")
    assert code == 2 and out == "" and words in err and err.count("\n") == 1, err
    assert not (tmp_path / "new").exists() and not (tmp_path / "out").exists()


@pytest.mark.parametrize("edit", [
    lambda t: t + "   \n\t\n",  # lines of spaces at the end (an editor's)
    lambda t: t.replace("orderNo,deliveryDate,customer,deliverTo",
                        "orderNo, deliveryDate, customer, deliverTo"),
])
def test_odd_but_valid_orders_files_import_as_the_plain_ones(monkeypatch, capsys, tmp_path,
                                                             edit):
    data = _lunch_with(tmp_path, "orders.csv", edit)
    code, out, err = run(monkeypatch, capsys, "db", "import", str(data), "--db",
                         f"sqlite:///{tmp_path / 's.db'}")
    assert code == 0, err
    assert "108 orders added" in out
