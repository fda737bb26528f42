"""The jobs, fleet_runs, servers and fleet_run_files tables: migrations 0002 to 0006 (also
over a 0001 store with its days, a 0002 store with its jobs and a 0003, 0004 or 0005 store
with its fleet runs, and back), a job's life, orphans, fleet runs with their files,
stored in parts, streamed and paged by lines, on SQLite and PostgreSQL alike."""

from __future__ import annotations

import datetime as dt
import uuid
from functools import partial
from pathlib import Path

import pytest
import sqlalchemy as sa

from skyroute.delivery import store as dstore
from skyroute.errors import OptionError, SkyrouteError
from skyroute.jobs import store
from tests.jobs.conftest import part_reads

COLUMNS = {
    "jobs": ["id", "kind", "params", "state", "progress", "result", "error", "created",
             "updated", "owner"],
    "fleet_runs": ["id", "job_id", "scenario", "params", "report", "created"],
    "servers": ["id", "started", "heartbeat"],
    "fleet_run_files": ["run_id", "name", "part", "data", "lines"],
}
HEAD = "0006"


def upgrade_to(engine, revision: str, *, down: bool = False) -> None:
    """The schema at ``revision`` by the shipped migrations, as an older skyroute left it
    (``down``: by their downgrades, from a newer schema)."""
    from alembic import command
    from alembic.config import Config

    cfg = Config()
    cfg.set_main_option("script_location", str(Path(dstore.__file__).parent / "migrations"))
    with engine.begin() as conn:
        cfg.attributes["connection"] = conn
        (command.downgrade if down else command.upgrade)(cfg, revision)


@pytest.fixture(params=["sqlite", "postgresql"])
def engine(request, tmp_path):
    url = (f"sqlite:///{tmp_path / 'jobs.db'}" if request.param == "sqlite"
           else request.getfixturevalue("pg_url"))
    e = dstore.connect(url)
    assert dstore.init(e) == HEAD
    yield e
    e.dispose()


def test_migrations_make_the_tables(engine):
    insp = sa.inspect(engine)
    for table, cols in COLUMNS.items():
        assert [c["name"] for c in insp.get_columns(table)] == cols
    assert dstore.init(engine) == HEAD  # again: nothing to do


def test_upgrading_a_0001_store_keeps_its_days(tmp_path):
    e = dstore.connect(f"sqlite:///{tmp_path / 'old.db'}")
    upgrade_to(e, "0001")
    day = dt.date(2024, 1, 1)
    run = {"started": dt.datetime(2024, 1, 1), "finished": dt.datetime(2024, 1, 1),
           "moves": 0, "orders_placed": 0, "orders_delivered": 0, "orders_invalid": 0,
           "money_delivered": 0, "money_placed": 0, "settings": {}}
    dstore.write_day(e, day, run, [], [])
    with pytest.raises(SkyrouteError, match=r"no table jobs, fleet_runs, servers, "
                                            r"fleet_run_files \(an "
                                            r"older schema\); run 'skyroute db init'"):
        store.get_job(e, "x")
    assert dstore.init(e) == HEAD
    assert store.get_job(e, "x") is None
    with e.connect() as c:
        assert c.execute(sa.text("select count(*) from runs")).scalar_one() == 1


def test_a_jobs_life(engine):
    job_id = store.create_job(engine, "deliver", {"from": "2024-01-01", "n": 2})
    job = store.get_job(engine, job_id)
    assert job["state"] == "queued" and job["progress"] == 0.0 and job["kind"] == "deliver"
    assert job["params"] == {"from": "2024-01-01", "n": 2} and job["result"] is None
    assert job["created"].endswith("+00:00")
    store.set_progress(engine, job_id, 0.25)
    job = store.get_job(engine, job_id)
    assert (job["state"], job["progress"]) == ("running", 0.25)
    store.finish_job(engine, job_id, {"mean_pct": float("nan"), "rows": [(1, 2.5)]})
    job = store.get_job(engine, job_id)
    assert (job["state"], job["progress"]) == ("done", 1.0)
    assert job["result"] == {"mean_pct": None, "rows": [[1, 2.5]]}  # JSON: no NaN
    store.set_progress(engine, job_id, 0.5)  # too late: a finished job stays finished
    assert store.get_job(engine, job_id)["state"] == "done"
    other = store.create_job(engine, "fleet", {})
    store.fail_job(engine, other, "scenario.airports: too few\n  (see the docs)")
    job = store.get_job(engine, other)
    assert job["state"] == "failed" and job["error"] == "scenario.airports: too few (see the docs)"
    assert store.get_job(engine, "no-such-id") is None
    with pytest.raises(OptionError, match=r"progress=1.5 must be within 0\.\.1"):
        store.set_progress(engine, job_id, 1.5)


