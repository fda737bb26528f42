"""A store whose skyroute tables are gone under a running server (dropped, its file
replaced by an empty one) is the server's condition, not the request's: a 503 whose body
names no path or URL of the store. ``delivery.store.tables``' message ("sqlite:////srv/
.../x.db: no skyroute tables; ...") reached the body as a 422 (``_submit``'s
``str(exc)`` for a job, the library handler for the reads); it now stays in the log."""

from __future__ import annotations

import sqlite3

import pytest

from tests.service.conftest import AUTH, make_client


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
