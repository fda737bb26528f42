"""The jobs and fleet_runs tables: migration 0002 (also over a 0001 store with its days),
a job's life, fleet runs with their files, on SQLite and PostgreSQL alike."""

from __future__ import annotations

import datetime as dt
from pathlib import Path

import pytest
import sqlalchemy as sa

from skyroute.delivery import store as dstore
from skyroute.errors import OptionError, SkyrouteError
from skyroute.jobs import store

COLUMNS = {
    "jobs": ["id", "kind", "params", "state", "progress", "result", "error", "created",
             "updated"],
    "fleet_runs": ["id", "job_id", "scenario", "params", "report", "events_jsonl",
                   "tracks_csv", "packages_csv", "fleet_geojson", "created"],
}


@pytest.fixture(params=["sqlite", "postgresql"])
def engine(request, tmp_path):
    url = (f"sqlite:///{tmp_path / 'jobs.db'}" if request.param == "sqlite"
           else request.getfixturevalue("pg_url"))
    e = dstore.connect(url)
    assert dstore.init(e) == "0002"
    yield e
    e.dispose()


def test_migration_makes_both_tables(engine):
    insp = sa.inspect(engine)
    for table, cols in COLUMNS.items():
        assert [c["name"] for c in insp.get_columns(table)] == cols
    assert dstore.init(engine) == "0002"  # again: nothing to do


def test_upgrading_a_0001_store_keeps_its_days(tmp_path):
    from alembic import command
    from alembic.config import Config

    e = dstore.connect(f"sqlite:///{tmp_path / 'old.db'}")
    cfg = Config()
    cfg.set_main_option("script_location", str(Path(dstore.__file__).parent / "migrations"))
    with e.begin() as conn:
        cfg.attributes["connection"] = conn
        command.upgrade(cfg, "0001")
    day = dt.date(2024, 1, 1)
    run = {"started": dt.datetime(2024, 1, 1), "finished": dt.datetime(2024, 1, 1),
           "moves": 0, "orders_placed": 0, "orders_delivered": 0, "orders_invalid": 0,
           "money_delivered": 0, "money_placed": 0, "settings": {}}
    dstore.write_day(e, day, run, [], [])
    with pytest.raises(SkyrouteError, match=r"no table jobs, fleet_runs \(an older schema\); "
                                            r"run 'skyroute db init'"):
        store.get_job(e, "x")
    assert dstore.init(e) == "0002"
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
    assert [r["id"] for r in store.list_fleet_runs(engine, job_id=job_id)] == [a]
    assert {r["id"] for r in store.list_fleet_runs(engine)} == {a, b}
    assert store.get_fleet_run(engine, "nope") is None
    with pytest.raises(OptionError, match="limit=0"):
        store.list_fleet_runs(engine, limit=0)
