"""Long jobs in the background, their state in the store: what the service calls.

``submit(engine, kind, params, executor=ex)`` checks ``params`` (an
:class:`~skyroute.errors.OptionError` naming the field when one is wrong), records the job
as ``queued`` and returns its id at once (``submit_once`` returns the id of a job of the
same kind and parameters already queued or running instead, and says which it did);
``get(engine, job_id)`` reads it back as ``{"id", "kind", "params", "state", "progress",
"result", "error", "created", "updated", "owner"}`` (None for an unknown id).

Kinds (:data:`KINDS`) and their parameters:

- ``deliver``: ``{"date": D}`` or ``{"from": D, "to": D}``, ``data`` (folder) or
  ``source`` (URL) naming the site, ``method``; orders already in the store
  (:func:`skyroute.jobs.deliver.check_params`). Result: the range's summary.
- ``fleet``: ``preset`` or ``scenario``, ``hours``, ``seed``, ``scheduler``,
  ``airspace``, ``rate_per_hour``, ``track_step``
  (:func:`skyroute.jobs.fleet.check_fleet_params`). Result: ``{"fleet_run": id,
  "report"}``; the run's files are in ``fleet_runs`` (:func:`skyroute.jobs.store.get_fleet_run`).
- ``sweep``: ``preset`` or ``scenario``, ``schedulers``, ``airspaces``, ``rates``,
  ``seeds``, ``hours`` (:func:`skyroute.jobs.fleet.check_sweep_params`). Result:
  ``{"rows": [...]}``. A sweep some of whose runs were lost (their worker process died
  each time they were tried) ends ``failed`` naming them, with the result
  ``{"rows": [...], "lost": [...]}``: the rows over the runs that finished and one entry
  per lost run (:class:`~skyroute.jobs.fleet.RunsLostError`).

Jobs run in two lanes per process, each a background thread running its jobs one at a
time in the order submitted: deliveries in one, fleet runs and sweeps in the other
(:data:`KINDS`' ``lane``). Each job spreads its tasks over the executor's workers, and
the two lanes share them (a local ``map`` keeps at most twice its workers' tasks in the
pool), so a delivery job does not wait behind a long fleet run or sweep, nor a fleet
run behind a long range of days; a job waiting for one of its lane before it stays
``queued``. Fleet runs and sweeps share a lane because both fly the compiled Dubins
kernels, whose threading layer may not take two threads at once when a job's tasks run
in this process (one worker). While a job runs it is ``running`` with its
progress, the share of its tasks done (a fleet run is one task: 0, then 1). It ends
``done`` with its result, or ``failed`` with a one-line error: a SkyrouteError's message,
else the exception's type and message; the ``skyroute.jobs`` logger gets the first at
INFO, the traceback of any other at ERROR, never the store. The thread is a daemon: a job
still queued or running when the process ends is left so in the store, and is failed
later as an orphan. A job whose executor is closed under it (the server shutting down
while another lane's job runs: :class:`~skyroute.jobs.executor.ExecutorClosedError`),
and a queued one that reaches a closed executor, ends ``failed`` with the orphans'
:data:`ORPHANED` at once.

Several servers (and each server's ``--workers`` processes) may share one store. Each
job names its owner, the process that took it (:func:`owner`: host, process id and a
random part). While a process has jobs queued or running it beats every
:data:`HEARTBEAT_EVERY` seconds in the store's ``servers`` table and fails the orphans
there (:func:`heartbeat`); :func:`fail_orphans` (also called by ``skyroute serve``
before its workers start, and by :func:`get` on another owner's unfinished job) marks
``failed`` with :data:`ORPHANED` the unfinished jobs whose owner has been silent for
:data:`DEAD_AFTER` seconds, or that have no owner (jobs stored before owners were), and
leaves the live servers' jobs alone. An owner that shares this process's view of
process ids (the same boot, the same PID namespace: a server restarted on the same
machine or in the same container) and has ended is seen so at once (:func:`gone`: its
process id free, or another process's), so a restarted server fails its predecessor's
jobs at start, not a minute later; owners elsewhere keep the heartbeat rule. A process stalled
for longer than that (or cut off from the store) has its jobs marked failed, and they
stay failed: a job failed while queued is not run, one failed while running is stopped
at its next progress write, and a result or error that comes after all is discarded
(logged as a warning on ``skyroute.jobs``), as is the fleet run a late fleet job's
worker would store (:func:`skyroute.jobs.store.save_fleet_run`).
"""

