"""A store locked by another process past its busy timeout is the server's passing
condition: 503 with ``Retry-After`` and a problem naming the busy store, never a 422 (as
if the request were wrong) or a 500, and nothing written."""

from __future__ import annotations

import contextlib
import sqlite3

import pytest

from tests.service.conftest import AUTH, EXAMPLE, TestClient

WRITES = [
    ("post", "/jobs/deliver", {"date": "2024-01-03"}),
    ("post", "/jobs/fleet", {"preset": "seed-3x3", "hours": 0.1}),
    ("delete", "/days/2024-01-03", None),
]
READS = ["/days", "/days/2024-01-03", "/fleet/runs", "/jobs/no-such-job", "/orders?date="
         "2024-01-03"]


@contextlib.contextmanager
def busy_app(tmp_path, lock: str):
    """A client of an app over a SQLite store (busy timeout 0.2 s), opened, then locked
    by a second connection holding ``BEGIN <lock>`` (another process's long write)."""
    from skyroute.service.app import create_app
    from skyroute.service.settings import Settings
    from tests.service.conftest import TOKEN

    path = tmp_path / "busy.db"
    settings = Settings(token=TOKEN, warm=False, data_dir=EXAMPLE,
                        db_url=f"sqlite:///{path}?timeout=0.2")
    with TestClient(create_app(settings)) as client:
        assert client.get("/days").status_code == 200  # the store opened and made
        holder = sqlite3.connect(path, isolation_level=None)
        holder.execute(f"BEGIN {lock}")
        try:
            yield client, path
        finally:
            holder.execute("ROLLBACK")
            holder.close()


def assert_busy(r) -> None:
    assert r.status_code == 503, r.text
    assert r.headers["content-type"] == "application/problem+json"
    assert int(r.headers["retry-after"]) > 0
    doc = r.json()
    assert doc["type"] == "urn:skyroute:problem:store-busy", doc
    assert doc["detail"].startswith("the store is busy"), doc
    assert "busy.db" not in r.text and "Traceback" not in r.text  # the URL stays in the log


@pytest.mark.parametrize("method, path, body", WRITES)
def test_a_write_on_a_store_locked_by_another_writer_is_a_503(tmp_path, method, path,
                                                              body):
    """It was a 422 "invalid input" naming the store's URL: a client told its request
    was wrong would not retry it."""
    with busy_app(tmp_path, "IMMEDIATE") as (client, db):
        assert_busy(client.request(method, path, json=body, headers=AUTH))
    with sqlite3.connect(db) as con:  # nothing half-written: no job, no server beat
        assert con.execute("select count(*) from jobs").fetchone() == (0,)
        assert con.execute("select count(*) from servers").fetchone() == (0,)


@pytest.mark.parametrize("path", READS)
def test_a_read_of_a_store_locked_against_readers_is_a_503(tmp_path, path):
    """A writer whose transaction outgrew SQLite's page cache (a big fleet run being
    saved) holds the lock that keeps readers out; a read then was a 500 whose log held
    a "database is locked" traceback."""
    with busy_app(tmp_path, "EXCLUSIVE") as (client, _):
        assert_busy(client.get(path))


def test_a_store_busy_at_its_first_use_is_a_503(tmp_path):
    """The first request opens the store and brings its schema up to date, a write."""
    from skyroute.delivery import store
    from skyroute.service.app import create_app
    from skyroute.service.settings import Settings
    from tests.service.conftest import TOKEN

    path = tmp_path / "new.db"
    store.init(store.connect(f"sqlite:///{path}"))
    holder = sqlite3.connect(path, isolation_level=None)
    holder.execute("BEGIN EXCLUSIVE")
    try:
        settings = Settings(token=TOKEN, warm=False, db_url=f"sqlite:///{path}?timeout=0.2")
        with TestClient(create_app(settings)) as client:
            r = client.get("/days")
            assert_busy(r)
    finally:
        holder.execute("ROLLBACK")
        holder.close()
    with TestClient(create_app(settings)) as client:  # free again: answered
        assert client.get("/days").status_code == 200
