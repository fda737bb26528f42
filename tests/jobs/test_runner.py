"""The runner as the service sees it: submit returns at once, the job's state moves
queued -> running (with progress) -> done in the store, a failure is one line, bad
parameters are refused before anything is queued."""

from __future__ import annotations

import time

import pytest
import sqlalchemy as sa

from skyroute.errors import OptionError
from skyroute.jobs import runner
from skyroute.jobs.executor import open_executor
from tests.jobs.conftest import EXAMPLE, lunch_store, slow_days


def watch(engine, ids: list[str], timeout: float = 300) -> dict[str, list[tuple]]:
    """Every distinct (state, progress) of each job, polled until all have ended."""
    seen: dict[str, list[tuple]] = {i: [] for i in ids}
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        for i in ids:
            j = runner.get(engine, i)
            if not seen[i] or seen[i][-1] != (j["state"], j["progress"]):
                seen[i].append((j["state"], j["progress"]))
        if all(s[-1][0] in ("done", "failed") for s in seen.values()):
            return seen
        time.sleep(0.01)
    raise AssertionError(f"jobs still running after {timeout} s: {seen}")


def test_states_move_from_queued_through_running_to_done(tmp_path, monkeypatch):
    engine = lunch_store(f"sqlite:///{tmp_path / 'r.db'}")
    slow_days(monkeypatch)
    days = {"from": "2024-01-01", "to": "2024-01-04", "data": str(EXAMPLE)}
    with open_executor("local", workers=1) as ex:
        first = runner.submit(engine, "deliver", days, executor=ex)
        second = runner.submit(engine, "deliver", {**days, "to": "2024-01-02"}, executor=ex)
        assert runner.get(engine, second)["state"] == "queued"  # behind the first
        assert runner.pending() == 2
        seen = watch(engine, [first, second])
    for job_id in (first, second):
        states = [s for s, _ in seen[job_id]]
        assert states[-1] == "done" and "queued" not in states[states.index("running"):]
        progress = [p for s, p in seen[job_id] if s == "running"]
        assert progress == sorted(progress)
    assert seen[second][0] == ("queued", 0.0)
    # the first job's 4 days: some share of them done while it was still running
    assert any(0 < p < 1 for s, p in seen[first] if s == "running"), seen[first]
    job = runner.get(engine, first)
    assert job["progress"] == 1.0 and job["error"] is None
    assert job["result"]["days"] == 4 and job["result"]["days_with_orders"] == 3
    assert job["params"] == {**days, "method": "milp", "replace": False}
    settle()  # the lane counts a job ended just after it writes the job's last state


def test_a_failing_job_ends_failed_with_one_line(tmp_path):
    engine = lunch_store(f"sqlite:///{tmp_path / 'f.db'}")
    (tmp_path / "empty" / "website").mkdir(parents=True)  # a site without its files
    with open_executor("local", workers=1) as ex:
        job_id = runner.submit(engine, "deliver", {"date": "2024-01-01",
                                                   "data": str(tmp_path / "empty")},
                               executor=ex)
        job = runner.wait(engine, job_id, timeout=60)
    assert job["state"] == "failed" and job["result"] is None
    assert job["error"].endswith("website/menus/menus.json: no such file"), job["error"]
    assert "\n" not in job["error"] and "Traceback" not in job["error"]


def test_an_unexpected_error_is_its_type_and_message(tmp_path, monkeypatch):
    from skyroute.jobs import fleet

    def boom(*_args, **_kwargs):
        raise ZeroDivisionError("division by zero\nsecond line")

    monkeypatch.setattr(fleet, "_simulate", boom)
    engine = lunch_store(f"sqlite:///{tmp_path / 'u.db'}", ())
    with open_executor("local", workers=1) as ex:
        job = runner.wait(engine, runner.submit(engine, "fleet", {"preset": "seed-3x3"},
                                                executor=ex), timeout=60)
    assert job["state"] == "failed"
    assert job["error"] == "ZeroDivisionError: division by zero second line"