from __future__ import annotations

import hashlib
import logging
import math
import os
import queue
import re
import socket
import threading
import time
import uuid
from collections.abc import Callable
from pathlib import Path
from typing import NamedTuple

import sqlalchemy as sa

from skyroute.errors import SkyrouteError, check_choice
from skyroute.jobs import deliver, fleet, store
from skyroute.jobs.executor import ExecutorClosedError

log = logging.getLogger("skyroute.jobs")
PROGRESS_EVERY = 0.2  # seconds between progress writes (the last one always goes)


class Kind(NamedTuple):
    check: Callable[[dict], dict]
    run: Callable[..., dict]
    lane: str | None = None  # the jobs it takes turns with (None: those of its kind)


KINDS = {
    "deliver": Kind(deliver.check_params, deliver.deliver_job),
    "fleet": Kind(fleet.check_fleet_params, fleet.fleet_job, "fleet"),
    "sweep": Kind(fleet.check_sweep_params, fleet.sweep_job, "fleet"),
}

ORPHANED = "the server stopped while this job ran; submit it again"
HEARTBEAT_EVERY = 10.0  # seconds between a process's heartbeats while it has jobs
DEAD_AFTER = 60.0  # seconds without a heartbeat after which an owner is dead

_lock = threading.Lock()
_lanes: dict[str, tuple[queue.Queue, threading.Thread]] = {}  # lane -> its jobs, thread
_beater: threading.Thread | None = None
_pending = 0
_stores: dict[str, list] = {}  # URL -> [engine, this process's unfinished jobs there]
_owner: tuple[int, str] | None = None  # (pid, id)
_space_id: str | None = None  # _space(): "" where there is none
_reaped: dict[str, float] = {}  # URL -> when get() last failed orphans there (monotonic)


def owner() -> str:
    """This process's owner id, ``HOST:PID:RANDOM``, then ``:SPACE:START`` where the
    process can be seen (:func:`_space`, :func:`_started`); made once per process. The
    random part tells apart processes that reuse a host name and process id; ``SPACE``
    and ``START`` let another process that sees the same process ids tell at once that
    this one has ended (:func:`gone`)."""
    global _owner
    pid = os.getpid()
    if _owner is None or _owner[0] != pid:
        me = f"{socket.gethostname()[:40]}:{pid}:{uuid.uuid4().hex[:12]}"
        space, start = _space(), _started(pid)
        if space is not None and start is not None:
            me += f":{space}:{start[1]}"
        _owner = (pid, me)
    return _owner[1]


def gone(owner_id: str | None) -> bool:
    """True when ``owner_id`` names a process that has certainly ended: one that shares
    this process's view of process ids (the same boot of the same kernel, the same PID
    namespace, so not another container with the same host name) and whose process id is
    free now, held by a zombie, or held by a process started at another time (the id
    reused). False when that cannot be told (another machine or container, an owner id
    without ``SPACE:START``, no ``/proc``): the heartbeat rule decides those."""
    if not isinstance(owner_id, str):  # a job stored before owners were
        return False
    parts = owner_id.rsplit(":", 4)
    if len(parts) != 5 or not parts[1].isdigit() or not parts[4].isdigit():
        return False
    pid = int(parts[1])
    if pid <= 0 or owner_id == owner() or parts[3] != _space():
        return False
    try:
        os.kill(pid, 0)  # signal 0: only asks whether the process exists
    except ProcessLookupError:
        return True
    except OSError:  # another user's process (EPERM): it exists
        pass
    now = _started(pid)
    return now is not None and (now[0] in "ZX" or now[1] != parts[4])