def test_fleet_runs_keep_their_files_and_replace_on_the_same_id(engine):
    job_id = store.create_job(engine, "fleet", {"preset": "seed-3x3"})
    files = {"events_jsonl": '{"t":0,"kind":"spawn"}\n', "tracks_csv": b"t,drone\n0,1\n",
             "packages_csv": "id\n0\n", "fleet_geojson": '{"type":"FeatureCollection"}'}
    a = store.save_fleet_run(engine, scenario="seed-3x3", params={"hours": 0.5},
                             report={"delivered": 3}, job_id=job_id, **files)
    b = store.save_fleet_run(engine, scenario="other", params={}, report={}, **files)
    again = store.save_fleet_run(engine, scenario="seed-3x3", params={"hours": 0.5},
                                 report={"delivered": 4}, job_id=job_id, run_id=a, **files)
    assert again == a
    run = store.get_fleet_run(engine, a)
    assert run["report"] == {"delivered": 4} and run["job_id"] == job_id
    assert {k: run[k] for k in files} == files
    assert "tracks_csv" not in store.get_fleet_run(engine, a, files=False)
    some = store.get_fleet_run(engine, a, files=("events_jsonl", "packages_csv"))
    assert {k for k in store.FILES if k in some} == {"events_jsonl", "packages_csv"}
    assert some["report"] == {"delivered": 4} and some["events_jsonl"] == files["events_jsonl"]
    one = store.get_fleet_run(engine, a, files="tracks_csv")
    assert [k for k in store.FILES if k in one] == ["tracks_csv"]
    assert one["tracks_csv"] == files["tracks_csv"]
    with pytest.raises(OptionError, match=r"files='tracks'.*'tracks_csv'"):
        store.get_fleet_run(engine, a, files=("tracks",))
    assert [r["id"] for r in store.list_fleet_runs(engine, job_id=job_id)] == [a]
    assert {r["id"] for r in store.list_fleet_runs(engine)} == {a, b}
    assert store.get_fleet_run(engine, "nope") is None
    with pytest.raises(OptionError, match="limit=0"):
        store.list_fleet_runs(engine, limit=0)


def _file_rows(engine) -> int:
    with engine.connect() as c:
        return c.execute(sa.text("select count(*) from fleet_run_files")).scalar_one()


def test_a_runs_files_go_with_it(engine):
    files = {"events_jsonl": "{}\n", "tracks_csv": b"t\n0\n", "packages_csv": "id\n",
             "fleet_geojson": "{}"}
    job_id = store.create_job(engine, "fleet", {})
    run = store.save_fleet_run(engine, scenario="s", params={}, report={}, job_id=job_id,
                               **files)
    before = _file_rows(engine)  # PostgreSQL's database may hold other tests' runs
    store.save_fleet_run(engine, scenario="s", params={}, report={}, job_id=job_id,
                         run_id=run, **files)  # replaced, not doubled
    assert _file_rows(engine) == before
    store.fail_job(engine, job_id, "boom")
    assert store.get_fleet_run(engine, run) is None
    assert _file_rows(engine) == before - len(store.FILES)


def _big(n: int) -> bytes:
    """``n`` bytes of every value, in no repeating order a part boundary could hide."""
    import numpy as np

    return np.random.default_rng(n).integers(0, 256, n, dtype=np.uint8).tobytes()


def _selects(engine, run):
    """(what ``run()`` returned, the parameters of each SELECT it sent)."""
    seen: list = []

    def record(conn, cursor, statement, parameters, *args):
        if statement.lstrip().upper().startswith("SELECT"):
            seen.append(parameters)

    sa.event.listen(engine, "before_cursor_execute", record)
    try:
        return run(), seen
    finally:
        sa.event.remove(engine, "before_cursor_execute", record)


