"""open_executor: the same results in item order on every kind, progress as tasks end,
errors raised as themselves, bad addresses one clear line."""

from __future__ import annotations

import contextlib
import math
import time
import warnings

import pytest

from skyroute.errors import OptionError, SkyrouteError
from skyroute.jobs import executor as executor_mod
from skyroute.jobs.executor import open_executor

ITEMS = [4.0, 1.0, 9.0, 16.0, 25.0]


@pytest.mark.parametrize("workers", [1, 2])
def test_local_results_in_item_order_and_each_reported_once(workers):
    seen = []
    with open_executor("local", workers=workers) as ex:
        out = ex.map(math.sqrt, ITEMS, on_result=lambda i, r: seen.append((i, r)))
    assert out == [2.0, 1.0, 3.0, 4.0, 5.0]
    assert sorted(seen) == list(enumerate(out))


def test_maps_from_two_threads_take_turns_on_the_local_workers():
    """A short map started while a long one runs (the runner's two lanes) waits for a few
    of the long one's tasks, not for all of them: it ends long before the long one."""
    import threading

    ends = {}
    with open_executor("local", workers=2) as ex:
        ex.map(time.sleep, [0.0, 0.0])  # the pool's processes started

        def long():
            ex.map(time.sleep, [0.3] * 12)  # 6 rounds of 2 workers: about 1.8 s
            ends["long"] = time.monotonic()

        thread = threading.Thread(target=long)
        thread.start()
        time.sleep(0.2)
        ex.map(time.sleep, [0.01, 0.01])
        ends["short"] = time.monotonic()
        thread.join()
    assert ends["short"] < ends["long"] - 0.6, ends


def test_dask_gives_what_local_gives(dask_executor):
    seen = []
    out = dask_executor.map(math.sqrt, ITEMS, on_result=lambda i, r: seen.append((i, r)))
    assert out == [2.0, 1.0, 3.0, 4.0, 5.0] and sorted(seen) == list(enumerate(out))
    assert dask_executor.map(math.sqrt, []) == []
    assert dask_executor.workers == 2 and dask_executor.kind == "dask"


@pytest.mark.parametrize("kind", ["local", "dask"])
def test_a_failing_task_raises_its_own_error(kind, dask_executor):
    ex = dask_executor if kind == "dask" else open_executor("local", workers=2)
    try:
        with pytest.raises(ValueError, match="math domain error"):
            ex.map(math.sqrt, [1.0, -1.0, 4.0])
        assert ex.map(math.sqrt, [9.0]) == [3.0]  # still usable afterwards
    finally:
        if kind == "local":
            ex.close()


@pytest.mark.parametrize("kwargs, words", [
    ({"kind": "spark"}, "kind='spark' is not valid; choose one of 'local', 'dask'"),
    ({"kind": "local", "workers": 0}, "workers=0 must be an integer >= 1"),
    ({"kind": "local", "address": "tcp://h:8786"}, "address='tcp://h:8786' needs kind='dask'"),
    ({"kind": "dask", "address": "nonsense"}, "address='nonsense': no Dask scheduler there"),
    ({"kind": "dask", "address": "http://127.0.0.1:8786"}, "unknown address scheme 'http'"),
])
def test_bad_options_are_one_line_errors(kwargs, words):
    with pytest.raises(SkyrouteError) as err:
        open_executor(**kwargs)
    assert words in str(err.value) and "\n" not in str(err.value)


def test_a_scheduler_that_does_not_answer_is_an_error_within_the_timeout(monkeypatch):
    monkeypatch.setattr(executor_mod, "CONNECT_TIMEOUT", "1s")
    t0 = time.perf_counter()
    with pytest.raises(SkyrouteError, match=r"address='tcp://127.0.0.1:9': no Dask "
                                            r"scheduler there \(Timed out") as err:
        open_executor("dask", address="tcp://127.0.0.1:9")
    assert err.value.param == "address" and time.perf_counter() - t0 < 10
    assert not isinstance(err.value, OptionError)