def _space() -> str | None:
    """A short hash of this boot of the kernel and this process's PID namespace: the
    processes that share it see the same process ids. None where ``/proc`` does not say
    (not Linux), or names another namespace's processes (its ``self`` is not this
    process)."""
    global _space_id
    if _space_id is None:
        try:
            boot = Path("/proc/sys/kernel/random/boot_id").read_text().strip()
            ns = os.readlink("/proc/self/ns/pid")
            ours = Path("/proc/self/stat").read_text().split(" ", 1)[0] == str(os.getpid())
        except OSError:
            ours = False
        _space_id = (hashlib.sha256(f"{boot}|{ns}".encode()).hexdigest()[:12] if ours
                     else "")
    return _space_id or None


def _started(pid: int) -> tuple[str, str] | None:
    """(state, start time in clock ticks after boot) of process ``pid`` from
    ``/proc/PID/stat``; None where it cannot be read."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    fields = stat[stat.rfind(")") + 2:].split()  # after "pid (command) "
    return (fields[0], fields[19]) if len(fields) > 19 else None


def submit(engine: sa.Engine, kind: str, params: dict, *, executor) -> str:
    """Check ``params``, record the job (``queued``) and queue it to run on
    ``executor`` (an open :func:`~skyroute.jobs.executor.open_executor`, which the
    caller keeps open and closes); the job's id."""
    return _submit(engine, kind, params, executor=executor, once=False)[0]


def submit_once(engine: sa.Engine, kind: str, params: dict, *,
                executor) -> tuple[str, bool]:
    """As :func:`submit`, ``(id, True)``; but when a job of ``kind`` with the same
    checked ``params`` is already queued or running on this store (this process's or
    another server's), ``(its id, False)``, and nothing is recorded or queued. The
    orphans are failed first (:func:`fail_orphans`), so a stopped server's job is not
    taken for a live one. The look and the record are one transaction
    (:func:`skyroute.jobs.store.create_job_once`)."""
    return _submit(engine, kind, params, executor=executor, once=True)


def live_twin(engine: sa.Engine, kind: str, params: dict) -> str | None:
    """The id of the job :func:`submit_once` would answer with instead of a new one (a
    job of ``kind`` with the same checked ``params`` queued or running on this store, the
    orphans failed first), or None; nothing is recorded. ``params`` are checked as
    :func:`submit` checks them."""
    check_choice("kind", kind, tuple(KINDS))
    params = KINDS[kind].check(params)
    fail_orphans(engine)
    return store.live_job(engine, kind, params)


def _submit(engine: sa.Engine, kind: str, params: dict, *, executor,
            once: bool) -> tuple[str, bool]:
    global _beater, _pending
    check_choice("kind", kind, tuple(KINDS))
    params = KINDS[kind].check(params)
    me = owner()
    store.beat(engine, me)  # alive before its job exists: no one fails it as an orphan
    if once:
        fail_orphans(engine)
    job_id, new = store.create_job_once(engine, kind, params, owner=me, once=once)
    if not new:
        return job_id, False
    with _lock:
        _pending += 1
        _stores.setdefault(str(engine.url), [engine, 0])[1] += 1
        lane = KINDS[kind].lane or kind
        jobs, thread = _lanes.get(lane) or (queue.Queue(), None)
        jobs.put((engine, job_id, kind, params, executor))
        if thread is None or not thread.is_alive():
            thread = threading.Thread(target=_work, args=(jobs,), daemon=True,
                                      name=f"skyroute-jobs-{lane}")
            _lanes[lane] = (jobs, thread)
            thread.start()
        if _beater is None or not _beater.is_alive():
            _beater = threading.Thread(target=_beat_forever, name="skyroute-jobs-beat",
                                       daemon=True)
            _beater.start()
    return job_id, True


