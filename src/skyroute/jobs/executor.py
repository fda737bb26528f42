"""Where a list of independent tasks runs: a local process pool or a Dask cluster, behind
one small interface.

>>> with open_executor("local", workers=1) as ex:
...     ex.map(abs, [-2, 3, -5])
[2, 3, 5]

``map(fn, items, on_result=None)`` runs ``fn(item)`` for every item and returns the
results in item order; ``on_result(index, result)`` is called in the calling thread as
each one finishes (in finishing order), for progress bars and job progress. An exception
in a task is raised by ``map`` (the tasks not yet started are cancelled). ``fn`` and the
items must pickle: ``fn`` a module-level function, the items plain data. ``close`` while
another thread's ``map`` runs (a server shutting down under a job) cancels that map's
tasks not yet started, and the map raises :class:`ExecutorClosedError`, as does a ``map``
on a closed executor. A map with no task left to cancel (all of them handed to the workers
already: the local pool does not take back the ``workers + 1`` it has queued) runs them
to their end and returns their results, as if the close came after it.

A worker process that dies under a task (the out-of-memory killer, a signal, a crash in
compiled code) does not end the map: the other tasks run on, and a task whose worker
died every time it was tried (see each kind) is raised at the end as
:class:`TasksLostError`, with the results of the others (each already passed to
``on_result``) and one line per lost task.

- ``local``: ``workers`` processes started with the ``spawn`` method (a forked child of
  a process whose compiled kernels have started OpenMP threads dies), created on the
  first ``map`` and reused until ``close``; one worker runs the tasks in the calling
  process, as a plain loop. A ``map`` keeps at most twice ``workers`` of its tasks in
  the pool and hands it the next as one ends, so ``map`` calls from several threads
  (the runner's lanes) share the workers in turn: a short one started while a long one
  runs waits for a few of its tasks, not all of them. A worker that dies breaks the
  whole pool (Python ends its other workers and fails every task it held, not knowing
  which one killed it): the map goes on in a fresh pool, and runs the tasks the broken
  pool held again once the others are done, one at a time in a process of their own,
  so a task that kills its worker again is the one named (with the exit signal or code)
  and takes no other task with it. A task is tried at most twice. A pool that refuses a
  task as broken (a worker died since the map looked) is replaced by a fresh one; a task
  the fresh one refuses too is one of those run again alone.
- ``dask``: a ``distributed.Client`` on an existing scheduler (``address`` such as
  ``tcp://10.0.0.5:8786``) or on an in-process ``LocalCluster`` of ``workers`` worker
  processes, one thread each. Dask re-runs the tasks of a worker that dies on another
  one, so every task must be safe to run twice (each of skyroute's tasks writes its
  result in one transaction that replaces an earlier run of the same task); a task
  whose workers died ``distributed.scheduler.allowed-failures`` + 1 times (4 by
  default) is lost (Dask's ``KilledWorker``).
"""

from __future__ import annotations

import contextlib
import gc
import itertools
import logging
import multiprocessing
import os
import signal
import threading
import time
from collections.abc import Callable, Iterable
from concurrent.futures import FIRST_COMPLETED, CancelledError, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from skyroute.errors import OptionError, SkyrouteError, check_choice

log = logging.getLogger("skyroute.jobs")
KINDS = ("local", "dask")
CONNECT_TIMEOUT = "10s"  # an existing scheduler that does not answer within this is an error


class ExecutorClosedError(SkyrouteError):
    """A ``map`` cut off by its executor's ``close`` (its tasks not yet started were
    cancelled), or started after it."""


class TasksLostError(SkyrouteError):
    """Tasks of a ``map`` whose worker died under them every time they were tried; the
    map ran every other task. ``lost``: {item index: why, a clause such as "its worker
    process died (killed by SIGKILL), also when run again alone"}; ``results``: every
    result in item order, ``None`` at a lost task (the others were passed to
    ``on_result`` as they came)."""

    def __init__(self, lost: dict[int, str], results: list) -> None:
        self.lost, self.results = dict(sorted(lost.items())), results
        first, n = next(iter(self.lost.items())), len(lost)
        super().__init__(f"{n:,} of the {len(results):,} tasks {'was' if n == 1 else 'were'} "
                         f"lost: task {first[0]}: {first[1]}")