@contextlib.contextmanager
def _not_a_scheduler(answer: bytes | None):
    """A TCP server on a free port of 127.0.0.1 that is no Dask scheduler: it says
    ``answer`` to each connection (an HTTP server's reply, as on the dashboard's port
    8787), or nothing at all (``None``), and keeps the connection open."""
    import socket
    import threading

    server = socket.create_server(("127.0.0.1", 0))
    held = []

    def serve():
        with contextlib.suppress(OSError):
            while True:
                conn, _ = server.accept()
                held.append(conn)
                if answer is not None:
                    conn.sendall(answer)

    threading.Thread(target=serve, daemon=True).start()
    try:
        yield f"tcp://127.0.0.1:{server.getsockname()[1]}"
    finally:
        server.close()
        for conn in held:
            conn.close()


@pytest.mark.parametrize("answer", [None, b"HTTP/1.1 400 Bad Request\r\n\r\n"],
                         ids=["silent", "http"])
def test_a_server_that_is_no_scheduler_is_an_error_within_the_timeout(monkeypatch, answer):
    """``--dask`` at a port where another server listens: distributed bounds the TCP
    connection but not the handshake after it, so a silent server kept the command
    waiting for ever, and an HTTP answer was read as a frame of 3 EiB (a MemoryError
    traceback). Both are the one-line error, within the timeout."""
    import threading

    monkeypatch.setattr(executor_mod, "CONNECT_TIMEOUT", "1s")
    raised = []

    def connect(address):
        try:
            open_executor("dask", address=address).close()
        except BaseException as exc:
            raised.append(exc)

    with _not_a_scheduler(answer) as address:
        # in a thread: the old code never returned from the silent server. 60 s bounds
        # a 1 s timeout on a loaded machine (8 s was too few in a CI at load 15, its
        # event loop stalled for 5 s), and still tells "within the timeout" from never
        attempt = threading.Thread(target=connect, args=(address,), daemon=True)
        attempt.start()
        attempt.join(60)
        assert not attempt.is_alive(), "still waiting for the handshake"
    (err,) = raised
    assert isinstance(err, SkyrouteError), repr(err)
    assert str(err).startswith(f"address={address!r}: no Dask scheduler there (")
    assert "\n" not in str(err) and err.param == "address"


def test_a_tls_scheduler_of_the_dask_configuration_is_reached(tmp_path):
    """A ``tls://`` scheduler whose certificates are in Dask's configuration, as
    ``Client`` reads them: the handshake check connected without them and refused it
    ("TLS expects a `ssl_context` argument")."""
    import shutil
    import subprocess

    import dask
    from distributed import LocalCluster
    from distributed.security import Security

    if shutil.which("openssl") is None:
        pytest.skip("no openssl to make a certificate")
    cert, key = str(tmp_path / "cert.pem"), str(tmp_path / "key.pem")
    subprocess.run(["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout",
                    key, "-out", cert, "-days", "1", "-subj", "/CN=localhost", "-addext",
                    "subjectAltName=IP:127.0.0.1"], check=True, capture_output=True)
    roles = {f"tls_{r}_{k}": v for r in ("client", "scheduler", "worker")
             for k, v in (("cert", cert), ("key", key))}
    security = Security(tls_ca_file=cert, require_encryption=True, **roles)
    config = {"distributed.comm.require-encryption": True,
              "distributed.comm.tls.ca-file": cert, "distributed.comm.tls.client.cert": cert,
              "distributed.comm.tls.client.key": key}
    cluster = LocalCluster(n_workers=0, processes=False, protocol="tls", security=security,
                           host="127.0.0.1", dashboard_address=None)
    with cluster, dask.config.set(config), \
            open_executor("dask", address=cluster.scheduler_address) as ex:
        assert ex.client.scheduler.address == cluster.scheduler_address


def _in_memory(dask_scheduler, prefix: str) -> int:
    """On the scheduler: how many tasks whose key starts with ``prefix`` hold a result."""
    return sum(1 for k, ts in dask_scheduler.tasks.items()
               if str(k).startswith(prefix) and ts.state == "memory")