def test_a_database_error_is_stored_without_its_statement(tmp_path, caplog):
    """The store refusing a day's row (a full disk, a constraint): the job's error was
    SQLAlchemy's text, the INSERT with every value of the row in it; it is one line
    naming the kind of statement and the database's reason, the SQL in the log."""
    engine = lunch_store(f"sqlite:///{tmp_path / 'd.db'}", ())
    with engine.begin() as c:
        c.exec_driver_sql("CREATE TRIGGER full BEFORE INSERT ON runs BEGIN "
                          "SELECT RAISE(ABORT, 'database or disk is full'); END")
    with open_executor("local", workers=1) as ex, caplog.at_level("ERROR", "skyroute.jobs"):
        job = runner.wait(engine, runner.submit(engine, "deliver", {
            "date": "2024-01-05", "data": str(EXAMPLE)}, executor=ex), timeout=60)
    assert job["state"] == "failed"
    assert job["error"] == ("IntegrityError: the store could not run an INSERT: database "
                            "or disk is full"), job["error"]
    assert "INSERT INTO runs" in caplog.text  # the detail stays in the server's log


def test_an_error_stored_with_its_statement_is_read_without_it(tmp_path):
    """A job failed by an older skyroute kept SQLAlchemy's whole text: it is read up to
    the row (PostgreSQL's DETAIL) and the SQL."""
    from skyroute.jobs import store

    engine = lunch_store(f"sqlite:///{tmp_path / 'o.db'}", ())
    job_id = store.create_job(engine, "deliver", {"date": "2024-01-05"})
    store.fail_job(engine, job_id, 'IntegrityError: (psycopg.errors.UniqueViolation) '
                   'duplicate key value violates unique constraint "t_pkey"\nDETAIL:  Key '
                   "(a)=(x) already exists.\n[SQL: INSERT INTO t VALUES (%(a)s)]\n"
                   "[parameters: {'a': 'x'}]")
    assert runner.get(engine, job_id)["error"] == (
        'IntegrityError: (psycopg.errors.UniqueViolation) duplicate key value violates '
        'unique constraint "t_pkey"')


@pytest.mark.parametrize("kind, params, words", [
    ("plan", {}, "kind='plan' is not valid; choose one of 'deliver', 'fleet', 'sweep'"),
    ("deliver", {"date": "tomorrow", "data": str(EXAMPLE)}, "date='tomorrow'"),
    ("fleet", {"preset": "seed-1x1"}, "preset='seed-1x1' is not valid"),
    ("fleet", {"preset": "seed-3x3", "hours": 0}, "hours=0 must be a number > 0"),
    ("fleet", {"scenario": {"airports": []}}, "scenario: airports"),
    ("sweep", {"preset": "seed-3x3", "seeds": [1.5]}, "seeds=1.5 must be an integer"),
    ("sweep", {"preset": "seed-3x3", "airspaces": ["open"]}, "airspaces='open'"),
])
def test_bad_params_are_refused_before_queueing(tmp_path, kind, params, words):
    engine = lunch_store(f"sqlite:///{tmp_path / 'b.db'}", ())
    with pytest.raises(OptionError) as err:
        runner.submit(engine, kind, params, executor=None)
    assert words in str(err.value) and "\n" not in str(err.value)
    with engine.connect() as c:
        assert c.exec_driver_sql("select count(*) from jobs").scalar_one() == 0


def test_a_delivery_job_runs_while_a_long_fleet_job_holds_its_lane(tmp_path, monkeypatch):
    """Deliveries and fleet jobs run in two lanes: a day submitted behind a long fleet
    run is flown and done while that run goes on; a second fleet run waits for the first
    (one at a time in a lane)."""
    import threading

    release = threading.Event()

    def hold(engine, job_id, params, *, executor, progress):  # a long fleet run
        progress(0.5)
        release.wait(120)
        return {"held": True}

    monkeypatch.setitem(runner.KINDS, "fleet",
                        runner.KINDS["fleet"]._replace(check=dict, run=hold))
    engine = lunch_store(f"sqlite:///{tmp_path / 'lanes.db'}", ("2024-01-03",))
    with open_executor("local", workers=1) as ex:
        long = runner.submit(engine, "fleet", {}, executor=ex)
        after = runner.submit(engine, "fleet", {}, executor=ex)
        try:
            day = runner.submit(engine, "deliver", {"date": "2024-01-03",
                                                    "data": str(EXAMPLE)}, executor=ex)
            job = runner.wait(engine, day, timeout=90)
            assert job["state"] == "done" and job["result"]["days"] == 1, job
            assert runner.get(engine, long)["state"] == "running"
            assert runner.get(engine, after)["state"] == "queued"
        finally:
            release.set()
        for job_id in (long, after):
            assert runner.wait(engine, job_id, timeout=60)["result"] == {"held": True}
    settle()