def _closed(ex: _Executor) -> ExecutorClosedError:
    return ExecutorClosedError(f"the {ex.kind} executor was closed; the tasks not yet "
                               "started were cancelled")


def open_executor(kind: str = "local", *, address: str | None = None,
                  workers: int | None = None) -> LocalExecutor | DaskExecutor:
    """An executor of ``kind`` (``local`` or ``dask``); close it (or use ``with``).

    ``workers``: processes (default: the CPU count); for ``dask`` the workers of the
    in-process cluster, ignored with ``address`` (the scheduler has its own workers).
    ``address``: an existing Dask scheduler; only for ``dask``. A malformed address or a
    scheduler that does not answer is a :class:`SkyrouteError` naming ``address``.
    """
    check_choice("kind", kind, KINDS)
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                or workers < 1):
        raise OptionError(f"workers={workers!r} must be an integer >= 1", param="workers")
    if kind == "local":
        if address is not None:
            raise OptionError(f"address={address!r} needs kind='dask'", param="address")
        return LocalExecutor(workers or os.cpu_count() or 1)
    return DaskExecutor(address=address, workers=workers)


class _Executor:
    workers: int
    kind: str
    aborted = False  # abort() was called: a task's error may be the workers ending

    def map(self, fn: Callable, items: Iterable, *,
            on_result: Callable[[int, Any], None] | None = None) -> list:
        raise NotImplementedError

    def close(self) -> None:
        raise NotImplementedError

    def abort(self) -> None:
        """Close, stopping the tasks that run (an error or Ctrl-C ended the work, or
        the server is shutting down)."""
        self.aborted = True
        self.close()

    def __enter__(self):
        return self

    def __exit__(self, exc_type, *exc) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abort()