def test_dask_lets_go_of_each_result_once_it_has_it(dask_executor):
    """A result taken is released on the cluster while the map runs: kept to the map's
    end, every result stayed in its worker's memory, and a worker that died late in a
    range had every task it had finished run again."""
    client = dask_executor.client
    quick: list[int] = []  # the quick tasks come back long before the slow one
    held: list[int] = []  # tasks in memory on the cluster once all three came back

    def on_result(i: int, _r) -> None:
        if i == 3:
            return
        quick.append(i)
        if len(quick) == 3:  # wait (up to 3 s) until the scheduler has let go of them
            end = time.monotonic() + 3
            while not held or (held[-1] and time.monotonic() < end):
                held.append(client.run_on_scheduler(_in_memory, prefix="sleep-"))
                time.sleep(0.05)

    out = dask_executor.map(time.sleep, [0.0, 0.0, 0.0, 5.0], on_result=on_result)
    assert out == [None] * 4 and sorted(quick) == [0, 1, 2]
    assert held[-1] == 0, f"{held[-1]} finished tasks still held on the cluster"


def test_ctrl_c_in_the_terminal_leaves_the_local_clusters_workers_to_the_command():
    """Ctrl-C reaches every process of the terminal's group: each worker of the
    in-process cluster printed a KeyboardInterrupt traceback over the command's
    "skyroute: interrupted", and its nanny started it again. They ignore it; the
    command closes the cluster."""
    import os
    import signal

    with open_executor("dask", workers=1) as ex:
        client = ex.client
        (pid,) = client.run(os.getpid).values()
        os.kill(pid, signal.SIGINT)
        time.sleep(1.0)  # a worker that took it ends, and its nanny starts another
        client.wait_for_workers(1, timeout=10)
        assert list(client.run(os.getpid).values()) == [pid]
        assert ex.map(math.sqrt, [4.0]) == [2.0]


def test_an_existing_scheduler_runs_the_tasks(dask_executor):
    address = dask_executor.client.scheduler.address
    with open_executor("dask", address=address, workers=5) as ex:  # workers: unused
        assert ex.workers == 2 and ex.map(math.sqrt, [16.0, 9.0]) == [4.0, 3.0]


def test_another_skyroute_on_the_cluster_is_refused(dask_executor, monkeypatch):
    import importlib.metadata

    real = importlib.metadata.version
    monkeypatch.setattr(importlib.metadata, "version",
                        lambda name: "9.9" if name == "skyroute" else real(name))
    address = dask_executor.client.scheduler.address
    with pytest.raises(SkyrouteError) as err:
        open_executor("dask", address=address)
    assert str(err.value) == (f"address={address!r}: the scheduler has skyroute "
                              f"{real('skyroute')}, this machine 9.9; install the same "
                              "skyroute on the scheduler and every worker")


def test_a_worker_that_cannot_import_the_tasks_is_refused(dask_executor, monkeypatch):
    """A worker whose skyroute is installed (the versions agree) but does not import (a
    dependency missing on its machine; here a module of the tasks that is not there)
    closed itself on its first task, and with no other worker the run waited forever."""
    monkeypatch.setattr(executor_mod, "TASK_IMPORTS", "import skyroute.jobs.no_such_module",
                        raising=False)
    address = dask_executor.client.scheduler.address
    with pytest.raises(SkyrouteError) as err:
        open_executor("dask", address=address)
    text = str(err.value)
    assert text.startswith(f"address={address!r}: worker tcp://") and "\n" not in text
    assert ("cannot import skyroute's tasks (ModuleNotFoundError: No module named "
            "'skyroute.jobs.no_such_module'); install the same skyroute") in text
    assert dask_executor.map(math.sqrt, [4.0]) == [2.0]  # the workers are still there