def fail_orphans(engine: sa.Engine) -> list[str]:
    """Mark ``failed`` (:data:`ORPHANED`) the jobs left ``queued`` or ``running`` by
    servers that stopped: owners silent for :data:`DEAD_AFTER` seconds, or none; their
    ids. A job runs only in the process that took it, so none of these will ever end.
    ``skyroute serve`` calls it at start; :func:`heartbeat` while jobs run."""
    ended = [o for o in store.live_owners(engine) if gone(o)]
    return store.fail_orphans(engine, ORPHANED, dead_after=DEAD_AFTER, gone=ended)


def heartbeat() -> None:
    """For each store where this process has jobs queued or running: beat, then fail
    the orphans. The beat thread calls it every :data:`HEARTBEAT_EVERY` seconds; a store
    that cannot be reached is logged and tried again next time."""
    with _lock:
        engines = [e for e, _ in _stores.values()]
    for engine in engines:
        try:
            store.beat(engine, owner())
            failed = fail_orphans(engine)
        except Exception:
            log.warning("heartbeat to %s failed", engine.url, exc_info=True)
            continue
        if failed:
            log.warning("%d orphaned job(s) marked failed: %s", len(failed),
                        ", ".join(failed))


def get(engine: sa.Engine, job_id: str) -> dict | None:
    """The job as :func:`skyroute.jobs.store.get_job` gives it; None for an unknown id.
    Another owner's unfinished job is first checked for orphans (:func:`fail_orphans`,
    at most once per :data:`HEARTBEAT_EVERY` seconds per store), so a job whose server
    died is seen failed even where no server has jobs left to beat for. An error stored
    by an older skyroute, which quoted the SQL of a database error, is cut before it."""
    job = store.get_job(engine, job_id)
    if job is not None and job["error"]:
        job["error"] = SQL_QUOTES.split(job["error"])[0]  # stored before database_error
    if job is None or job["state"] not in ("queued", "running") or job["owner"] == owner():
        return job
    url, now = str(engine.url), time.monotonic()
    with _lock:
        due = now - _reaped.get(url, -math.inf) >= HEARTBEAT_EVERY
        if due:
            _reaped[url] = now
    if (due or gone(job["owner"])) and job_id in fail_orphans(engine):
        job = store.get_job(engine, job_id)
    return job


def pending() -> int:
    """Jobs submitted in this process and not finished yet (queued or running)."""
    return _pending


def wait(engine: sa.Engine, job_id: str, *, timeout: float | None = None,
         every: float = 0.05) -> dict:
    """Poll until the job is ``done`` or ``failed`` (or ``timeout`` seconds pass); the
    job as :func:`get` gives it."""
    end = None if timeout is None else time.monotonic() + timeout
    while True:
        job = get(engine, job_id)
        if job is None:
            raise SkyrouteError(f"job_id={job_id!r}: no such job", param="job_id")
        if job["state"] in ("done", "failed") or (end is not None and time.monotonic() > end):
            return job
        time.sleep(every)


def error_line(exc: BaseException) -> str:
    """One line for the store: a SkyrouteError's message, a database error's
    (:func:`database_error`), else type and message."""
    if isinstance(exc, SkyrouteError):
        text = str(exc)
    elif isinstance(exc, sa.exc.StatementError):
        text = database_error(exc)
    else:
        text = f"{type(exc).__name__}: {exc}"
    return " ".join(text.split()) or type(exc).__name__


SQL_VERBS = ("SELECT", "INSERT", "UPDATE", "DELETE")
# where SQLAlchemy's text of an error, made one line, goes on to quote the row
# (PostgreSQL's DETAIL) and the SQL with its parameters
SQL_QUOTES = re.compile(r" (?:DETAIL: |\[SQL: )")