def test_a_job_cut_off_by_the_executors_close_fails_as_an_orphan(tmp_path, monkeypatch):
    """The server shutting down closes the executor while a job's map runs in its lane:
    the job ends failed with the orphans' message (not "RuntimeError: cannot schedule
    new futures after shutdown"), and the job queued behind it fails so too rather than
    opening a new pool."""
    import threading

    from skyroute.jobs import store

    first = threading.Event()

    def spread(engine, job_id, params, *, executor, progress):
        executor.map(time.sleep, [0.2] * 8, on_result=lambda i, r: first.set())
        return {"ran": True}

    monkeypatch.setitem(runner.KINDS, "spread", runner.Kind(dict, spread, "fleet"))
    engine = lunch_store(f"sqlite:///{tmp_path / 'closed.db'}", ())
    ex = open_executor("local", workers=2)
    try:
        running = runner.submit(engine, "spread", {}, executor=ex)
        queued = runner.submit(engine, "spread", {}, executor=ex)
        assert first.wait(60), "no task ended"
        assert store.get_job(engine, queued)["state"] == "queued"
    finally:
        ex.close()
    for job_id in (running, queued):
        job = runner.wait(engine, job_id, timeout=60)
        assert (job["state"], job["error"], job["result"]) == \
            ("failed", runner.ORPHANED, None), job
    settle()


def test_two_servers_on_one_store_fail_only_the_orphans_of_dead_ones(tmp_path, monkeypatch):
    """This process's job and a live server's job survive another server's start and
    this process's heartbeat; a silent server's job and one without an owner do not."""
    import datetime as dt
    import threading

    from skyroute.delivery.store import tables
    from skyroute.jobs import store

    release = threading.Event()

    def hold(engine, job_id, params, *, executor, progress):
        progress(0.5)
        release.wait(60)
        return {"held": True}

    monkeypatch.setitem(runner.KINDS, "hold", runner.Kind(dict, hold))
    engine = lunch_store(f"sqlite:///{tmp_path / 'two.db'}", ())
    mine = runner.submit(engine, "hold", {}, executor=None)
    try:
        assert runner.get(engine, mine)["owner"] == runner.owner()
        end = time.monotonic() + 60
        while runner.get(engine, mine)["state"] != "running" and time.monotonic() < end:
            time.sleep(0.01)
        store.beat(engine, "other-server:1:a")  # another server, alive, with its job
        other = store.create_job(engine, "fleet", {}, owner="other-server:1:a")
        store.set_progress(engine, other, 0.2)
        with engine.begin() as c:  # a server last heard of two DEAD_AFTERs ago
            then = store.db_now(c) - dt.timedelta(seconds=2 * runner.DEAD_AFTER)
            c.execute(tables(engine, ("servers",))["servers"].insert().values(
                id="gone-server:2:b", started=then, heartbeat=then))
        dead = store.create_job(engine, "fleet", {}, owner="gone-server:2:b")
        store.set_progress(engine, dead, 0.7)
        unowned = store.create_job(engine, "fleet", {})  # as a server before owners

        assert sorted(runner.fail_orphans(engine)) == sorted([dead, unowned])  # a start
        runner.heartbeat()  # nothing more to fail; this process beats
        for job_id, state in ((mine, "running"), (other, "running"), (dead, "failed"),
                              (unowned, "failed")):
            job = runner.get(engine, job_id)
            assert job["state"] == state, (job_id, job)
        assert runner.get(engine, dead)["error"] == runner.ORPHANED
        with engine.connect() as c:
            servers = tables(engine, ("servers",))["servers"]
            assert set(c.scalars(sa.select(servers.c.id))) == {runner.owner(),
                                                               "other-server:1:a"}
    finally:
        release.set()
    job = runner.wait(engine, mine, timeout=60)
    assert (job["state"], job["result"]) == ("done", {"held": True})


def test_reading_a_dead_servers_job_fails_it(tmp_path):
    """Where no server has jobs to beat for, a job whose owner is silent is failed when
    it is read; another live server's job is not."""
    import datetime as dt

    from skyroute.delivery.store import tables
    from skyroute.jobs import store

    engine = lunch_store(f"sqlite:///{tmp_path / 'read.db'}", ())
    with engine.begin() as c:
        then = store.db_now(c) - dt.timedelta(seconds=2 * runner.DEAD_AFTER)
        c.execute(tables(engine, ("servers",))["servers"].insert().values(
            id="gone-server:2:b", started=then, heartbeat=then))
    dead = store.create_job(engine, "fleet", {}, owner="gone-server:2:b")
    store.beat(engine, "other-server:1:a")
    live = store.create_job(engine, "fleet", {}, owner="other-server:1:a")
    assert store.get_job(engine, dead)["state"] == "queued"
    job = runner.get(engine, dead)
    assert (job["state"], job["error"]) == ("failed", runner.ORPHANED)
    assert runner.get(engine, live)["state"] == "queued"