class LocalExecutor(_Executor):
    """Tasks in ``workers`` spawned processes (or in this process when ``workers`` is 1)."""

    kind = "local"

    def __init__(self, workers: int) -> None:
        self.workers = workers
        self._pool: ProcessPoolExecutor | None = None
        self._alone: set[ProcessPoolExecutor] = set()  # maps' pools of one (_again_alone)
        self._lock = threading.Lock()  # map may be called from several threads
        self._closed = False

    def __repr__(self) -> str:
        return f"LocalExecutor(workers={self.workers})"

    def map(self, fn, items, *, on_result=None) -> list:
        items = list(items)
        if self.workers == 1 or len(items) <= 1:
            out = []
            for i, item in enumerate(items):
                if self._closed:  # (a task already running in this thread runs to its end)
                    raise _closed(self)
                out.append(fn(item))
                if on_result:
                    on_result(i, out[-1])
            return out
        suspects: list[int] = []  # held by a pool that broke: run again, alone

        def submit(item):
            with self._lock:  # never into a pool being shut down, nor a broken one
                if self._closed:  # (nor a new pool that nothing would close)
                    raise _closed(self)
                for tries in (1, 2):
                    if self._pool is not None and getattr(self._pool, "_broken", False):
                        # (it has ended its workers and shut itself down; shutdown()
                        # would forget them, which _how_ended reads)
                        self._pool = None
                    if self._pool is None:
                        self._pool = _new_pool(self.workers)
                    pool = self._pool
                    try:
                        with _sigint_blocked():  # (it may start a worker)
                            future = pool.submit(fn, item)
                    except (BrokenProcessPool, RuntimeError) as exc:
                        if not _broke(pool, exc):
                            raise
                        if tries == 1:  # it broke since the look above: a fresh one
                            continue
                        # the fresh one broke too (two workers dying in quick
                        # succession): the item runs again alone, as its pool's others
                        future = _failed(exc)
                    pool_of[future] = pool
                    # its processes as they are now: a broken pool's own table may have
                    # lost the one that died by the time _how_ended reads it
                    procs_of.setdefault(pool, {}).update(
                        getattr(pool, "_processes", None) or {})
                    return future

        pool_of: dict = {}  # future -> its pool
        procs_of: dict = {}  # pool -> {pid: process} of every worker it has had
        broke: list = []  # the pools that broke under our tasks

        def broken(i: int, future) -> None:
            if self._closed:  # abort() ended the workers: no task of ours killed them
                raise _closed(self)
            suspects.append(i)
            if pool_of[future] not in broke:
                broke.append(pool_of[future])

        try:
            out = _gather(submit, items, 2 * self.workers, on_result, on_broken=broken)
            if not suspects:
                return out
            log.warning("a worker process died (%s); the %d task(s) its pool held run "
                        "again, one at a time, each alone",
                        _how_ended(procs=list(procs_of.get(broke[0], {}).values())),
                        len(suspects))
            return self._again_alone(fn, items, sorted(suspects), out, on_result)
        except (CancelledError, RuntimeError):  # cancelled or refused by close
            if self._closed:
                raise _closed(self) from None
            raise

    def _submit_alone(self, pool, fn, item) -> tuple[ProcessPoolExecutor, Future]:
        """``item`` submitted to ``pool``, a one-process pool of :attr:`_alone` (None: a
        new one); a pool whose process died idle after the task before (killed from
        outside, or by what that task left running) is replaced once. Returns the pool
        and the future, a failed one when the fresh pool refuses too (the task is then
        lost, as a death under it)."""
        for tries in (1, 2):
            if pool is None:
                pool = _new_pool(1)
                self._alone.add(pool)
            try:
                with _sigint_blocked():
                    future = pool.submit(fn, item)
            except (BrokenProcessPool, RuntimeError) as exc:
                if not _broke(pool, exc):
                    raise
                future = _failed(exc)
                if tries == 1:
                    self._alone.discard(pool)
                    pool = None
                    continue
            return pool, future

    def _again_alone(self, fn, items: list, again: list[int], out: list, on_result) -> list:
        """Run ``fn`` on the items at ``again`` (their pool broke under them) one at a
        time, each alone in a one-process pool (a fresh one after a death): fill ``out``
        and call ``on_result`` as in ``map``; raise :class:`TasksLostError` at the end
        for those whose process died again."""
        lost: dict[int, str] = {}
        pool = None
        try:
            for i in again:
                with self._lock:
                    if self._closed:
                        raise _closed(self)
                    pool, future = self._submit_alone(pool, fn, items[i])
                    procs = list((getattr(pool, "_processes", None) or {}).values())
                try:
                    out[i] = _result(future)
                except BrokenProcessPool:
                    if self._closed:
                        raise _closed(self) from None
                    lost[i] = (f"its worker process died ({_how_ended(procs=procs)}), "
                               "also when run again alone")
                    self._drop_alone(pool)
                    pool = None
                    continue
                if on_result:
                    on_result(i, out[i])
        except Exception:  # the task's own error, or the caller's (on_result): its
            # process is idle now; left to the executor's close, a server kept one idle
            # worker process each time this happened, until it stopped
            self._drop_alone(pool)
            raise
        # (a Ctrl-C leaves the pool to the executor's abort, or close, which ends its
        # process: shut down here, it ran on to the end)
        self._drop_alone(pool)
        if lost:
            raise TasksLostError(lost, out)
        return out

    def _drop_alone(self, pool: ProcessPoolExecutor | None) -> None:
        """Shut down a pool of :meth:`_again_alone` whose process runs no task now."""
        if pool is not None:
            with self._lock:
                self._alone.discard(pool)
            pool.shutdown(wait=False)

    def close(self) -> None:
        with self._lock:
            self._closed = True
            pools, self._pool = [self._pool, *self._alone], None
        for pool in pools:
            if pool is not None:
                pool.shutdown(wait=False, cancel_futures=True)

    def abort(self) -> None:
        """Close and end the worker processes now (SIGTERM): their running tasks stop
        where they are, their open transactions rolled back, rather than run to the end
        and store their results after the command reported the interrupt (the exit
        waited for them: 20 s after a Ctrl-C in a range of days with 2 jobs)."""
        self.aborted = True
        with self._lock:
            self._closed = True  # another thread's map ends in ExecutorClosedError
            pools, self._pool = [self._pool, *self._alone], None
        for pool in pools:
            if pool is not None:
                _end(pool)


