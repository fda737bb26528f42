"""Jobs and fleet runs in the SQL store of the delivery days (same database, same
migrations: revision 0002 adds the jobs and fleet_runs tables, 0003 the jobs' owners and
the servers, 0004 moves the runs' files to fleet_run_files, 0005 splits them in parts,
0006 counts each part's lines; ``skyroute db init`` upgrades to the newest).

- ``jobs(id, kind, params, state, progress, result, error, created, updated, owner)``:
  ``state`` is ``queued``, ``running``, ``done`` or ``failed``; ``progress`` 0..1;
  ``params`` and ``result`` JSON; ``error`` one line. Times are UTC. ``owner`` is the id
  of the server process that runs the job (None for jobs stored before revision 0003).
  A job only moves queued -> running -> done or failed (queued -> failed too): each
  write checks, in its own statement, that the job is still queued or running, and a
  job done or failed is never written again (:func:`finish_job` and :func:`fail_job`
  say whether they wrote). An owner never changes, so the state alone tells whether
  a result is still wanted.
- ``servers(id, started, heartbeat)``: the server processes that own jobs, each beating
  (:func:`beat`) while it has jobs to run; times from the database's clock, so servers
  on hosts whose clocks differ agree on who is silent. :func:`fail_orphans` fails the
  unfinished jobs of owners silent for longer than ``dead_after``, or known to have
  ended (``gone``: the runner tells those of its own machine by their process ids).
- ``fleet_runs(id, job_id, scenario, params, report, created)``: a fleet run's
  ``report.json`` and what made it; ``fleet_run_files(run_id, name, part, data, lines)``
  its files in parts of at most :data:`PART_BYTES`, one row each (``name`` one of
  :data:`FILES`; ``part`` 0, 1, ...; ``data`` the part's bytes, text as UTF-8; an empty
  file is one empty part; ``lines`` the lines that end in the part, :func:`part_lines`,
  NULL in the files but events.jsonl of runs stored before 0006): ``events.jsonl``,
  ``tracks.csv``, ``packages.csv`` and ``fleet.geojson`` as :mod:`skyroute.io.fleet_out`
  writes them (a big run's tracks are big: 1 s rows of 1000 drones for an hour are
  about 150 MB; use a coarser ``track_step``). The files live apart so that listing
  runs or reading one file never reads through the tracks (SQLite keeps a row's columns
  in order), and in parts so that :func:`open_fleet_file` streams one part per read (a
  slice of one big value costs a read of the value up to the slice on both databases)
  and pages a file's lines from the parts they lie in (:meth:`StoredFile.lines`; the
  counts are read from an index of their own). No run names a failed job:
  failing a job deletes its runs in the same transaction, and :func:`save_fleet_run`
  refuses (:class:`JobEndedError`) a run of a job already failed.

Every function takes the engine first and runs one short transaction; writes go through
:func:`skyroute.delivery.store.writing`, as the delivery store's do (on SQLite the write
lock is taken first and a lock held past the busy timeout is one line, "the store is
busy"). Lookups of an unknown id return None.
"""

from __future__ import annotations

import datetime as dt
import hashlib
import math
import uuid
from collections.abc import Collection, Iterator
from pathlib import Path

import sqlalchemy as sa

from skyroute.caches import register
from skyroute.delivery.store import connect, tables, writing
from skyroute.errors import OptionError, SkyrouteError, check_choice

STATES = ("queued", "running", "done", "failed")
LIVE = ("queued", "running")  # the states a job may still leave
# the PostgreSQL advisory lock :func:`create_job_once` holds while it looks for a twin
JOBS_LOCK = 0x736B796A  # "skyj"
TABLES = ("jobs", "fleet_runs", "servers", "fleet_run_files")


_ENGINES: dict[str, sa.Engine] = {}
register(_ENGINES.clear)


class JobEndedError(SkyrouteError):
    """A write for a job that has already ended (failed, say as an orphan of a stalled
    server): nothing was written."""


class RunChangedError(SkyrouteError):
    """A fleet run replaced (saved again under its id) or deleted while one of its files
    was streamed: the rest of the file is not sent."""


def worker_url(engine: sa.Engine) -> str:
    """The URL a worker connects with: the engine's, password included (it goes to the
    workers, never into a job's params), a relative SQLite path made absolute."""
    url = engine.url
    if url.drivername.startswith("sqlite") and url.database not in (None, "", ":memory:"):
        url = url.set(database=str(Path(url.database).resolve()))
    return url.render_as_string(hide_password=False)


