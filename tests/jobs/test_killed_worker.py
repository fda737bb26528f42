"""A worker process killed in the middle of a range: Dask runs its days again on another
worker, the job ends done, every day is stored exactly once and equals a local run."""

from __future__ import annotations

import datetime as dt
import os
import signal
import time

import pytest

from skyroute.delivery import store
from skyroute.jobs import runner
from skyroute.jobs.executor import open_executor
from tests.jobs.conftest import EXAMPLE, lunch_store

FIRST, LAST = "2024-01-01", "2024-01-08"  # two days of orders, six empty days
ORDER_DATES = ("2024-01-01", "2024-01-02")  # (2024-01-03: see test_deliver_jobs.DATES)


class KillAfterFirstResult:
    """The cluster's executor, killing (SIGKILL) the process of a worker that holds a
    task as soon as the first task has come back."""

    def __init__(self, inner) -> None:
        self.inner = inner
        self.killed: list[tuple[str, int, list]] = []

    def map(self, fn, items, *, on_result=None):
        def kill_once(i, result):
            if not self.killed:
                self._kill_a_busy_worker()
            if on_result:
                on_result(i, result)

        return self.inner.map(fn, items, on_result=kill_once)

    def _kill_a_busy_worker(self) -> None:
        client = self.inner.client
        end = time.monotonic() + 10
        while time.monotonic() < end:
            busy = {w: list(keys) for w, keys in client.processing().items() if keys}
            if busy:
                w = sorted(busy)[0]
                pid = client.run(os.getpid, workers=[w])[w]
                os.kill(pid, signal.SIGKILL)
                self.killed.append((w, pid, busy[w]))
                return
            time.sleep(0.01)


def day_counts(engine) -> dict[str, list]:
    with engine.connect() as c:
        return {t: c.exec_driver_sql(
            f"select delivery_date, count(*) from {t} group by delivery_date "
            "order by delivery_date").all() for t in ("runs", "flightpath", "deliveries")}


@pytest.fixture(scope="module")
def cluster(leg_cache):
    ex = open_executor("dask", workers=2)
    yield ex
    ex.close()


def test_a_killed_worker_loses_no_day_and_writes_none_twice(tmp_path, cluster):
    params = {"from": FIRST, "to": LAST, "data": str(EXAMPLE)}
    with open_executor("local", workers=1) as local:
        plain = lunch_store(f"sqlite:///{tmp_path / 'local.db'}", ORDER_DATES)
        ok = runner.wait(plain, runner.submit(plain, "deliver", params, executor=local),
                         timeout=300)
    assert ok["state"] == "done", ok["error"]

    for attempt in range(3):  # the cluster may finish every task before one is killed
        engine = lunch_store(f"sqlite:///{tmp_path / f'dask{attempt}.db'}", ORDER_DATES)
        killer = KillAfterFirstResult(cluster)
        job = runner.wait(engine, runner.submit(engine, "deliver", params, executor=killer),
                          timeout=300)
        if killer.killed:
            break
        cluster.client.wait_for_workers(2, timeout=60)
    assert killer.killed, "no worker held a task after the first result, three times"
    _, pid, keys = killer.killed[0]
    assert keys and pid != os.getpid()
    assert job["state"] == "done", job["error"]
    assert job["progress"] == 1.0 and job["result"]["days"] == 8
    assert job["result"] == {**ok["result"], "seconds_per_day_mean": job["result"][
        "seconds_per_day_mean"], "seconds_per_day_max": job["result"]["seconds_per_day_max"]}

    counts = day_counts(engine)
    dates = [dt.date.fromisoformat(FIRST) + dt.timedelta(k) for k in range(8)]
    assert [dt.date.fromisoformat(str(d)) for d, n in counts["runs"]] == dates
    assert all(n == 1 for _, n in counts["runs"])  # each day once
    assert counts == day_counts(plain)  # no move or delivery twice
    for d in dates:
        assert store.day_rows(engine, d) == store.day_rows(plain, d)
    cluster.client.wait_for_workers(2, timeout=60)  # the nanny restarted the killed one