def _end(pool: ProcessPoolExecutor) -> None:
    """Shut ``pool`` down, ending its worker processes now (SIGTERM)."""
    # (shutdown forgets both)
    procs = list((getattr(pool, "_processes", None) or {}).values())
    manager = getattr(pool, "_executor_manager_thread", None)
    pool.shutdown(wait=False, cancel_futures=True)
    # the pool's thread first drops the cancelled tasks: one still listed when the
    # workers end was set failed on top of cancelled, an InvalidStateError
    # traceback from that thread (Python 3.11)
    end = time.monotonic() + 2.0
    while (manager is not None and manager.is_alive()
           and getattr(pool, "_cancel_pending_futures", False)
           and time.monotonic() < end):
        time.sleep(0.005)
    for proc in procs:
        proc.terminate()
    if manager is not None:  # it sees them end and closes its pipes: wait for that,
        manager.join(timeout=5.0)  # or the exit's wake-up call races the closing


def _new_pool(workers: int) -> ProcessPoolExecutor:
    return ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"),
                               initializer=_leave_sigint)


def _broke(pool: ProcessPoolExecutor, exc: BaseException) -> bool:
    """Whether ``exc``, raised by ``pool.submit``, says the pool broke: BrokenProcessPool,
    or the "cannot schedule new futures after shutdown" RuntimeError of a submit that
    looked before the pool's thread marked it broken and after it marked it shut down."""
    return isinstance(exc, BrokenProcessPool) or bool(getattr(pool, "_broken", False))


def _failed(exc: BaseException) -> Future:
    """A future failed with BrokenProcessPool, for a task its pool refused as broken."""
    future: Future = Future()
    future.set_exception(exc if isinstance(exc, BrokenProcessPool)
                         else BrokenProcessPool(str(exc)))
    return future


def _result(future):
    """``future.result()`` in short waits (see :data:`WAKE_EVERY`)."""
    while True:
        try:
            return future.result(timeout=WAKE_EVERY)
        except TimeoutError:
            continue
        except BaseException:
            if not future.done():  # Ctrl-C while it runs
                future.cancel()
            raise


def _exit_code(proc, wait: float = 2.0) -> int | None:
    """``proc``'s exit code, waiting up to ``wait`` s for it. The pool's own thread may
    be reaping the process at the same moment: our ``waitpid`` then finds no child and
    ``exitcode`` stays None for an instant after the process has ended, until that
    thread records the code (a dead worker read as "exit status unknown", or only its
    SIGTERMed neighbours seen: "killed by SIGTERM")."""
    deadline = time.monotonic() + wait
    while True:
        proc.join(timeout=0.05)
        if proc.exitcode is not None or time.monotonic() > deadline:
            return proc.exitcode
        time.sleep(0.01)


def _how_ended(pool: ProcessPoolExecutor | None = None, *, procs=None) -> str:
    """How a broken pool's worker died: "killed by SIGKILL", "exit code 3", or
    "exit status unknown". The pool ends its other workers with SIGTERM, so another
    signal or code names the one that died; ``procs``: the processes, when the pool has
    forgotten them."""
    if procs is None:
        procs = list((getattr(pool, "_processes", None) or {}).values())
    codes = []
    for proc in procs:
        try:
            codes.append(_exit_code(proc))
        except (ValueError, AssertionError, OSError):  # a closed Process object
            continue
    known = [c for c in codes if c is not None]
    code = next((c for c in known if c != -signal.SIGTERM), known[0] if known else None)
    if code is None:
        return "exit status unknown"
    if code < 0:
        try:
            name = signal.Signals(-code).name
        except ValueError:
            name = f"signal {-code}"
        return f"killed by {name}" + (", as the out-of-memory killer does"
                                      if code == -signal.SIGKILL else "")
    return f"exit code {code}"