def engine_for(url: str) -> sa.Engine:
    """One engine per URL in this process (a worker keeps its own across tasks).

    A SQLite store (:func:`worker_url`: an absolute path on the server's machine) that
    is not there is refused, and nothing is made: a Dask worker on another machine made
    an empty file (and its folders) at that path and failed the fleet job with "no
    skyroute tables; run 'skyroute db init' first", of a store that has them."""
    if url not in _ENGINES:
        parsed = sa.engine.make_url(url)
        db = parsed.database
        if (parsed.drivername.startswith("sqlite") and db not in (None, "", ":memory:")
                and not Path(db).is_file()):
            import socket

            raise SkyrouteError(
                f"the SQLite store {db} is not on this worker's machine "
                f"({socket.gethostname()}); a fleet job's worker stores its run, so on a "
                "cluster of several machines the store must be a database every worker "
                "reaches (PostgreSQL)", param="url")
        _ENGINES[url] = connect(url)
    return _ENGINES[url]


def _t(engine: sa.Engine) -> dict[str, sa.Table]:
    return tables(engine, TABLES)


def _now() -> dt.datetime:
    return dt.datetime.now(dt.UTC).replace(tzinfo=None)


def _iso(t: dt.datetime | None) -> str | None:
    return None if t is None else t.replace(tzinfo=dt.UTC).isoformat()