@pytest.mark.parametrize("kind, workers", [("local", 2), ("local", 1), ("dask", 1)])
def test_closing_cuts_off_another_threads_map_with_a_clear_error(kind, workers):
    """A server shutting down closes its executor while a lane's map runs: that map ends
    in ExecutorClosedError (not the pool's "cannot schedule new futures after shutdown"
    RuntimeError, nor a Dask client error), and so does a map started afterwards (no new
    pool is opened behind the close)."""
    import threading

    ex = open_executor(kind, workers=workers)
    first = threading.Event()
    raised: list[BaseException] = []

    def lane():
        try:
            ex.map(time.sleep, [0.2] * 8, on_result=lambda i, r: first.set())
        except BaseException as exc:  # what the runner's lane would see
            raised.append(exc)

    thread = threading.Thread(target=lane)
    thread.start()
    try:
        assert first.wait(60), "no task ended"
    finally:
        ex.close()
    thread.join(60)
    assert not thread.is_alive()
    assert [type(e).__name__ for e in raised] == ["ExecutorClosedError"], raised
    assert isinstance(raised[0], SkyrouteError)
    assert str(raised[0]) == (f"the {kind} executor was closed; the tasks not yet started "
                              "were cancelled")
    with pytest.raises(SkyrouteError, match=f"the {kind} executor was closed"):
        ex.map(math.sqrt, ITEMS)
    if kind == "local":
        assert ex._pool is None
ABORTED = """
import os, signal, sys, time
from pathlib import Path
from skyroute.jobs.executor import open_executor

def task(i):
    here = Path(sys.argv[1])
    (here / f"started-{i}").touch()
    time.sleep(10)
    (here / f"done-{i}").touch()  # what a task stores when it runs to its end
    return i

if __name__ == "__main__":
    try:
        with open_executor("local", workers=2) as ex:
            ex.map(task, range(6))
    except KeyboardInterrupt:
        print("interrupted", flush=True)
"""


def test_ctrl_c_in_a_local_map_ends_the_running_tasks(tmp_path):
    """Ctrl-C (to the whole process group, as a terminal sends it) while workers run
    tasks: the workers print nothing, their tasks stop where they are, no task starts
    after it, and the program ends with no worker left. The tasks ran to the end (a
    range of days stored after 'interrupted', the exit waiting for them) and the
    workers printed KeyboardInterrupt tracebacks."""
    import os
    import signal
    import subprocess
    import sys
    from pathlib import Path

    import skyroute

    script = tmp_path / "aborted.py"
    script.write_text(ABORTED)
    env = {**os.environ, "PYTHONPATH": str(Path(skyroute.__file__).resolve().parents[1])}
    p = subprocess.Popen([sys.executable, str(script), str(tmp_path)], env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         start_new_session=True)
    try:
        while len(list(tmp_path.glob("started-*"))) < 2 and p.poll() is None:
            time.sleep(0.01)
        os.killpg(p.pid, signal.SIGINT)
        # communicate ends when every process holding the pipes (the workers) has ended
        out, err = p.communicate(timeout=9)
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(p.pid, signal.SIGKILL)
    assert (out, err, p.returncode) == ("interrupted\n", "", 0)
    assert sorted(f.name for f in tmp_path.glob("*-*")) == ["started-0", "started-1"]


def test_a_dying_local_worker_loses_only_the_task_that_kills_it(caplog):
    """A task that kills its worker process (the out-of-memory killer, a crash): the map
    raised BrokenProcessPool at once, with the results of the tasks in flight on the
    other workers and of those not yet started lost. Now the others run on in a fresh
    pool, the tasks the broken pool held run again each alone, and only those that kill
    their process again are lost, named with how it ended."""
    from skyroute.jobs.executor import TasksLostError
    from tests.jobs.failing import die_below_zero

    seen = []
    with open_executor("local", workers=2) as ex:
        with pytest.raises(TasksLostError) as info, caplog.at_level("WARNING"):
            ex.map(die_below_zero, [1, -9, 2, 3, -3, 4, 5],
                   on_result=lambda i, r: seen.append((i, r)))
        assert ex.map(abs, [-1, -2]) == [1, 2]  # still usable afterwards
    again = "also when run again alone"
    assert info.value.lost == {
        1: f"its worker process died (killed by SIGKILL, as the out-of-memory killer "
           f"does), {again}",
        4: f"its worker process died (exit code 3), {again}"}
    assert info.value.results == [1, None, 2, 3, None, 4, 5]
    assert sorted(seen) == [(0, 1), (2, 2), (3, 3), (5, 4), (6, 5)]  # each once
    assert str(info.value).startswith("2 of the 7 tasks were lost: task 1: its worker "
                                      "process died (killed by SIGKILL")
    assert any("a worker process died" in r.getMessage() for r in caplog.records)