@contextlib.contextmanager
def _sigint_blocked():
    """SIGINT blocked in this thread while the block runs: a pool's ``submit`` starts
    its worker processes, which inherit the mask, so a worker is deaf to Ctrl-C from
    its first instruction (and then ignores it, :func:`_leave_sigint`). A Ctrl-C in the
    second or so a spawned worker took to start Python and reach that initializer
    printed a KeyboardInterrupt traceback from multiprocessing's ``spawn_main`` (each
    worker one) over ``skyroute: interrupted``. This process still gets the signal:
    another thread takes it for the main one, or this thread once it is unblocked.

    multiprocessing's resource tracker is started first: the first spawn or semaphore
    of a process starts it, and that unblocks SIGINT in the thread that does
    (``resource_tracker.ensure_running`` blocks it around the tracker's spawn, then
    unblocks it whatever it was): the in-process Dask cluster's event loop, inheriting
    this block, started its workers deaf to nothing."""
    from multiprocessing import resource_tracker

    resource_tracker.ensure_running()
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _leave_sigint() -> None:
    """A pool worker's start: ignore SIGINT. Ctrl-C in a terminal reaches every process
    of its group; each worker printed a KeyboardInterrupt traceback, and the command
    that owns the pool decides what its tasks become (:meth:`LocalExecutor.abort`)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


WAKE_EVERY = 0.1  # seconds: how soon a map waiting for its tasks sees Ctrl-C


def _gather(submit: Callable, items: list, window: int, on_result,
            on_broken: Callable[[int, Any], None]) -> list:
    """Results of ``submit(item)`` (a future) for every item, in item order, at most
    ``window`` of them submitted and not yet ended at a time; ``on_result`` as each
    ends, ``on_broken(index, future)`` for each whose pool broke (its result left ``None``). On
    an error or Ctrl-C the futures not yet started are cancelled (and the items not yet
    submitted never are)."""
    out: list = [None] * len(items)
    todo = iter(enumerate(items))
    pending: dict = {}  # future -> index

    def top_up() -> None:
        for i, item in itertools.islice(todo, window - len(pending)):
            pending[submit(item)] = i

    try:
        top_up()
        while pending:
            # in short waits: a signal taken by another thread (the pool's own) does not
            # wake a wait without a timeout, so Ctrl-C waited for the next task to end
            done, _ = wait(pending, timeout=WAKE_EVERY, return_when=FIRST_COMPLETED)
            for f in sorted(done, key=pending.get):
                i = pending.pop(f)
                try:
                    out[i] = f.result()
                except BrokenProcessPool:
                    on_broken(i, f)
                    continue
                if on_result:
                    on_result(i, out[i])
            top_up()
    except BaseException:
        for f in pending:
            f.cancel()
        raise
    return out


# what a worker runs to import the modules skyroute's tasks name (run by ``exec``, a
# builtin: a function of skyroute's own could not be sent to a worker that lacks it)
TASK_IMPORTS = "import skyroute.jobs.deliver, skyroute.jobs.fleet"


def _handshake(address: str) -> None:
    """Connect to ``address`` and read a Dask handshake within ``CONNECT_TIMEOUT``, else
    raise OSError. distributed bounds the TCP connection but not the handshake read
    after it: another server on the port (the dashboard's 8787, any HTTP server) kept
    ``Client`` waiting for ever when silent, and its answer, read as a frame length,
    was a MemoryError of exabytes. Run on a thread of its own, with its own event loop,
    as a server calls this from inside one. It connects as ``Client`` does, with the
    connection arguments of Dask's configuration (a ``tls://`` scheduler's certificates).
    """
    import asyncio
    from concurrent.futures import ThreadPoolExecutor

    from dask.utils import parse_timedelta
    from distributed.comm import connect
    from distributed.security import Security

    timeout = parse_timedelta(CONNECT_TIMEOUT, default="seconds")
    bound = timeout + 2  # connect() ends an unanswered connection at timeout, its way
    args = Security().get_connection_args("client")  # Client's own, from the config

    async def shake():
        try:
            comm = await asyncio.wait_for(connect(address, timeout=timeout, **args), bound)
        except TimeoutError:
            raise OSError(f"something at {address} took the connection but did not "
                          f"answer as a Dask scheduler within {bound:g} s") from None
        except (OSError, ValueError, TypeError):  # refused, timed out, malformed
            raise
        except Exception as exc:
            raise OSError(f"something at {address} answered, but not in Dask's "
                          f"protocol ({type(exc).__name__} reading it)") from None
        await comm.close()

    with ThreadPoolExecutor(1, thread_name_prefix="skyroute-dask-handshake") as pool:
        pool.submit(asyncio.run, shake()).result()


class DaskExecutor(_Executor):
    """Tasks on a Dask cluster: an existing scheduler, or an in-process ``LocalCluster``.

    ``client`` is the ``distributed.Client`` (tests use it to reach the workers).
    """

    kind = "dask"

    def __init__(self, *, address: str | None, workers: int | None) -> None:
        try:
            from distributed import Client, LocalCluster
        except ModuleNotFoundError:  # pragma: no cover - a dependency of skyroute
            raise SkyrouteError("the dask executor needs 'distributed' "
                                "(pip install 'dask[distributed]')") from None
        self.address = address
        self._cluster = None
        self._closed = False
        # A Client left to the garbage collector (one whose connection failed is left in
        # a reference cycle) closes itself in __del__, taking distributed's class-wide
        # LoopRunner lock; collected while a new Client starts under that lock, it
        # deadlocks the process (seen in the test suite). Finalise such leftovers now.
        gc.collect()
        if address is None:
            # SIGINT blocked while the cluster starts: its event loop's thread, and the
            # threads that thread starts, inherit the mask, and so do the worker
            # processes they spawn (as the local pool's, _sigint_blocked). A Ctrl-C in
            # the seconds a worker took to import distributed, before its preload
            # (local_worker) ignores SIGINT, printed its KeyboardInterrupt traceback,
            # "Nanny failed to start" and, at exit, distributed's close_clusters
            # AssertionError (Status.init). The Ctrl-C is taken once the cluster is up,
            # and closes it.
            try:
                with _sigint_blocked():
                    self._cluster = LocalCluster(
                        n_workers=workers or os.cpu_count() or 1, threads_per_worker=1,
                        processes=True, dashboard_address=None,
                        # its HTTP routes (no dashboard) on a free port: at distributed's
                        # default (8787), a second cluster or any server there made a
                        # "Port 8787 is already in use" warning
                        scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                        silence_logs=logging.ERROR, preload=["skyroute.jobs.local_worker"])
                    self.client = Client(self._cluster)
            except BaseException:
                if hasattr(self, "client"):  # up, when a signal held meanwhile was taken
                    self.close()
                raise
        else:
            if not isinstance(address, str):
                raise OptionError(f"address={address!r} must be a scheduler address like "
                                  "tcp://HOST:8786", param="address")
            try:
                _handshake(address)
                self.client = Client(address, timeout=CONNECT_TIMEOUT)
            except (OSError, ValueError, TypeError) as exc:
                reason = " ".join(str(exc).split()) or type(exc).__name__
                raise SkyrouteError(f"address={address!r}: no Dask scheduler there "
                                    f"({reason}); expected tcp://HOST:8786",
                                    param="address") from None
            try:
                self._check_versions()
                self._check_imports()
            except BaseException:
                self.client.close()
                raise

    def _check_versions(self) -> None:
        """The scheduler and every worker must have this skyroute: the tasks name its
        functions, and a worker that cannot import them dies reading the task."""
        from importlib.metadata import PackageNotFoundError, version

        try:
            mine = version("skyroute")
        except PackageNotFoundError:  # running from a source tree: nothing to compare
            return
        v = self.client.get_versions(packages=["skyroute"])
        where = [("the scheduler", v["scheduler"]["packages"].get("skyroute"))]
        where += [(f"worker {w}", info["packages"].get("skyroute"))
                  for w, info in sorted(v["workers"].items())]
        for name, theirs in where:
            if theirs != mine:
                raise SkyrouteError(
                    f"address={self.address!r}: {name} has skyroute "
                    f"{theirs or '(not installed)'}, this machine {mine}; install the same "
                    "skyroute on the scheduler and every worker", param="address")

    def _check_imports(self) -> None:
        """Every worker must import skyroute's tasks. One whose skyroute is installed
        (the versions agree) but does not import (a dependency missing or broken on its
        machine) closes itself on its first task, reading it; with no other worker the
        run waited forever. Importing them now also spares the first tasks the time."""
        got = self.client.run(exec, TASK_IMPORTS, on_error="return")
        for worker, r in sorted(got.items()):
            if isinstance(r, BaseException):
                why = " ".join(str(r).split()) or "no message"
                raise SkyrouteError(
                    f"address={self.address!r}: worker {worker} cannot import skyroute's "
                    f"tasks ({type(r).__name__}: {why}); install the same skyroute, with "
                    "its dependencies, on the scheduler and every worker", param="address")

    def __repr__(self) -> str:
        where = self.address or "LocalCluster"
        return f"DaskExecutor({where}, workers={self.workers})"

    @property
    def workers(self) -> int:
        """Workers the scheduler knows now."""
        return len(self.client.scheduler_info(n_workers=-1)["workers"])

    def map(self, fn, items, *, on_result=None) -> list:
        from distributed import KilledWorker, as_completed

        items = list(items)
        if self._closed:
            raise _closed(self)
        if not items:
            return []
        if self.address is not None and not self.workers:
            # (a scheduler started before its workers, or whose workers all left): the
            # tasks wait for one, which Dask does without a word: the run looked hung
            log.warning("the Dask scheduler at %s has no workers; the tasks wait until "
                        "one joins", self.address)
        # pure=False: a task is run each time it is asked for, never served from an
        # earlier identical call (the tasks write to the store)
        futures = self.client.map(fn, items, pure=False)
        index = {f.key: i for i, f in enumerate(futures)}
        out: list = [None] * len(items)
        lost: dict[int, str] = {}
        try:
            for f in as_completed(futures):
                i = index[f.key]
                # let go of each task once its result is here: held to the map's end,
                # every result stayed in its worker's memory, and a worker that died
                # had all the tasks it had finished run again (a long range of days
                # flown twice over, while the map waited for its last ones)
                futures[i] = None
                try:
                    out[i] = f.result()
                except KilledWorker as exc:  # the others run on
                    tries = exc.allowed_failures + 1
                    lost[i] = ("its Dask worker died running it" if tries == 1 else
                               f"its Dask worker died running it, on each of the {tries} "
                               "workers that tried it") + " (KilledWorker; see the workers' logs)"
                    continue
                finally:
                    with contextlib.suppress(RuntimeError):  # a client closed meanwhile
                        f.release()
                if on_result:
                    on_result(i, out[i])
        except Exception as exc:
            if self._closed:  # the client closed under this map: nothing left to cancel
                raise _closed(self) from None
            self.client.cancel([f for f in futures if f is not None])
            if not isinstance(exc, RuntimeError) or "deserializ" not in str(exc):
                raise
            raise SkyrouteError(f"the Dask scheduler at {self.client.scheduler.address} "
                                "cannot read skyroute's tasks; install the same skyroute on "
                                "the scheduler and every worker") from None
        except BaseException:
            if not self._closed:
                self.client.cancel([f for f in futures if f is not None])
            raise
        finally:
            del futures
        if lost:
            raise TasksLostError(lost, out)
        return out

    def close(self) -> None:
        self._closed = True
        self.client.close()
        if self._cluster is not None:
            self._cluster.close()
