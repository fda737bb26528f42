"""The jobs' Dask cluster as the operator names it with ``serve --dask``: a scheduler
that does not answer is refused at start in one line, and one that goes away later
makes a job's submission a 503 (the server's condition), not a 422 naming its address."""

from __future__ import annotations

import logging

from skyroute.jobs import executor as executor_mod
from tests.cli.test_cli import run
from tests.service.conftest import AUTH, make_client
from tests.service.test_app import assert_problem

NOBODY = "tcp://127.0.0.1:9"  # the discard port: nothing listens there


def test_a_scheduler_it_cannot_reach_is_a_503_for_a_job(monkeypatch, tmp_path, caplog):
    monkeypatch.setattr(executor_mod, "CONNECT_TIMEOUT", "1s")
    with make_client(db_url=f"sqlite:///{tmp_path / 's.db'}", dask_address=NOBODY) as c, \
            caplog.at_level(logging.WARNING, logger="skyroute.service"):
        r = c.post("/jobs/fleet", json={"preset": "seed-3x3", "hours": 0.1}, headers=AUTH)
    doc = assert_problem(r, 503, words="cannot reach its Dask cluster")
    assert doc["type"] == "urn:skyroute:problem:executor-unavailable"
    assert r.headers["Retry-After"] == "30" and "127.0.0.1" not in r.text
    assert any(NOBODY in m and "no Dask scheduler there" in m for m in caplog.messages)


def test_serve_refuses_a_scheduler_it_cannot_reach_at_start(monkeypatch, capsys, tmp_path):
    import uvicorn

    served = []
    monkeypatch.setattr(uvicorn, "run", lambda *a, **k: served.append(a))
    monkeypatch.setattr(executor_mod, "CONNECT_TIMEOUT", "1s")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SKYROUTE_TOKEN", "serve-test-token-0001")
    code, _, err = run(monkeypatch, capsys, "serve", "--db", f"sqlite:///{tmp_path / 's.db'}",
                       "--dask", NOBODY)
    assert not served
    assert code == 2 and err.startswith(f"skyroute: error: --dask '{NOBODY}': no Dask "
                                        "scheduler there (")
    assert len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "s.db").exists()  # refused before the store was made