def json_safe(value):
    """``value`` with NaN and infinities as None (JSON has neither; PostgreSQL refuses
    them), tuples as lists; raises OptionError on what JSON cannot hold."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {str(k): json_safe(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [json_safe(v) for v in value]
    if value is None or isinstance(value, str | int | bool):
        return value
    if hasattr(value, "item"):  # numpy scalars
        return json_safe(value.item())
    raise OptionError(f"{type(value).__name__} {value!r} cannot be stored as JSON")


def create_job(engine: sa.Engine, kind: str, params: dict, *,
               owner: str | None = None) -> str:
    """Record a new job (``queued``, progress 0) run by the server ``owner`` (which
    :func:`beat` first); its id (a UUID string)."""
    return create_job_once(engine, kind, params, owner=owner, once=False)[0]


def create_job_once(engine: sa.Engine, kind: str, params: dict, *,
                    owner: str | None = None, once: bool = True) -> tuple[str, bool]:
    """``(id, True)`` for a new job as :func:`create_job` records it; with ``once``, when
    a job of ``kind`` with the same ``params`` is queued or running (any owner's; fail
    the orphans first), ``(its id, False)`` instead and nothing is written. The look and
    the insert are one transaction holding the write lock (SQLite) or the advisory lock
    :data:`JOBS_LOCK` (PostgreSQL): two servers on one store submitting the same job at
    once record it once."""
    jobs = _t(engine)["jobs"]
    stored = json_safe(params)
    job_id = str(uuid.uuid4())
    now = _now()
    with writing(engine) as c:
        if once:
            if c.dialect.name == "postgresql":
                c.execute(sa.select(sa.func.pg_advisory_xact_lock(JOBS_LOCK)))
            twin = _twin(c, jobs, kind, stored)
            if twin is not None:
                return twin, False
        c.execute(jobs.insert().values(
            id=job_id, kind=kind, params=stored, state="queued", progress=0.0,
            created=now, updated=now, owner=owner))
    return job_id, True


def live_job(engine: sa.Engine, kind: str, params: dict) -> str | None:
    """The id of the oldest job of ``kind`` with these ``params`` still queued or
    running (any owner's), or None."""
    jobs = _t(engine)["jobs"]
    with engine.connect() as c:
        return _twin(c, jobs, kind, json_safe(params))


def _twin(c: sa.Connection, jobs: sa.Table, kind: str, stored) -> str | None:
    # few jobs are live at once (each server holds at most its queue's): the JSON
    # parameters are compared here, the same on both databases
    live = c.execute(sa.select(jobs.c.id, jobs.c.params)
                     .where(jobs.c.kind == kind, jobs.c.state.in_(LIVE))
                     .order_by(jobs.c.created, jobs.c.id)).all()
    return next((str(i) for i, p in live if p == stored), None)


def set_progress(engine: sa.Engine, job_id: str, progress: float) -> bool:
    """Mark the job ``running`` at ``progress`` (0..1); False (and nothing written) when
    it is no longer queued or running."""
    p = float(progress)
    if not 0.0 <= p <= 1.0:
        raise OptionError(f"progress={progress!r} must be within 0..1", param="progress")
    return _move(engine, job_id, state="running", progress=p)


def finish_job(engine: sa.Engine, job_id: str, result: dict | None) -> bool:
    """Mark the job ``done`` (progress 1) with its JSON ``result``; False (and nothing
    written) when it is no longer queued or running: a late result, say of a server
    that stalled until its job was failed as an orphan, leaves that job failed."""
    return _move(engine, job_id, state="done", progress=1.0, result=json_safe(result),
                 error=None)


def fail_job(engine: sa.Engine, job_id: str, error: str, *,
             result: dict | None = None) -> bool:
    """Mark the job ``failed`` with ``error`` (made one line; no traceback belongs here)
    and delete its fleet runs; False (and nothing written) when it is no longer queued
    or running. ``result``: what the job did finish, kept as its JSON result (a sweep's
    rows when some runs were lost)."""
    line = " ".join(str(error).split()) or "failed"
    extra = {} if result is None else {"result": json_safe(result)}
    return _move(engine, job_id, state="failed", error=line, **extra)


def _move(engine: sa.Engine, job_id: str, **values) -> bool:
    """Write ``values`` to the job if it is still queued or running, in one statement
    (the check and the write cannot be parted by another server's write); a job moved
    to ``failed`` loses its fleet runs in the same transaction. Whether it was written."""
    t = _t(engine)
    jobs = t["jobs"]
    with writing(engine) as c:
        moved = c.execute(jobs.update().where(jobs.c.id == job_id, jobs.c.state.in_(LIVE))
                          .values(**values, updated=_now())).rowcount == 1
        if moved and values["state"] == "failed":
            _drop_runs(c, t, [job_id])
    return moved


def _drop_runs(c: sa.Connection, t: dict[str, sa.Table], job_ids: list[str]) -> None:
    """Delete the fleet runs of ``job_ids``, jobs just marked failed: no run names a
    failed job (a run saved before its job failed goes with the failure)."""
    if job_ids:
        runs = t["fleet_runs"]
        _drop_files(c, t, sa.select(runs.c.id).where(runs.c.job_id.in_(job_ids)))
        c.execute(runs.delete().where(runs.c.job_id.in_(job_ids)))


def _drop_files(c: sa.Connection, t: dict[str, sa.Table], run_ids) -> None:
    """Delete the files of the runs ``run_ids`` (a list or a select of ids): SQLite does
    not enforce the foreign key's ON DELETE CASCADE unless asked per connection."""
    files = t["fleet_run_files"]
    c.execute(files.delete().where(files.c.run_id.in_(run_ids)))


def db_now(conn: sa.Connection) -> dt.datetime:
    """The database's clock, UTC without a time zone (as the store keeps times)."""
    now = conn.execute(sa.select(sa.func.current_timestamp())).scalar_one()
    if isinstance(now, str):  # a driver that leaves SQLite's text as it is
        now = dt.datetime.fromisoformat(now)
    if now.tzinfo is not None:
        now = now.astimezone(dt.UTC).replace(tzinfo=None)
    return now


def beat(engine: sa.Engine, server: str) -> None:
    """Record that the server process ``server`` is alive now (by the database's
    clock), adding it to ``servers`` the first time (or again after
    :func:`fail_orphans` removed it as silent)."""
    servers = _t(engine)["servers"]
    with writing(engine) as c:
        now = db_now(c)
        if not c.execute(servers.update().where(servers.c.id == server)
                         .values(heartbeat=now)).rowcount:
            c.execute(servers.insert().values(id=server, started=now, heartbeat=now))


def live_owners(engine: sa.Engine) -> list[str]:
    """The owners of the jobs still ``queued`` or ``running`` (each once, none for the
    jobs without an owner)."""
    jobs = _t(engine)["jobs"]
    with engine.connect() as c:
        return list(c.scalars(sa.select(jobs.c.owner).distinct()
                              .where(jobs.c.state.in_(LIVE), jobs.c.owner.is_not(None))))


def fail_orphans(engine: sa.Engine, error: str, *, dead_after: float,
                 gone: Collection[str] = ()) -> list[str]:
    """Mark ``failed`` with ``error`` every ``queued`` or ``running`` job whose owner
    has not beaten for ``dead_after`` seconds, is one of ``gone`` (owners the caller
    knows have ended, however recent their heartbeat) or is None; delete their fleet
    runs and forget those servers; the ids of the jobs it failed. The live servers' jobs
    are left as they are."""
    if not dead_after > 0:
        raise OptionError(f"dead_after={dead_after!r} must be a number of seconds > 0",
                          param="dead_after")
    gone = list(gone)
    t = _t(engine)
    jobs, servers = t["jobs"], t["servers"]
    with writing(engine) as c:
        cutoff = db_now(c) - dt.timedelta(seconds=dead_after)
        alive = sa.select(servers.c.id).where(servers.c.heartbeat >= cutoff)
        orphaned = sa.and_(jobs.c.state.in_(LIVE),
                           sa.or_(jobs.c.owner.is_(None), jobs.c.owner.not_in(alive),
                                  jobs.c.owner.in_(gone)))
        # RETURNING: the jobs this statement failed, not those a select saw before it
        # (a job finished in between is left done, and not reported)
        ids = list(c.scalars(jobs.update().where(orphaned)
                             .values(state="failed", error=error, updated=_now())
                             .returning(jobs.c.id)))
        _drop_runs(c, t, ids)
        c.execute(servers.delete().where(sa.or_(servers.c.heartbeat < cutoff,
                                                servers.c.id.in_(gone))))
    return ids


def _no_such_id(key: str) -> bool:
    """Whether no row can have the id ``key``: one holding a NUL character. Ids are made
    here (UUIDs); PostgreSQL refuses the character in any text value (a DataError, a 500
    of the service's, where SQLite found no row), so such an id is unknown on both."""
    return "\0" in str(key)


def get_job(engine: sa.Engine, job_id: str) -> dict | None:
    """``{"id", "kind", "params", "state", "progress", "result", "error", "created",
    "updated", "owner"}`` (times ISO 8601 UTC), or None for an unknown id."""
    if _no_such_id(job_id):
        return None
    jobs = _t(engine)["jobs"]
    with engine.connect() as c:
        r = c.execute(sa.select(jobs).where(jobs.c.id == str(job_id))).mappings().first()
    if r is None:
        return None
    return {"id": r["id"], "kind": r["kind"], "params": r["params"], "state": r["state"],
            "progress": r["progress"], "result": r["result"], "error": r["error"],
            "created": _iso(r["created"]), "updated": _iso(r["updated"]),
            "owner": r["owner"]}


def save_fleet_run(engine: sa.Engine, *, scenario: str, params: dict, report: dict,
                   events_jsonl: str, tracks_csv: bytes, packages_csv: str,
                   fleet_geojson: str, job_id: str | None = None,
                   run_id: str | None = None) -> str:
    """Store a fleet run in one transaction; its id. Saving again under the same
    ``run_id`` replaces the run (a task re-run after its worker died stores it once).
    The run of a job already failed is refused (:class:`JobEndedError`), an unknown
    ``job_id`` too (a SkyrouteError naming it)."""
    run_id = run_id or str(uuid.uuid4())
    t = _t(engine)
    runs, jobs, stored = t["fleet_runs"], t["jobs"], t["fleet_run_files"]
    data = {"events_jsonl": events_jsonl.encode(), "tracks_csv": bytes(tracks_csv),
            "packages_csv": packages_csv.encode(), "fleet_geojson": fleet_geojson.encode()}
    with writing(engine) as c:
        if job_id is not None:
            # a write, not a read: it takes the job's row lock (PostgreSQL) or the write
            # lock (SQLite) before the run is written, so a failure of the job comes
            # either before (seen here) or after (and deletes this run)
            state = c.execute(jobs.update().where(jobs.c.id == job_id)
                              .values(state=jobs.c.state).returning(jobs.c.state)
                              ).scalar_one_or_none()
            if state is None:
                raise SkyrouteError(f"job_id={job_id!r}: no such job", param="job_id")
            if state == "failed":
                raise JobEndedError(f"job {job_id} has failed; its fleet run is not stored")
        _drop_files(c, t, [run_id])
        replaced = c.execute(runs.delete().where(runs.c.id == run_id)
                             .returning(runs.c.created)).scalar_one_or_none()
        c.execute(runs.insert().values(
            id=run_id, job_id=job_id, scenario=scenario, params=json_safe(params),
            report=json_safe(report), created=_later(replaced)))
        for name in FILES:  # a part at a time: no second copy of the tracks in a list
            for k, (part, last) in enumerate(_parts(data.pop(name))):
                c.execute(stored.insert().values(run_id=run_id, name=name, part=k,
                                                 data=part, lines=part_lines(part, last)))
    return run_id


def _later(replaced: dt.datetime | None) -> dt.datetime:
    """A saved run's ``created``: now, but at least a microsecond (what both databases
    keep) after the version it replaces. ``created`` is the version a streamed file is
    read by (:class:`StoredFile`), and the clock alone could give two saves the same one
    (a coarse clock's tick, a clock stepped back, another host's clock): the file then
    went on in the new bytes without a word. So a run's versions only grow while it is
    stored (a run is deleted only with its failed job, whose runs are then refused)."""
    now = _now()
    if replaced is not None and now <= replaced:
        return replaced + dt.timedelta(microseconds=1)
    return now


def _parts(data: bytes) -> Iterator[tuple[bytes, bool]]:
    """``data`` in parts of :data:`PART_BYTES` (the last one shorter), each with whether
    it is the last; an empty file is one empty part, so every stored file has a row."""
    view = memoryview(data)
    n = max(1, len(view))
    for a in range(0, n, PART_BYTES):
        yield bytes(view[a:a + PART_BYTES]), a + PART_BYTES >= n


def part_lines(data: bytes, last: bool) -> int:
    """The lines that end in a part of a file (``fleet_run_files.lines``): its newlines,
    and one more in the file's ``last`` part when the file ends without one. A file's
    lines are the sum over its parts; the parts before a line hold its number of
    newlines."""
    return data.count(b"\n") + (1 if last and data and not data.endswith(b"\n") else 0)


_HEAD = ("id", "job_id", "scenario", "params", "report", "created")
FILES = ("events_jsonl", "tracks_csv", "packages_csv", "fleet_geojson")
# the largest part of a stored file (revision 0005 split the files stored before): what one
# read of a streamed file holds
PART_BYTES = 1 << 20


def _run_dict(r, files: dict[str, bytes] | None = None) -> dict:
    out = {k: r[k] for k in _HEAD}
    out["created"] = _iso(out["created"])
    for k in FILES:
        if files and k in files:
            out[k] = files[k] if k == "tracks_csv" else files[k].decode()
    return out


def get_fleet_run(engine: sa.Engine, run_id: str, *,
                  files: bool | Collection[str] = True) -> dict | None:
    """``{"id", "job_id", "scenario", "params", "report", "created"}`` and, with
    ``files``, ``events_jsonl`` (text), ``tracks_csv`` (bytes), ``packages_csv`` (text)
    and ``fleet_geojson`` (text); None for an unknown id. ``files`` may also name the
    files wanted (of :data:`FILES`): only their columns are read, so a run's summary or
    one of its files does not load its tracks (about 150 MB for a big run)."""
    if isinstance(files, bool):
        wanted = FILES if files else ()
    elif isinstance(files, str):
        check_choice("files", files, FILES)
        wanted = (files,)
    else:
        wanted = tuple(files)
        for k in wanted:
            check_choice("files", k, FILES)
    if _no_such_id(run_id):
        return None
    t = _t(engine)
    runs, stored = t["fleet_runs"], t["fleet_run_files"]
    if not wanted:  # the run's head alone
        with engine.connect() as c:
            head = c.execute(sa.select(*[runs.c[k] for k in _HEAD])
                             .where(runs.c.id == str(run_id))).mappings().first()
        return None if head is None else _run_dict(head)
    # one statement (the run and its files as one snapshot, never a run replaced in
    # between): a row per part of a wanted file, or one row with no file
    q = (sa.select(*[runs.c[k] for k in _HEAD], stored.c.name, stored.c.data)
         .select_from(runs.outerjoin(stored, sa.and_(stored.c.run_id == runs.c.id,
                                                     stored.c.name.in_(wanted))))
         .where(runs.c.id == str(run_id)).order_by(stored.c.name, stored.c.part))
    with engine.connect() as c:
        rows = c.execute(q).mappings().all()
    if not rows:
        return None
    parts: dict[str, list] = {}
    for r in rows:
        if r["name"] is not None:
            parts.setdefault(r["name"], []).append(r["data"])
    head = rows[0]
    del rows
    return _run_dict(head, {k: b"".join(v) for k, v in parts.items()})


class StoredFile:
    """One of a fleet run's files as :func:`open_fleet_file` finds it: ``size`` (bytes),
    ``parts`` and the run's ``created`` (as :func:`get_fleet_run` gives it); iterating
    reads it part by part, each part (at most :data:`PART_BYTES`) by its key in a short
    transaction of its own, so a slow reader holds no connection and no lock between
    parts; :meth:`lines` reads a page of its lines from the parts it lies in. A run
    replaced or deleted meanwhile is :class:`RunChangedError` at the next part, never
    bytes of two versions.

    Iterating follows a run replaced by the same bytes (a fleet task run again after its
    worker died stores its run again, byte for byte): when the run's file now has the
    same size and its parts read so far are the ones already yielded (compared by
    digest), the rest comes from the new version, so the whole is the new version's
    bytes (also when only its parts not yet read differ). Any other change (other bytes
    in the parts yielded, another size, the run deleted) is the error."""

    FOLLOW = 3  # replacements one iteration follows (also one met while comparing)

    def __init__(self, engine: sa.Engine, run_id: str, name: str, created, size: int,
                 parts: int) -> None:
        self._engine, self._created = engine, created
        self.run_id, self.name, self.size, self.parts = run_id, name, size, parts
        self.created = _iso(created)

    def __repr__(self) -> str:
        return (f"StoredFile(run_id={self.run_id!r}, name={self.name!r}, "
                f"size={self.size}, parts={self.parts})")

    def __iter__(self) -> Iterator[bytes]:
        digests: list[bytes] = []  # of the parts yielded
        follows = 0
        while True:
            try:
                for data in self._read(len(digests)):
                    digests.append(_digest(data))
                    yield data
                return
            except RunChangedError:
                while True:  # the version now, unless it changes again while compared
                    follows += 1
                    if follows > self.FOLLOW:
                        raise
                    same = self._follow(digests)
                    if same is not None:
                        break
                if not same:
                    raise

    def _follow(self, digests: list[bytes]) -> bool | None:
        """Whether the run's file is now the same size, in as many parts, and begins with
        the parts of ``digests``; if so this file is now that version. None when that
        version was itself replaced while its parts were compared (saved twice in quick
        succession): the caller asks again. (That was False: the stream was cut although
        the run was the same bytes each time.)"""
        now = open_fleet_file(self._engine, self.run_id, self.name)
        if now is None or (now.size, now.parts) != (self.size, self.parts):
            return False
        try:
            if [_digest(d) for d in now._read(0, len(digests))] != digests:
                return False
        except RunChangedError:
            return None
        self._created, self.created = now._created, now.created
        return True

    def _changed(self) -> RunChangedError:
        return RunChangedError(f"fleet run {self.run_id!r} was replaced or deleted while "
                               f"its {self.name} was read")

    def _read(self, start: int, stop: int | None = None) -> Iterator[bytes]:
        """The parts from ``start`` on (to ``stop``, not included), one statement each."""
        t = _t(self._engine)
        runs, stored = t["fleet_runs"], t["fleet_run_files"]
        k = sa.bindparam("k")
        q = (sa.select(stored.c.data)
             .select_from(stored.join(runs, runs.c.id == stored.c.run_id))
             .where(stored.c.run_id == self.run_id, stored.c.name == self.name,
                    stored.c.part == k, runs.c.created == self._created))
        for part in range(start, self.parts if stop is None else stop):
            with self._engine.connect() as c:
                data = c.execute(q, {"k": part}).scalar_one_or_none()
            if data is None:
                raise self._changed()
            yield bytes(data)

    def _line_counts(self) -> list[int]:
        """Each part's ``lines`` (:func:`part_lines`), read from the index of the counts
        (not the parts' bytes); counted from the bytes, a part at a time, for a file
        stored before revision 0006 without them."""
        t = _t(self._engine)
        runs, stored = t["fleet_runs"], t["fleet_run_files"]
        q = (sa.select(stored.c.lines)
             .select_from(stored.join(runs, runs.c.id == stored.c.run_id))
             .where(stored.c.run_id == self.run_id, stored.c.name == self.name,
                    runs.c.created == self._created).order_by(stored.c.part))
        with self._engine.connect() as c:
            counts = list(c.execute(q).scalars())
        if len(counts) != self.parts:
            raise self._changed()
        if None in counts:
            counts = [part_lines(data, k == self.parts - 1)
                      for k, data in enumerate(self._read(0))]
        return counts

    def lines(self, offset: int, limit: int) -> tuple[list[bytes], int]:
        """Lines ``offset`` .. ``offset + limit`` of the file (each without its newline;
        a last line without one is a line) and the number of lines it has: what
        ``data.splitlines()[offset:offset + limit]`` and ``len(...)`` give for a file of
        ``\\n``-ended lines, read from the parts the page lies in (a line may cross
        parts), one part held at a time with the lines kept."""
        if offset < 0 or limit < 1:
            raise OptionError(f"offset={offset!r}, limit={limit!r}: need offset >= 0 and "
                              "limit >= 1", param="offset" if offset < 0 else "limit")
        counts = self._line_counts()
        total = sum(counts)
        want = min(offset + limit, total) - offset
        if want <= 0:
            return [], total
        # line `offset` starts after newline number `offset`: in part `start`, after
        # `skip` of that part's newlines (the parts before it hold `before`)
        start, before = 0, 0
        if offset:
            while before + counts[start] < offset:
                before += counts[start]
                start += 1
        skip = offset - before
        out: list[bytes] = []
        carry = b""
        for data in self._read(start):
            pieces = (carry + data if carry else data).split(b"\n")
            carry = pieces.pop()  # the line that goes on into the next part
            if skip:
                n = min(skip, len(pieces))
                del pieces[:n]
                skip -= n
            out.extend(pieces[:want - len(out)])
            del pieces
            if len(out) == want:
                return out, total
        if carry and len(out) < want:  # the file's last line, without a newline
            out.append(carry)
        return out, total


def _digest(data: bytes) -> bytes:
    return hashlib.blake2b(data, digest_size=16).digest()


def open_fleet_file(engine: sa.Engine, run_id: str, name: str) -> StoredFile | None:
    """The fleet run's file ``name`` (one of :data:`FILES`) to stream: its size and
    parts, read now in one statement, its bytes as it is iterated (:class:`StoredFile`);
    a file the run lacks is empty; None for an unknown run."""
    check_choice("name", name, FILES)
    if _no_such_id(run_id):
        return None
    t = _t(engine)
    runs, stored = t["fleet_runs"], t["fleet_run_files"]
    q = (sa.select(runs.c.created, sa.func.count(stored.c.part),
                   sa.func.coalesce(sa.func.sum(sa.func.length(stored.c.data)), 0))
         .select_from(runs.outerjoin(stored, sa.and_(stored.c.run_id == runs.c.id,
                                                     stored.c.name == name)))
         .where(runs.c.id == str(run_id)).group_by(runs.c.id, runs.c.created))
    with engine.connect() as c:
        row = c.execute(q).first()
    if row is None:
        return None
    created, parts, size = row
    return StoredFile(engine, str(run_id), name, created, int(size), int(parts))


MAX_OFFSET = 2**62  # within a SQL BIGINT, as both databases read OFFSET and LIMIT


def list_fleet_runs(engine: sa.Engine, *, job_id: str | None = None,
                    limit: int = 100, offset: int = 0) -> list[dict]:
    """The newest fleet runs first (of one job when ``job_id`` is given), ``limit`` of
    them from the ``offset``-th on, without their files: ``{"id", "job_id", "scenario",
    "params", "report", "created"}``."""
    for name, value, low in (("limit", limit, 1), ("offset", offset, 0)):
        if isinstance(value, bool) or not isinstance(value, int) \
                or not low <= value <= MAX_OFFSET:
            raise OptionError(f"{name}={value!r} must be an integer in {low}..{MAX_OFFSET}",
                              param=name)
    runs = _t(engine)["fleet_runs"]
    q = sa.select(*[runs.c[k] for k in _HEAD]).order_by(runs.c.created.desc(),
                                                        runs.c.id).limit(limit).offset(offset)
    if job_id is not None:
        q = q.where(runs.c.job_id == job_id)
    with engine.connect() as c:
        return [_run_dict(r) for r in c.execute(q).mappings()]