@pytest.mark.parametrize("size", [0, 1, 2 * 1000, 2 * 1000 + 1, 3 * 1000 - 1])
def test_a_stored_file_streams_part_by_part(engine, monkeypatch, size):
    """A file is stored in parts of PART_BYTES (1000 here) and streamed one part per
    read: the bytes as saved, no read larger than a part, as many reads as parts; an
    empty file is one empty part."""
    monkeypatch.setattr(store, "PART_BYTES", 1000)
    tracks = _big(size)
    run = store.save_fleet_run(engine, scenario="s", params={}, report={},
                               events_jsonl="é" * 700, tracks_csv=tracks, packages_csv="",
                               fleet_geojson="{}")
    f = store.open_fleet_file(engine, run, "tracks_csv")
    parts = max(1, -(-size // 1000))
    assert (f.size, f.parts) == (size, parts)
    chunks, selects = _selects(engine, lambda: list(f))
    assert b"".join(chunks) == tracks
    assert [len(c) for c in chunks] == [min(1000, size - 1000 * k) for k in range(parts)]
    assert len(selects) == parts  # one read of one stored part each
    with engine.connect() as c:
        lengths = c.execute(sa.text(
            "select part, length(data) from fleet_run_files where run_id = :r and "
            "name = 'tracks_csv' order by part"), {"r": run}).all()
    assert [tuple(r) for r in lengths] == [(k, len(c)) for k, c in enumerate(chunks)]
    events = store.open_fleet_file(engine, run, "events_jsonl")  # 1400 bytes of UTF-8
    assert events.size == 1400 and b"".join(events).decode() == "é" * 700
    whole = store.get_fleet_run(engine, run)  # joined back whole
    assert whole["tracks_csv"] == tracks and whole["events_jsonl"] == "é" * 700
    assert store.open_fleet_file(engine, "nope", "tracks_csv") is None
    with pytest.raises(OptionError, match="name='tracks' is not valid"):
        store.open_fleet_file(engine, run, "tracks")


def test_a_large_file_is_stored_in_parts_of_a_mebibyte(engine):
    tracks = _big(2 * store.PART_BYTES + 7)
    run = store.save_fleet_run(engine, scenario="s", params={}, report={}, events_jsonl="",
                               tracks_csv=tracks, packages_csv="", fleet_geojson="")
    f = store.open_fleet_file(engine, run, "tracks_csv")
    chunks = list(f)
    assert (f.size, f.parts) == (len(tracks), 3) and b"".join(chunks) == tracks
    assert [len(c) for c in chunks] == [1 << 20, 1 << 20, 7]


@pytest.mark.parametrize("change", ["replaced", "deleted"])
def test_a_run_changed_while_its_file_streams_stops_the_stream(engine, monkeypatch, change):
    """The parts read after a run is replaced (saved again under its id) or deleted are
    an error, never the new run's bytes after the old one's."""
    monkeypatch.setattr(store, "PART_BYTES", 10)
    job = store.create_job(engine, "fleet", {})
    args = dict(scenario="s", params={}, report={}, events_jsonl="", packages_csv="",
                fleet_geojson="", job_id=job)
    run = store.save_fleet_run(engine, tracks_csv=b"a" * 35, **args)
    parts = iter(store.open_fleet_file(engine, run, "tracks_csv"))
    assert next(parts) == b"a" * 10
    if change == "replaced":
        store.save_fleet_run(engine, tracks_csv=b"b" * 35, run_id=run, **args)
    else:
        store.fail_job(engine, job, "boom")
    with pytest.raises(store.RunChangedError, match=f"fleet run '{run}' was replaced or "
                                                    "deleted while its tracks_csv was read"):
        next(parts)


def _part_reads(engine, run):
    """(what ``run()`` returned, the parts whose bytes it read: :func:`part_reads`)."""
    with part_reads() as seen:
        return run(), seen


def _jsonl(n: int, end: str) -> str:
    """``n`` JSON lines of 10 to 270 bytes (some longer than a part of 100), with
    two-byte characters a part boundary may cut, the last one ended by ``end``."""
    import json

    import numpy as np

    rng = np.random.default_rng(n)
    return "\n".join(json.dumps({"t": i, "at": "é" * int(rng.integers(0, 130))},
                                ensure_ascii=False) for i in range(n)) + end


@pytest.mark.parametrize("end", ["\n", ""])
def test_a_page_of_lines_is_read_from_the_parts_it_lies_in(engine, monkeypatch, end):
    """StoredFile.lines(offset, limit) is splitlines()[offset:offset + limit] and its
    length, for every offset, lines crossing parts and a last line with or without its
    newline; it reads the parts from the one with the newline before the page's first
    line to the one with the page's last line's end, and no other (none past the end)."""
    monkeypatch.setattr(store, "PART_BYTES", 100)
    text = _jsonl(40, end)
    run = store.save_fleet_run(engine, scenario="s", params={}, report={},
                               events_jsonl=text, tracks_csv=b"", packages_csv="",
                               fleet_geojson="")
    data, want = text.encode(), text.splitlines()
    newlines = [i for i, b in enumerate(data) if b == ord("\n")]
    f = store.open_fleet_file(engine, run, "events_jsonl")
    assert f.parts == -(-len(data) // 100) > 25
    for offset in range(len(want) + 2):
        for limit in (1, 2, 7, len(want) + 5):
            (got, total), reads = _part_reads(engine, partial(f.lines, offset, limit))
            assert total == len(want)
            assert [g.decode() for g in got] == want[offset:offset + limit], (offset, limit)
            n = len(want[offset:offset + limit])
            if not n:
                assert reads == []
                continue
            first = newlines[offset - 1] // 100 if offset else 0
            end_at = newlines[offset + n - 1] if offset + n <= len(newlines) else len(data) - 1
            assert reads == list(range(first, end_at // 100 + 1)), (offset, limit)
    empty = store.save_fleet_run(engine, scenario="s", params={}, report={},
                                 events_jsonl="", tracks_csv=b"", packages_csv="",
                                 fleet_geojson="")
    assert _part_reads(engine, lambda: store.open_fleet_file(
        engine, empty, "events_jsonl").lines(0, 5)) == (([], 0), [])


@pytest.fixture(params=["sqlite", "postgresql"])
def new_store(request, tmp_path):
    """An engine on a new empty store: a SQLite file, or a PostgreSQL database of this
    test's own."""
    url = (f"sqlite:///{tmp_path / 'new.db'}" if request.param == "sqlite"
           else request.getfixturevalue("fresh_pg"))
    e = dstore.connect(url)
    yield e
    e.dispose()


OLD_RUNS = [  # as a 0003 skyroute stored them: text with non-ASCII, tracks any bytes
    {"id": "run-a", "job_id": "job-a", "scenario": "seed-3x3", "params": {"hours": 0.25},
     "report": {"delivered": 3, "note": "Pâtisserie"},
     "events_jsonl": '{"t":0,"kind":"spawn","where":"Édinburgh ✈"}\n' * 50,
     "tracks_csv": b"t,drone\n" + bytes(range(256)) * 40,
     "packages_csv": "id,to\n0,Café\n", "fleet_geojson": '{"type":"FeatureCollection"}',
     "created": dt.datetime(2024, 1, 1, 12, 0, 1)},
    {"id": "run-b", "job_id": None, "scenario": "other", "params": {}, "report": {},
     "events_jsonl": "", "tracks_csv": b"", "packages_csv": "", "fleet_geojson": "",
     "created": dt.datetime(2024, 1, 1, 12, 0, 2)},
]
OLD_FILES = ("events_jsonl", "tracks_csv", "packages_csv", "fleet_geojson")


def test_upgrading_a_0003_store_keeps_its_fleet_runs_and_downgrading_puts_them_back(
        new_store):
    e = new_store
    upgrade_to(e, "0003")
    md = sa.MetaData()
    md.reflect(e, only=("jobs", "fleet_runs"))
    t = dt.datetime(2024, 1, 1, 12)
    with e.begin() as c:
        c.execute(md.tables["jobs"].insert().values(
            id="job-a", kind="fleet", params={}, state="done", progress=1.0,
            result={"fleet_run": "run-a"}, created=t, updated=t))
        c.execute(md.tables["fleet_runs"].insert(), OLD_RUNS)
    with pytest.raises(SkyrouteError, match=r"no table fleet_run_files \(an older schema\)"):
        store.list_fleet_runs(e)
    assert dstore.init(e) == HEAD
    assert [c["name"] for c in sa.inspect(e).get_columns("fleet_runs")] == \
        COLUMNS["fleet_runs"]
    assert [r["id"] for r in store.list_fleet_runs(e)] == ["run-b", "run-a"]
    for old in OLD_RUNS:
        run = store.get_fleet_run(e, old["id"])
        assert {k: run[k] for k in OLD_FILES} == {k: old[k] for k in OLD_FILES}
        assert {k: run[k] for k in ("job_id", "scenario", "params", "report")} == \
            {k: old[k] for k in ("job_id", "scenario", "params", "report")}
        assert run["created"] == old["created"].replace(tzinfo=dt.UTC).isoformat()
        assert store.get_fleet_run(e, old["id"], files="packages_csv")["packages_csv"] == \
            old["packages_csv"]
    # a run stored at 0004 goes back too
    new = store.save_fleet_run(e, scenario="new", params={}, report={}, events_jsonl="é",
                               tracks_csv=b"\x00\xff", packages_csv="p",
                               fleet_geojson="g")

    upgrade_to(e, "0003", down=True)
    assert "fleet_run_files" not in sa.inspect(e).get_table_names()
    cols = {c["name"]: c for c in sa.inspect(e).get_columns("fleet_runs")}
    assert all(not cols[k]["nullable"] for k in OLD_FILES)
    with e.connect() as c:
        got = {r["id"]: r for r in c.execute(sa.text(
            "select id, events_jsonl, tracks_csv, packages_csv, fleet_geojson "
            "from fleet_runs")).mappings()}
    for old in OLD_RUNS:
        assert {k: got[old["id"]][k] for k in OLD_FILES} == {k: old[k] for k in OLD_FILES}
    assert {k: got[new][k] for k in OLD_FILES} == {
        "events_jsonl": "é", "tracks_csv": b"\x00\xff", "packages_csv": "p",
        "fleet_geojson": "g"}
    assert dstore.init(e) == HEAD  # and up again
    assert store.get_fleet_run(e, "run-a")["tracks_csv"] == OLD_RUNS[0]["tracks_csv"]


def test_upgrading_a_0004_store_splits_its_files_and_downgrading_joins_them(new_store):
    e = new_store
    upgrade_to(e, "0004")
    md = sa.MetaData()
    md.reflect(e, only=("fleet_runs", "fleet_run_files"))
    big = _big(2 * store.PART_BYTES + 3)
    old = {"events_jsonl": "é\n".encode() * 10, "tracks_csv": big, "packages_csv": b"",
           "fleet_geojson": b"{}"}
    with e.begin() as c:
        c.execute(md.tables["fleet_runs"].insert().values(
            id="run-a", job_id=None, scenario="s", params={}, report={},
            created=dt.datetime(2024, 1, 1, 12)))
        c.execute(md.tables["fleet_run_files"].insert(),
                  [{"run_id": "run-a", "name": k, "data": v} for k, v in old.items()])
    assert dstore.init(e) == HEAD
    with e.connect() as c:
        rows = c.execute(sa.text("select name, part, length(data) from fleet_run_files "
                                 "order by name, part")).all()
    assert [tuple(r) for r in rows] == [
        ("events_jsonl", 0, 30), ("fleet_geojson", 0, 2), ("packages_csv", 0, 0),
        ("tracks_csv", 0, 1 << 20), ("tracks_csv", 1, 1 << 20), ("tracks_csv", 2, 3)]
    assert b"".join(store.open_fleet_file(e, "run-a", "tracks_csv")) == big
    run = store.get_fleet_run(e, "run-a")
    assert run["tracks_csv"] == big and run["events_jsonl"] == "é\n" * 10
    # a run stored at 0005 goes back too
    new = store.save_fleet_run(e, scenario="new", params={}, report={}, events_jsonl="é",
                               tracks_csv=big[:store.PART_BYTES + 1], packages_csv="",
                               fleet_geojson="g")

    upgrade_to(e, "0004", down=True)
    assert [c["name"] for c in sa.inspect(e).get_columns("fleet_run_files")] == \
        ["run_id", "name", "data"]
    with e.connect() as c:
        got = {(r, n): bytes(d) for r, n, d in c.execute(sa.text(
            "select run_id, name, data from fleet_run_files"))}
    assert {n: got["run-a", n] for n in old} == old
    assert got[new, "tracks_csv"] == big[:store.PART_BYTES + 1]
    assert got[new, "events_jsonl"] == "é".encode()
    assert dstore.init(e) == HEAD  # and up again
    assert store.get_fleet_run(e, new)["tracks_csv"] == big[:store.PART_BYTES + 1]


def test_upgrading_a_0005_store_counts_its_events_lines_and_downgrading_drops_them(
        new_store):
    """0006 counts the lines of each stored part of events.jsonl (a line may cross
    parts; the last may lack its newline) and leaves the other files' counts NULL, which
    a page of lines then counts from the bytes; the downgrade drops the counts alone."""
    e = new_store
    upgrade_to(e, "0005")
    md = sa.MetaData()
    md.reflect(e, only=("fleet_runs", "fleet_run_files"))
    parts = {"events_jsonl": [b'{"a":1}\n{"b', b'":"\xc3', b'\xa9"}\n\n', b'{"c":3}'],
             "tracks_csv": [b"t,drone\n0,1\n", b"1,2\n"], "packages_csv": [b""],
             "fleet_geojson": [b"{}"]}
    with e.begin() as c:
        c.execute(md.tables["fleet_runs"].insert().values(
            id="run-a", job_id=None, scenario="s", params={}, report={},
            created=dt.datetime(2024, 1, 1, 12)))
        c.execute(md.tables["fleet_run_files"].insert(), [
            {"run_id": "run-a", "name": k, "part": i, "data": d}
            for k, v in parts.items() for i, d in enumerate(v)])
    assert dstore.init(e) == HEAD
    with e.connect() as c:
        rows = c.execute(sa.text("select name, part, lines from fleet_run_files "
                                 "order by name, part")).all()
    assert [tuple(r) for r in rows] == [
        ("events_jsonl", 0, 1), ("events_jsonl", 1, 0), ("events_jsonl", 2, 2),
        ("events_jsonl", 3, 1), ("fleet_geojson", 0, None), ("packages_csv", 0, None),
        ("tracks_csv", 0, None), ("tracks_csv", 1, None)]
    assert "fleet_run_files_lines" in {i["name"] for i in sa.inspect(e).get_indexes(
        "fleet_run_files")}
    events = store.open_fleet_file(e, "run-a", "events_jsonl")
    text = b"".join(parts["events_jsonl"]).decode()
    assert events.lines(1, 9) == ([x.encode() for x in text.splitlines()[1:]], 4)
    assert _part_reads(e, lambda: events.lines(3, 1)) == (([b'{"c":3}'], 4), [2, 3])
    tracks = store.open_fleet_file(e, "run-a", "tracks_csv")  # no counts: read them
    assert tracks.lines(1, 1) == ([b"0,1"], 3)

    upgrade_to(e, "0005", down=True)
    assert [c["name"] for c in sa.inspect(e).get_columns("fleet_run_files")] == \
        ["run_id", "name", "part", "data"]
    assert "fleet_run_files_lines" not in {i["name"] for i in sa.inspect(e).get_indexes(
        "fleet_run_files")}
    with e.connect() as c:
        got = c.execute(sa.text("select name, data from fleet_run_files "
                                "order by name, part")).all()
    assert {k: [bytes(d) for n, d in got if n == k] for k in parts} == parts
    assert dstore.init(e) == HEAD  # and up again
    assert store.open_fleet_file(e, "run-a", "events_jsonl").lines(0, 1) == \
        ([b'{"a":1}'], 4)


@pytest.fixture(params=["sqlite", "postgresql"])
def empty(request, tmp_path):
    """An engine on an empty store: a new SQLite file, or the test PostgreSQL database
    emptied."""
    if request.param == "sqlite":
        e = dstore.connect(f"sqlite:///{tmp_path / 'empty.db'}")
    else:
        e = dstore.connect(request.getfixturevalue("pg_url"))
        with e.begin() as c:
            for t in ("servers", "fleet_run_files", "fleet_runs", "jobs", "runs",
                      "flightpath", "deliveries", "order_details", "orders",
                      "alembic_version"):
                c.execute(sa.text(f"drop table if exists {t} cascade"))
    yield e
    e.dispose()


def stale(engine, server: str, seconds: float) -> None:
    """A server row whose last heartbeat was ``seconds`` ago (by the database's clock)."""
    servers = dstore.tables(engine, ("servers",))["servers"]
    with engine.begin() as c:
        then = store.db_now(c) - dt.timedelta(seconds=seconds)
        c.execute(servers.insert().values(id=server, started=then, heartbeat=then))


def test_upgrading_a_0002_store_keeps_its_jobs(empty):
    e = empty
    upgrade_to(e, "0002")
    jobs = sa.table("jobs", *(sa.column(n, sa.JSON if n in ("params", "result") else None)
                              for n in COLUMNS["jobs"][:-1]))
    t = dt.datetime(2024, 1, 1, 12)
    rows = {state: {"id": f"job-{state}", "kind": "fleet", "params": {"preset": "seed-3x3"},
                    "state": state, "progress": {"queued": 0.0, "running": 0.5}.get(state, 1.0),
                    "result": {"fleet_run": "r"} if state == "done" else None,
                    "error": "boom" if state == "failed" else None,
                    "created": t, "updated": t}
            for state in store.STATES}
    with e.begin() as c:  # as a 0002 server wrote them
        c.execute(jobs.insert(), list(rows.values()))
    assert dstore.init(e) == HEAD
    for state, row in rows.items():
        job = store.get_job(e, row["id"])
        assert job["owner"] is None and job["state"] == state
        assert {k: job[k] for k in ("kind", "params", "progress", "result", "error")} == \
            {k: row[k] for k in ("kind", "params", "progress", "result", "error")}
        assert job["created"] == "2024-01-01T12:00:00+00:00"
    # no owner: no live server runs them, so the unfinished ones are orphans
    failed = store.fail_orphans(e, "gone", dead_after=60)
    assert sorted(failed) == ["job-queued", "job-running"]
    assert [store.get_job(e, f"job-{s}")["state"] for s in store.STATES] == \
        ["failed", "failed", "done", "failed"]
    assert store.get_job(e, "job-failed")["error"] == "boom"


def test_orphans_are_the_jobs_of_silent_or_unknown_owners(engine):
    store.beat(engine, "live")
    stale(engine, "dead", 120)
    stale(engine, "late", 30)  # silent, but not yet for dead_after
    ids = {}
    for name, owner, running in [("live_q", "live", False), ("live_r", "live", True),
                                 ("late_r", "late", True), ("dead_q", "dead", False),
                                 ("dead_r", "dead", True), ("none_q", None, False),
                                 ("unknown_r", "never-beat", True)]:
        ids[name] = store.create_job(engine, "fleet", {}, owner=owner)
        if running:
            store.set_progress(engine, ids[name], 0.5)
    dead_done = store.create_job(engine, "fleet", {}, owner="dead")
    store.finish_job(engine, dead_done, {})

    failed = set(store.fail_orphans(engine, "orphaned", dead_after=60))
    orphans = {ids[n] for n in ("dead_q", "dead_r", "none_q", "unknown_r")}
    assert orphans <= failed  # PostgreSQL's database may hold other tests' jobs
    for name, job_id in ids.items():
        job = store.get_job(engine, job_id)
        if job_id in orphans:
            assert (job["state"], job["error"]) == ("failed", "orphaned"), name
        else:
            assert job_id not in failed and job["state"] in ("queued", "running"), name
    assert store.get_job(engine, dead_done)["state"] == "done"
    servers = dstore.tables(engine, ("servers",))["servers"]
    with engine.connect() as c:
        left = set(c.scalars(sa.select(servers.c.id)))
    assert {"live", "late"} <= left and "dead" not in left  # silent servers forgotten
    store.beat(engine, "dead")  # back after all: it beats again
    assert set(store.fail_orphans(engine, "orphaned", dead_after=60)).isdisjoint(ids.values())
    with pytest.raises(OptionError, match=r"dead_after=0 must be a number of seconds > 0"):
        store.fail_orphans(engine, "orphaned", dead_after=0)


def test_owners_known_to_have_ended_are_orphans_at_once(engine):
    """An owner the caller knows has ended (``gone``) loses its unfinished jobs and its
    server row though it beat a moment ago; a live owner's jobs and row stay."""
    store.beat(engine, "ended")
    store.beat(engine, "live")
    ended = store.create_job(engine, "fleet", {}, owner="ended")
    store.set_progress(engine, ended, 0.5)
    ended_done = store.create_job(engine, "fleet", {}, owner="ended")
    store.finish_job(engine, ended_done, {})
    live = store.create_job(engine, "fleet", {}, owner="live")
    assert {"ended", "live"} <= set(store.live_owners(engine))
    assert None not in store.live_owners(engine)

    failed = store.fail_orphans(engine, "orphaned", dead_after=60, gone=["ended"])
    assert ended in failed and live not in failed and ended_done not in failed
    assert (store.get_job(engine, ended)["state"], store.get_job(engine, live)["state"],
            store.get_job(engine, ended_done)["state"]) == ("failed", "queued", "done")
    servers = dstore.tables(engine, ("servers",))["servers"]
    with engine.connect() as c:
        left = set(c.scalars(sa.select(servers.c.id)))
    assert "live" in left and "ended" not in left
    assert "ended" not in store.live_owners(engine)


def test_the_database_clock_is_utc_without_a_zone(engine):
    with engine.connect() as c:
        now = store.db_now(c)
    here = dt.datetime.now(dt.UTC).replace(tzinfo=None)
    assert now.tzinfo is None and abs(now - here) < dt.timedelta(hours=1)  # not local time


FILES = {"events_jsonl": "", "tracks_csv": b"", "packages_csv": "", "fleet_geojson": ""}


def save_run(engine, job_id: str, run_id: str | None = None) -> str:
    return store.save_fleet_run(engine, scenario="s", params={}, report={}, job_id=job_id,
                                run_id=run_id, **FILES)


def test_a_job_failed_as_an_orphan_stays_failed(engine):
    """A stalled server's job is failed as an orphan (its stored run with it); when the
    server wakes, its result, its error and its progress are refused, and so is the
    fleet run its worker would store."""
    stale(engine, "stalled", 120)
    job_id = store.create_job(engine, "fleet", {}, owner="stalled")
    assert store.set_progress(engine, job_id, 0.5)
    save_run(engine, job_id)  # the worker stored it, then the server stalled
    assert job_id in store.fail_orphans(engine, "orphaned", dead_after=60)
    assert store.list_fleet_runs(engine, job_id=job_id) == []

    assert store.finish_job(engine, job_id, {"fleet_run": "r"}) is False
    assert store.fail_job(engine, job_id, "a late error") is False
    assert store.set_progress(engine, job_id, 0.9) is False
    with pytest.raises(store.JobEndedError, match=f"job {job_id} has failed; its fleet "
                                                  "run is not stored"):
        save_run(engine, job_id, late := str(uuid.uuid4()))
    job = store.get_job(engine, job_id)
    assert (job["state"], job["error"], job["result"], job["progress"]) == \
        ("failed", "orphaned", None, 0.5)
    assert store.list_fleet_runs(engine, job_id=job_id) == []
    assert store.get_fleet_run(engine, late) is None


def test_ended_jobs_are_never_written_again(engine):
    done = store.create_job(engine, "fleet", {})
    assert store.finish_job(engine, done, {"fleet_run": "r1"})  # queued -> done
    run = save_run(engine, done)
    assert save_run(engine, done, run) == run  # a task run twice replaces its run
    assert store.fail_job(engine, done, "too late") is False
    assert store.finish_job(engine, done, {"fleet_run": "r2"}) is False
    job = store.get_job(engine, done)
    assert (job["state"], job["error"], job["result"]) == ("done", None, {"fleet_run": "r1"})
    assert [r["id"] for r in store.list_fleet_runs(engine, job_id=done)] == [run]

    failed = store.create_job(engine, "fleet", {})
    assert store.set_progress(engine, failed, 0.2)
    save_run(engine, failed)
    assert store.fail_job(engine, failed, "first")  # running -> failed, its run gone
    assert store.fail_job(engine, failed, "second") is False
    assert store.finish_job(engine, failed, {}) is False
    job = store.get_job(engine, failed)
    assert (job["state"], job["error"], job["result"]) == ("failed", "first", None)
    assert store.list_fleet_runs(engine, job_id=failed) == []
    for write in (lambda: store.finish_job(engine, "no-such-job", {}),
                  lambda: store.fail_job(engine, "no-such-job", "x"),
                  lambda: store.set_progress(engine, "no-such-job", 0.1)):
        assert write() is False
    with pytest.raises(SkyrouteError, match="job_id='no-such-job': no such job"):
        save_run(engine, "no-such-job")


def blocked_by(engine, pid: int) -> int:
    """How many PostgreSQL sessions wait for the session ``pid`` (read in a transaction
    of its own: pg_stat_activity is a snapshot taken once per transaction)."""
    with engine.connect() as c:
        return c.execute(sa.text("select count(*) from pg_stat_activity "
                                 "where :pid = any(pg_blocking_pids(pid))"),
                         {"pid": pid}).scalar_one()


def test_a_run_saved_while_its_job_fails_waits_for_the_failure(pg_url):
    """PostgreSQL: a worker saving its run while another server's transaction is failing
    the job waits for that transaction and then refuses the run (a plain read would
    see the job still running and store a run of a failed job)."""
    import threading
    import time

    e = dstore.connect(pg_url)
    dstore.init(e)
    job_id = store.create_job(e, "fleet", {})
    store.set_progress(e, job_id, 0.5)
    jobs = dstore.tables(e, ("jobs",))["jobs"]
    outcome = []

    def worker():
        try:
            outcome.append(save_run(e, job_id))
        except store.JobEndedError as exc:
            outcome.append(exc)

    with e.connect() as other:
        tx = other.begin()  # the failing server's transaction, not yet committed
        other.execute(jobs.update().where(jobs.c.id == job_id).values(state="failed"))
        pid = other.execute(sa.text("select pg_backend_pid()")).scalar_one()
        saving = threading.Thread(target=worker)
        saving.start()
        end = time.monotonic() + 30
        while not blocked_by(e, pid) and time.monotonic() < end:  # the worker waits
            time.sleep(0.01)
        assert blocked_by(e, pid) == 1
        tx.commit()
    saving.join(30)
    assert len(outcome) == 1 and isinstance(outcome[0], store.JobEndedError), outcome
    assert store.list_fleet_runs(e, job_id=job_id) == []
    e.dispose()


WRITES = {
    "create_job": lambda e, job: store.create_job(e, "fleet", {}),
    "set_progress": lambda e, job: store.set_progress(e, job, 0.5),
    "finish_job": lambda e, job: store.finish_job(e, job, {}),
    "fail_job": lambda e, job: store.fail_job(e, job, "x"),
    "beat": lambda e, job: store.beat(e, "server-1"),
    "fail_orphans": lambda e, job: store.fail_orphans(e, "orphaned", dead_after=60),
    "save_fleet_run": lambda e, job: save_run(e, job),
}


@pytest.mark.parametrize("write", list(WRITES))
def test_a_job_write_on_a_store_locked_too_long_is_one_line(tmp_path, write):
    # the job store wrote by engine.begin(): a lock held past the busy timeout (a long
    # import or day by another process) was a "database is locked" OperationalError
    # traceback (a 500 in the service); it now writes as the delivery store does
    import sqlite3

    path = tmp_path / "busy.db"
    e = dstore.connect(f"sqlite:///{path}")
    dstore.init(e)
    job_id = store.create_job(e, "fleet", {})
    holder = sqlite3.connect(path, isolation_level=None)
    holder.execute("BEGIN IMMEDIATE")
    try:
        short = dstore.connect(f"sqlite:///{path}?timeout=0.1")
        with pytest.raises(SkyrouteError, match=r"busy\.db\?timeout=0\.1: the store is busy"):
            WRITES[write](short, job_id)
    finally:
        holder.rollback()
        holder.close()
    job = store.get_job(e, job_id)
    assert (job["state"], job["progress"]) == ("queued", 0.0)
    assert store.list_fleet_runs(e) == []
    short.dispose()
    e.dispose()


def test_job_writers_on_one_sqlite_file_queue(tmp_path):
    # four threads, each with its own engine, writing jobs at once: every write lands
    import threading

    url = f"sqlite:///{tmp_path / 'many.db'}"
    dstore.init(dstore.connect(url))
    errors, made = [], []

    def writer(k: int) -> None:
        e = dstore.connect(url)
        try:
            for _ in range(20):
                store.beat(e, f"server-{k}")
                job = store.create_job(e, "fleet", {}, owner=f"server-{k}")
                store.set_progress(e, job, 0.5)
                save_run(e, job)
                assert store.finish_job(e, job, {"k": k})
                made.append(job)
        except Exception as exc:  # reported below
            errors.append(exc)
        finally:
            e.dispose()

    threads = [threading.Thread(target=writer, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(120)
    assert errors == []
    e = dstore.connect(url)
    assert {store.get_job(e, j)["state"] for j in made} == {"done"} and len(made) == 80
    assert len(store.list_fleet_runs(e, limit=1000)) == 80
    e.dispose()


@pytest.mark.parametrize("db", ["sqlite", "postgresql"])
def test_the_same_job_submitted_at_once_by_two_servers_is_recorded_once(tmp_path, request,
                                                                        db):
    """create_job_once from four connections at the same moment (servers sharing the
    store): one records the job, the others answer its id. Without the write lock
    (SQLite) or the advisory lock (PostgreSQL) round the look and the insert, rounds of
    this recorded the job two to four times (measured: 3 of 10 rounds on SQLite, 10 of
    10 on PostgreSQL)."""
    import threading

    url = (f"sqlite:///{tmp_path / 'once.db'}" if db == "sqlite"
           else request.getfixturevalue("fresh_pg"))
    params = {"from": "2024-01-01", "to": "2024-01-01", "method": "milp",
              "replace": False, "data": "/orders"}
    engine = dstore.connect(url)
    dstore.init(engine)
    servers = [dstore.connect(url) for _ in range(4)]
    try:
        for _ in range(10):
            with engine.begin() as c:
                c.execute(sa.text("DELETE FROM jobs"))
            at_once, answers = threading.Barrier(len(servers)), []

            def submit(eng, at_once=at_once, answers=answers):
                at_once.wait()
                answers.append(store.create_job_once(eng, "deliver", params, owner="s"))

            threads = [threading.Thread(target=submit, args=(e,)) for e in servers]
            for t in threads:
                t.start()
            for t in threads:
                t.join()
            with engine.connect() as c:
                ids = c.execute(sa.text("SELECT id FROM jobs")).scalars().all()
            assert len(ids) == 1, ids
            assert sorted(answers, key=lambda a: not a[1]) == [
                (ids[0], True)] + [(ids[0], False)] * (len(servers) - 1)
    finally:
        for e in [engine, *servers]:
            e.dispose()