CHILD = """
import sys
from skyroute.jobs import runner, store
engine = store.engine_for(sys.argv[1])
me = runner.owner()
store.beat(engine, me)
job = store.create_job(engine, "fleet", {}, owner=me)
store.set_progress(engine, job, 0.3)
print(job, me, flush=True)
sys.stdin.read()  # runs until the test closes its stdin
"""


def _child_running_a_job(url: str):
    """A Python process that takes a running job in the store at ``url`` (CHILD), prints
    its id and owner and waits for its stdin to close."""
    import os
    import subprocess
    import sys

    return subprocess.Popen([sys.executable, "-c", CHILD, url], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True,
                            env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})


@pytest.mark.parametrize("db", ["sqlite", "postgresql"])
def test_a_stopped_servers_jobs_fail_at_once_on_its_machine(tmp_path, request, db):
    """A server process on this machine that has ended, a moment after its heartbeat,
    has its running job failed at the next look (a restarted server's start, or a read),
    not 60 s later; while it runs its job is left alone."""
    from skyroute.jobs import store

    url = (f"sqlite:///{tmp_path / 'gone.db'}" if db == "sqlite"
           else request.getfixturevalue("pg_url"))
    engine = lunch_store(url, ())
    child = _child_running_a_job(url)
    try:
        job_id, its_owner = child.stdout.readline().split()
        assert runner.fail_orphans(engine) == []
        assert runner.get(engine, job_id)["state"] == "running"
    finally:
        child.stdin.close()
    assert child.wait(60) == 0
    assert runner.fail_orphans(engine) == [job_id]  # as `skyroute serve` at its start
    job = runner.get(engine, job_id)
    assert (job["state"], job["error"]) == ("failed", runner.ORPHANED)
    assert its_owner not in store.live_owners(engine)


def test_reading_a_job_of_an_ended_process_fails_it_at_once(tmp_path):
    """``runner.get`` (GET /jobs/{id}) fails the job of a process seen to have ended
    even right after another read looked for orphans."""

    url = f"sqlite:///{tmp_path / 'read.db'}"
    engine = lunch_store(url, ())
    child = _child_running_a_job(url)
    try:
        job_id, _ = child.stdout.readline().split()
        assert runner.get(engine, job_id)["state"] == "running"  # looked: none for 10 s
    finally:
        child.stdin.close()
    assert child.wait(60) == 0
    job = runner.get(engine, job_id)
    assert (job["state"], job["error"]) == ("failed", runner.ORPHANED)


def test_reading_a_job_without_an_owner_between_looks_for_orphans(tmp_path):
    """A job stored before owners were (owner None) read right after a look for orphans
    is shown as it is (and failed at the next look), not an error."""
    from skyroute.jobs import store

    engine = lunch_store(f"sqlite:///{tmp_path / 'none.db'}", ())
    first = store.create_job(engine, "fleet", {})
    assert runner.get(engine, first)["state"] == "failed"  # a look for orphans
    second = store.create_job(engine, "fleet", {})
    assert runner.get(engine, second)["state"] == "queued"  # within HEARTBEAT_EVERY
    assert second in runner.fail_orphans(engine)


def test_only_an_owner_this_process_can_see_is_known_gone():
    """Its process id free, a zombie's, or another process's (started at another time):
    gone. On another machine or in another container, or an owner id without the
    process's start: not known, left to the heartbeat."""
    import os
    import subprocess
    import sys

    me = runner.owner()
    host, pid, rand, space, start = me.rsplit(":", 4)
    assert int(pid) == os.getpid() and space == runner._space() and start.isdigit()
    ended = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                           capture_output=True, text=True, check=True)
    free = int(ended.stdout)  # a process id that was just given back
    parent = os.getppid()
    its_start = runner._started(parent)[1]
    assert runner.gone(f"{host}:{free}:{rand}:{space}:{start}")
    assert runner.gone(f"{host}:{parent}:{rand}:{space}:{int(its_start) + 1}")  # reused
    assert not runner.gone(f"{host}:{parent}:{rand}:{space}:{its_start}")  # alive
    assert not runner.gone(f"{host}:{free}:{rand}:{'0' * 12}:{start}")  # elsewhere
    assert not runner.gone(f"{host}:{free}:{rand}")  # an owner id of an older server
    assert not runner.gone(me) and not runner.gone("other-server:1:a")
    zombie = subprocess.Popen([sys.executable, "-c", "pass"])
    end = time.monotonic() + 60
    while runner._started(zombie.pid)[0] != "Z" and time.monotonic() < end:
        time.sleep(0.01)
    try:
        assert runner.gone(f"{host}:{zombie.pid}:{rand}:{space}:"
                           f"{runner._started(zombie.pid)[1]}")
    finally:
        zombie.wait()


