"""A store whose skyroute tables are gone under a running server (dropped, its file
replaced by an empty one) is the server's condition, not the request's: a 503 whose body
names no path or URL of the store. ``delivery.store.tables``' message ("sqlite:////srv/
.../x.db: no skyroute tables; ...") reached the body as a 422 (``_submit``'s
``str(exc)`` for a job, the library handler for the reads); it now stays in the log."""

from __future__ import annotations

import sqlite3

import pytest

from tests.service.conftest import AUTH, EXAMPLE, make_client


@pytest.mark.parametrize("dropped, method, path, body", [
    ("runs", "GET", "/days", None),  # "no skyroute tables"
    ("orders", "GET", "/orders?date=2024-01-03", None),  # "no table orders (an older ...)"
    ("fleet_runs", "GET", "/fleet/runs", None),
    ("jobs", "GET", "/jobs/some-id", None),
    ("jobs", "POST", "/jobs/fleet", {"preset": "seed-3x3", "hours": 0.1}),  # _submit
])
def test_a_store_without_its_tables_names_no_path(tmp_path, caplog, dropped, method, path,
                                                  body):
    db = tmp_path / "store.db"
    with make_client(db_url=f"sqlite:///{db}") as c:
        c.app.state.resources.engine()  # opened (and its schema made) as a server does
        with sqlite3.connect(db) as conn:  # then its table gone under the server
            conn.execute(f"DROP TABLE {dropped}")
        r = c.request(method, path, json=body, headers=AUTH)
    assert str(tmp_path) not in r.text, r.text
    assert "sqlite" not in r.text, r.text
    assert r.status_code == 503, r.text
    doc = r.json()
    assert doc["type"] == "urn:skyroute:problem:store-unavailable"
    assert doc["detail"].startswith("the store cannot be read"), doc
    logged = [x.getMessage() for x in caplog.records if x.name == "skyroute.service"]
    assert any(str(db) in m and "skyroute db init" in m for m in logged), logged



def test_a_job_failed_by_the_store_shows_no_sql(tmp_path):
    """A deliver job whose day the store refused to write (here a trigger; a full disk,
    a constraint): ``GET /jobs/{id}`` gave SQLAlchemy's text, the INSERT with the row's
    values and a link to SQLAlchemy's site; it gives one line saying what failed."""
    from skyroute.jobs import runner

    db = tmp_path / "store.db"
    with make_client(db_url=f"sqlite:///{db}", data_dir=EXAMPLE, job_workers=1) as c:
        res = c.app.state.resources
        with res.engine().begin() as conn:
            conn.exec_driver_sql("CREATE TRIGGER full BEFORE INSERT ON runs BEGIN "
                                 "SELECT RAISE(ABORT, 'database or disk is full'); END")
        # as POST /jobs/deliver submits it (without its check of the site, a second)
        job_id = runner.submit(res.engine(), "deliver", {"date": "2024-01-05",
                                                         "data": str(EXAMPLE)},
                               executor=res.executor())
        runner.wait(res.engine(), job_id, timeout=60)
        job = c.get(f"/jobs/{job_id}", headers=AUTH).json()
    assert job["state"] == "failed", job
    assert job["error"] == ("IntegrityError: the store could not run an INSERT: database "
                            "or disk is full"), job["error"]