def database_error(exc: sa.exc.StatementError) -> str:
    """What failed in the store, without the statement: SQLAlchemy's text of the error
    holds the SQL and its parameters (the rows being written: order numbers,
    customers' places; a run's scenario), which the job's stored error showed to every
    holder of the token; the traceback in the log keeps them. The kind of statement and
    the first line of the database's own reason (PostgreSQL's further lines, DETAIL,
    quote the row).

    >>> exc = sa.exc.IntegrityError("INSERT INTO t (a) VALUES (?)", ("x",),
    ...                             Exception("UNIQUE constraint failed: t.a"))
    >>> database_error(exc)
    'IntegrityError: the store could not run an INSERT: UNIQUE constraint failed: t.a'
    """
    reason = exc.orig if exc.orig is not None else exc
    lines = str(reason).strip().splitlines()
    words = (exc.statement or "").split(maxsplit=1)
    verb = words[0].upper() if words and words[0].upper() in SQL_VERBS else None
    what = f"{'an' if verb in ('INSERT', 'UPDATE') else 'a'} {verb}" if verb else \
        "a statement"
    return (f"{type(exc).__name__}: the store could not run {what}: "
            f"{lines[0] if lines else type(reason).__name__}")


def _work(jobs: queue.Queue) -> None:
    global _pending
    while True:
        engine, job_id, kind, params, executor = jobs.get()
        try:
            _run(engine, job_id, kind, params, executor)
        except Exception:  # the store itself failed: keep serving the queue
            log.exception("job %s: could not record its state", job_id)
        finally:
            with _lock:
                _pending -= 1
                held = _stores[str(engine.url)]
                held[1] -= 1
                if held[1] == 0:  # nothing of ours left there: stop beating to it
                    del _stores[str(engine.url)]


def _beat_forever() -> None:
    while True:
        time.sleep(HEARTBEAT_EVERY)
        heartbeat()


def _run(engine, job_id: str, kind: str, params: dict, executor) -> None:
    if not store.set_progress(engine, job_id, 0.0):
        _ended(engine, job_id, "it is not run")
        return
    last = time.monotonic()

    def progress(share: float) -> None:
        nonlocal last
        now = time.monotonic()
        if share >= 1.0 or now - last >= PROGRESS_EVERY:
            if not store.set_progress(engine, job_id, min(1.0, max(0.0, share))):
                raise store.JobEndedError(f"job {job_id} ended while it ran")
            last = now

    try:
        result = KINDS[kind].run(engine, job_id, params, executor=executor,
                                 progress=progress)
    except store.JobEndedError:  # from progress, or from a worker storing a fleet run
        _ended(engine, job_id, "it is stopped")
        return
    except ExecutorClosedError:  # the server shutting down closed the executor under it
        log.info("job %s (%s) cut off by the executor's close", job_id, kind)
        if not store.fail_job(engine, job_id, ORPHANED):  # as its orphans are failed
            _ended(engine, job_id, "its cut-off is not recorded")
        return
    except Exception as exc:
        if getattr(executor, "aborted", False):  # the server is stopping, its workers
            # ended (a local pool's abort is ExecutorClosedError, above; this is another
            # executor's error): the job stays running in the store, failed as an orphan
            # later
            log.info("job %s (%s) stopped with the server", job_id, kind)
            return
        if isinstance(exc, SkyrouteError):  # the job's input: its reason, no traceback
            log.info("job %s (%s) failed: %s", job_id, kind, error_line(exc))
        else:
            log.error("job %s (%s) failed", job_id, kind, exc_info=True)
        kept = getattr(exc, "job_result", None)  # what it finished (a sweep's rows)
        if not store.fail_job(engine, job_id, error_line(exc),
                              result=kept() if callable(kept) else None):
            _ended(engine, job_id, "its error is discarded")
        return
    if not store.finish_job(engine, job_id, result):
        _ended(engine, job_id, "its result is discarded")


def _ended(engine, job_id: str, what: str) -> None:
    """Log that this process's job was found ended (failed as an orphan while this
    process was stalled or cut off from the store) and what becomes of it."""
    job = store.get_job(engine, job_id)
    state = "gone" if job is None else job["state"]
    log.warning("job %s is already %s (%s); %s", job_id, state,
                (job or {}).get("error") or "no error", what)