def test_a_task_whose_worker_dies_once_is_run_again(tmp_path):
    # a worker killed from outside (an operator's kill, the out-of-memory killer taking
    # the biggest process): every task of the pool is run again, none lost
    from tests.jobs.failing import die_once

    marks = [str(tmp_path / name) for name in ("a", "die-b", "c", "d", "e", "f")]
    seen = []
    with open_executor("local", workers=2) as ex:
        assert ex.map(die_once, marks, on_result=lambda i, r: seen.append(i)) == marks
    assert (tmp_path / "die-b").exists()  # it did die once
    assert sorted(seen) == list(range(6))


def test_a_task_run_again_alone_that_raises_leaves_no_process():
    """A task of a broken pool that raises when run again alone: its error is the
    map's, and its one-process pool ends with it (it was kept until the executor
    closed: on a server, an idle worker process each time, until it stopped)."""
    import multiprocessing
    import re

    from tests.jobs.failing import die_or_raise

    with open_executor("local", workers=2) as ex:
        with pytest.raises(ValueError, match="task 1 failed in process") as info:
            ex.map(die_or_raise, [-9, 1])
        pid = int(re.search(r"process (\d+)", str(info.value))[1])
        end = time.monotonic() + 10  # a bound for a slow machine, not a measurement
        while (pid in {p.pid for p in multiprocessing.active_children()}
               and time.monotonic() < end):
            time.sleep(0.05)
        assert pid not in {p.pid for p in multiprocessing.active_children()}
        assert ex.map(abs, [-1, -2]) == [1, 2]  # still usable afterwards


ABORTED_ALONE = """
import os, signal, sys, time
from pathlib import Path
from skyroute.jobs.executor import open_executor

def task(i):
    here = Path(sys.argv[1])
    (here / f"started-{i}-{os.getpid()}").touch()
    if i == 0:  # kills its worker, twice: the second time run alone
        time.sleep(0.3)
        os.kill(os.getpid(), signal.SIGKILL)
    time.sleep(10)
    (here / f"done-{i}").touch()
    return i

if __name__ == "__main__":
    try:
        with open_executor("local", workers=2) as ex:
            ex.map(task, range(3))
    except KeyboardInterrupt:
        print("interrupted", flush=True)
"""


def test_ctrl_c_while_tasks_run_again_alone_ends_them(tmp_path):
    """Ctrl-C while the tasks of a broken pool run again one at a time: the process
    running one alone ends too (it ran to its end, the exit waiting for it)."""
    import os
    import signal
    import subprocess
    import sys
    from pathlib import Path

    import skyroute

    script = tmp_path / "aborted.py"
    script.write_text(ABORTED_ALONE)
    env = {**os.environ, "PYTHONPATH": str(Path(skyroute.__file__).resolve().parents[1])}
    p = subprocess.Popen([sys.executable, str(script), str(tmp_path)], env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         start_new_session=True)

    def started(i: int) -> set:
        return set(tmp_path.glob(f"started-{i}-*"))

    try:
        end = time.monotonic() + 120
        while len(started(0)) < 2 and p.poll() is None and time.monotonic() < end:
            time.sleep(0.01)  # task 0 has killed its process run alone: 1 runs next
        before = started(1)
        while started(1) == before and p.poll() is None and time.monotonic() < end:
            time.sleep(0.01)
        assert p.poll() is None and len(started(0)) == 2, p.communicate()
        os.killpg(p.pid, signal.SIGINT)
        out, err = p.communicate(timeout=9)
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(p.pid, signal.SIGKILL)
    assert (out, p.returncode) == ("interrupted\n", 0), err
    assert not list(tmp_path.glob("done-*"))


