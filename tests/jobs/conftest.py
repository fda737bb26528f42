"""Fixtures of the jobs tests: a store of the synthetic lunch orders, a Dask cluster per
module (a LocalCluster of two worker processes starts in about a second; its workers
then import skyroute on their first task), PostgreSQL when a server answers."""

from __future__ import annotations

import contextlib
import datetime as dt

import pytest
import sqlalchemy as sa

from tests.conftest import ROOT, new_pg_database

EXAMPLE = ROOT / "examples" / "lunch"


def lunch_store(url: str, dates: tuple[str, ...] | None = None):
    """A store at ``url`` (schema at the newest revision) holding the lunch orders of
    ``dates`` (default all three days)."""
    from skyroute.delivery.days import open_store
    from skyroute.delivery.orders import read_csv_orders
    from skyroute.delivery.store import import_orders

    engine = open_store(url)
    keep = None if dates is None else {dt.date.fromisoformat(d) for d in dates}
    import_orders(engine, [o for o in read_csv_orders(EXAMPLE)
                           if keep is None or o.date in keep])
    return engine


@pytest.fixture(scope="module")
def dask_executor(leg_cache):
    """One in-process Dask cluster (2 worker processes) for the module; started after the
    session's leg cache is set, so the workers read the same cache."""
    from skyroute.jobs.executor import open_executor

    ex = open_executor("dask", workers=2)
    yield ex
    ex.close()


@pytest.fixture(scope="session")
def _pg_database() -> str:
    """A database of this test session's own, dropped at its end: a fixed name was reset
    by every other session running beside this one, a helper's or a second terminal's."""
    with new_pg_database("skyroute_jobs") as url:
        yield url


@pytest.fixture
def pg_url(_pg_database) -> str:
    """The URL of the session's PostgreSQL database, emptied for this test."""
    eng = sa.create_engine(_pg_database)
    with eng.begin() as c:
        for t in ("servers", "fleet_run_files", "fleet_runs", "jobs", "runs", "flightpath",
                  "deliveries", "order_details", "orders", "alembic_version"):
            c.execute(sa.text(f"drop table if exists {t} cascade"))
    eng.dispose()
    return _pg_database


def slow_days(monkeypatch, seconds: float = 0.3) -> None:
    """Make each day of a delivery job take at least ``seconds`` (jobs run inline with one
    worker): on a fast machine with warm caches a few days fly within one
    ``runner.PROGRESS_EVERY``, so no share between 0 and 1 would ever be written, and a
    test that looks for progress while a job runs would fail by the machine's speed."""
    import time

    from skyroute.jobs import deliver

    fly = deliver.fly_day

    def slow(task):
        out = fly(task)
        time.sleep(seconds)
        return out

    monkeypatch.setattr(deliver, "fly_day", slow)


@contextlib.contextmanager
def part_reads():
    """The parts of a run's files read while in the block, by any engine: a part's
    number for a statement that reads one part, "all" for one that reads a file whole."""
    seen: list = []

    def record(conn, clause, multiparams, params, execution_options):
        cols = getattr(clause, "selected_columns", ())
        if any(getattr(c, "name", None) == "data" and getattr(c, "table", None) is not None
               and c.table.name == "fleet_run_files" for c in cols):
            p = multiparams[0] if multiparams else params
            seen.append((p or {}).get("k", "all"))

    sa.event.listen(sa.engine.Engine, "before_execute", record)
    try:
        yield seen
    finally:
        sa.event.remove(sa.engine.Engine, "before_execute", record)