def stall(engine) -> None:
    """As if this process had been silent for two DEAD_AFTERs: its heartbeat set back,
    then another server fails its jobs as orphans."""
    import datetime as dt

    from skyroute.delivery.store import tables
    from skyroute.jobs import store

    servers = tables(engine, ("servers",))["servers"]
    with engine.begin() as c:
        then = store.db_now(c) - dt.timedelta(seconds=2 * runner.DEAD_AFTER)
        c.execute(servers.update().where(servers.c.id == runner.owner())
                  .values(heartbeat=then))
    store.fail_orphans(engine, runner.ORPHANED, dead_after=runner.DEAD_AFTER)


def settle(timeout: float = 60) -> None:
    """Wait until this process has no job queued or running."""
    end = time.monotonic() + timeout
    while runner.pending() and time.monotonic() < end:
        time.sleep(0.01)
    assert runner.pending() == 0


@pytest.mark.parametrize("late", ["result", "progress"])
def test_jobs_failed_while_this_process_stalled_stay_failed(tmp_path, monkeypatch, caplog,
                                                            late):
    """A stall fails this process's running and queued jobs as orphans. When it wakes,
    the running job's result (or its next progress) is discarded and the queued job is
    not run: both stay failed as the client was told."""
    import threading

    release, ran = threading.Event(), []

    def hold(engine, job_id, params, *, executor, progress):
        ran.append(job_id)
        progress(0.5)
        release.wait(60)
        if late == "progress":
            progress(1.0)
            ran.append("went on")
        return {"late": True}

    monkeypatch.setattr(runner, "heartbeat", lambda: None)  # the stall: no beats
    monkeypatch.setitem(runner.KINDS, "hold", runner.Kind(dict, hold))
    engine = lunch_store(f"sqlite:///{tmp_path / 'stall.db'}", ())
    first = runner.submit(engine, "hold", {}, executor=None)
    second = runner.submit(engine, "hold", {}, executor=None)
    try:
        end = time.monotonic() + 60
        while runner.get(engine, first)["state"] != "running" and time.monotonic() < end:
            time.sleep(0.01)
        stall(engine)
        assert [runner.get(engine, i)["state"] for i in (first, second)] == ["failed"] * 2
    finally:
        release.set()
    with caplog.at_level("WARNING", logger="skyroute.jobs"):
        settle()
    assert ran == [first]  # the second job never ran; the first stopped at its progress
    for job_id in (first, second):
        job = runner.get(engine, job_id)
        assert (job["state"], job["error"], job["result"]) == \
            ("failed", runner.ORPHANED, None), job
    said = caplog.text
    what = "its result is discarded" if late == "result" else "it is stopped"
    assert f"job {first} is already failed ({runner.ORPHANED}); {what}" in said, said
    assert f"job {second} is already failed ({runner.ORPHANED}); it is not run" in said


@pytest.mark.parametrize("when", ["before the run is stored", "after the run is stored"])
def test_a_fleet_job_failed_while_it_ran_leaves_no_run(tmp_path, monkeypatch, when):
    """A fleet job failed as an orphan while its worker simulated (or just after the
    worker stored the run) ends failed, with no run left in fleet_runs."""
    from skyroute.jobs import fleet, store

    engine = lunch_store(f"sqlite:///{tmp_path / 'fleet.db'}", ())
    monkeypatch.setattr(runner, "heartbeat", lambda: None)
    if when == "before the run is stored":
        real = fleet.report
        monkeypatch.setattr(fleet, "report", lambda sim: (stall(engine), real(sim))[1])
    else:
        real = store.save_fleet_run
        monkeypatch.setattr(store, "save_fleet_run",
                            lambda *a, **kw: (real(*a, **kw), stall(engine))[0])
    with open_executor("local", workers=1) as ex:  # the task runs in this process
        job_id = runner.submit(engine, "fleet", {"preset": "seed-3x3", "hours": 0.1},
                               executor=ex)
        settle(300)
    job = runner.get(engine, job_id)
    assert (job["state"], job["error"], job["result"]) == ("failed", runner.ORPHANED, None)
    assert store.list_fleet_runs(engine, job_id=job_id) == []