def test_an_error_of_a_task_in_a_worker_is_raised_as_itself():
    # a SkyrouteError whose constructor takes more than its message (DaysFailedError,
    # InputFormatError, ...) raised in a pool worker did not unpickle in the caller: the
    # pool broke ('terminated abruptly'), the task was run again alone and reported
    # lost, "its worker process died (killed by SIGTERM)", its message gone
    from skyroute.jobs.deliver import DaysFailedError
    from tests.jobs.failing import raise_days_failed

    with open_executor("local", workers=2) as ex, pytest.raises(DaysFailedError) as info:
        ex.map(raise_days_failed, [1, 0, 2])
    assert str(info.value) == "1 of the 2 days failed and was not stored (the other 1 " \
        "is): 2024-01-01: the planner failed"
    assert info.value.days == 2 and info.value.failed[0].expected



class _BreakingSubmits:
    """``executor._new_pool`` whose pools refuse some submits, as a pool does when one of
    its workers died since the map looked at it: marked broken, BrokenProcessPool (or,
    in the instant between the pool's thread marking it broken and shut down, 'cannot
    schedule new futures after shutdown'). ``broken``: {workers: submit numbers}, counted
    from 1 over every pool of that many workers (the map's pools have 2, those it runs a
    task again alone in 1)."""

    def __init__(self, broken: dict[int, set[int]], error: str) -> None:
        self.broken, self.error = broken, error
        self.submits = dict.fromkeys(broken, 0)
        self.real = executor_mod._new_pool

    def __call__(self, workers: int):
        from concurrent.futures.process import BrokenProcessPool

        pool = self.real(workers)
        real = pool.submit

        def submit(fn, *args, **kwargs):
            self.submits[workers] += 1
            if self.submits[workers] in self.broken[workers]:
                pool._broken = "A child process terminated abruptly"
                raise (BrokenProcessPool(pool._broken) if self.error == "BrokenProcessPool"
                       else RuntimeError("cannot schedule new futures after shutdown"))
            return real(fn, *args, **kwargs)

        pool.submit = submit
        return pool


@pytest.mark.parametrize("error", ["BrokenProcessPool", "RuntimeError"])
@pytest.mark.parametrize("broken", [
    {2: {1, 2}, 1: set()},  # task 0 refused by the map's pool and by a fresh one
    {2: {1, 2}, 1: {1}},  # and the pool it runs again alone in died idle
])
def test_a_pool_that_breaks_twice_before_a_submit_runs_the_task_again_alone(
        monkeypatch, caplog, error, broken):
    """Two workers dying in quick succession: the pool breaks between the map's look and
    its submit, and the fresh pool the map opens breaks too; or the one-process pool a
    task of a broken pool runs again in dies idle before its submit. The map ended in a
    BrokenProcessPool (or RuntimeError) traceback; now the task is run again alone, and
    every result comes back."""
    breaking = _BreakingSubmits(broken, error)
    monkeypatch.setattr(executor_mod, "_new_pool", breaking)
    seen = []
    with open_executor("local", workers=2) as ex, caplog.at_level("WARNING"):
        assert ex.map(abs, [-1, -2, -3], on_result=lambda i, r: seen.append(i)) == [1, 2, 3]
        assert ex.map(abs, [-4, -5]) == [4, 5]  # still usable afterwards
    assert sorted(seen) == [0, 1, 2]
    assert breaking.submits[1] == 1 + len(broken[1])  # task 0 alone: once more per refusal
    assert any("a worker process died" in r.getMessage() for r in caplog.records)


def test_a_task_every_pool_refuses_is_lost_in_one_line(monkeypatch):
    """Every pool refuses task 0 (the map's and a fresh one; the one it would run alone
    in and a fresh one): it is reported lost in one line, the others' results kept; no
    BrokenProcessPool traceback."""
    from skyroute.jobs.executor import TasksLostError

    monkeypatch.setattr(executor_mod, "_new_pool",
                        _BreakingSubmits({2: {1, 2}, 1: {1, 2}}, "BrokenProcessPool"))
    with open_executor("local", workers=2) as ex, pytest.raises(TasksLostError) as info:
        ex.map(abs, [-1, -2, -3])
    assert info.value.results == [None, 2, 3] and list(info.value.lost) == [0]
    assert info.value.lost[0] == ("its worker process died (exit status unknown), also "
                                  "when run again alone")
    assert str(info.value).startswith("1 of the 3 tasks was lost: task 0: its worker ")


def test_a_scheduler_without_workers_says_so_and_its_tasks_wait_for_one(caplog):
    """A scheduler whose workers have not joined (or have all left): the tasks wait for
    one without a word from Dask, and the command looked hung. It says so once."""
    import logging
    import threading

    from distributed import LocalCluster

    with LocalCluster(n_workers=0, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, \
            caplog.at_level(logging.WARNING, logger="skyroute.jobs"), \
            open_executor("dask", address=cluster.scheduler_address) as ex:
        out: list = []
        thread = threading.Thread(target=lambda: out.append(ex.map(math.sqrt, [9.0])))
        thread.start()

        def said() -> list[str]:
            return [r.getMessage() for r in caplog.records if r.name == "skyroute.jobs"]

        end = time.monotonic() + 30
        while not said() and time.monotonic() < end:
            time.sleep(0.05)
        assert said() == [f"the Dask scheduler at {cluster.scheduler_address} has no "
                          "workers; the tasks wait until one joins"]
        cluster.scale(1)
        thread.join(timeout=60)
        assert out == [[3.0]]


def _sigint_blocked_here(_):
    """In a pool worker: whether SIGINT is blocked in it (its mask from its start)."""
    import signal

    return signal.SIGINT in signal.pthread_sigmask(signal.SIG_BLOCK, [])


def test_local_workers_start_deaf_to_ctrl_c():
    """A Ctrl-C to the terminal's group in the second or so a spawned worker takes to
    start Python and reach the pool's initializer (which ignores SIGINT) printed a
    KeyboardInterrupt traceback from multiprocessing's spawn_main, one per worker.
    Workers are started with SIGINT blocked, from their first instruction; the caller's
    mask is as it was."""
    import signal

    before = signal.pthread_sigmask(signal.SIG_BLOCK, [])
    with open_executor("local", workers=2) as ex:
        assert ex.map(_sigint_blocked_here, [0, 1]) == [True, True]
    assert signal.pthread_sigmask(signal.SIG_BLOCK, []) == before



def test_dask_workers_start_deaf_to_ctrl_c(dask_executor):
    """As the local pool's: a Ctrl-C in the seconds the in-process cluster's workers took
    to import distributed (before the preload that ignores SIGINT) printed a
    KeyboardInterrupt traceback from each, "Nanny failed to start" and distributed's
    close_clusters AssertionError at exit. The cluster is started with SIGINT blocked;
    its workers inherit the mask, the caller's is as it was."""
    import signal

    assert list(dask_executor.client.run(_sigint_blocked_here, None).values()) == [True] * 2
    assert signal.SIGINT not in signal.pthread_sigmask(signal.SIG_BLOCK, [])

# A local Dask cluster takes no fixed port: two at once (two commands, or a command beside
# a notebook's cluster) printed distributed's "Port 8787 is already in use" warning to the
# second one's user.
def test_a_second_local_cluster_warns_of_no_busy_port(dask_executor):
    assert dask_executor.map(abs, [-1]) == [1]  # the module's cluster is up
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        second = open_executor("dask", workers=1)
        try:
            assert second.map(abs, [-2]) == [2]
        finally:
            second.close()
    assert not [w for w in seen if "already in use" in str(w.message)], \
        [str(w.message) for w in seen]
