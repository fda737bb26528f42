"""Days that fail inside real pool workers: an initializer for the local executor's
spawned processes that makes ``plan_day`` raise on chosen dates there, so a test of a
range with ``--jobs 2`` meets a failed day where it happens, in a worker process (a
monkeypatch in the test's own process never reaches a spawned worker).

A test puts ``partial(fail_in_workers, {date: kind})`` in place of
``skyroute.jobs.executor._leave_sigint``, the initializer the local pool runs in each
worker. Kinds: ``skyroute`` (a SkyrouteError naming the day, as the planner's own
errors do), ``file`` (an InputFormatError naming a file: its pickle does not load, and
a pool handed it back as a worker 'terminated abruptly'), ``bug`` (a ZeroDivisionError),
``die`` (the worker kills its own process with SIGKILL, as the out-of-memory killer
does), ``die-once`` (the same, on the first try of that date only: a file in ``marks``
remembers it across processes). Dask workers: tests/jobs/failing_dask.py. This module
does not import ``distributed``: each spawned pool worker imports it, to unpickle its
initializer (a second a worker, four workers a test whose worker dies).

The same kinds apply to a fleet sweep's runs (``skyroute.jobs.fleet._simulate``): a key
``seed N`` matches every run of seed N, ``SCHEDULER AIRSPACE seed N`` one setting's.
"""

from __future__ import annotations


def fail_in_workers(kinds: dict[str, str], marks: str | None = None) -> None:
    import os
    import signal
    from pathlib import Path

    from skyroute.errors import InputFormatError, SkyrouteError
    from skyroute.jobs import deliver, executor, fleet

    executor._leave_sigint()  # what the pool's own initializer does
    real, real_simulate = deliver.plan_day, fleet._simulate

    def fail(key: str) -> None:
        kind = kinds.get(key)
        if kind == "skyroute":
            raise SkyrouteError(f"{key}: the planner failed")
        if kind == "file":
            raise InputFormatError("website/menus/menus.json", "cannot read: gone")
        if kind == "bug":
            return 1 / 0
        if kind == "die" or (kind == "die-once" and _first_try(Path(marks) / key)):
            os.kill(os.getpid(), signal.SIGKILL)

    def plan_day(site, date, orders, **kw):
        fail(str(date))
        return real(site, date, orders, **kw)

    def simulate(spec):
        one = f"{spec.scheduler} {spec.airspace} seed {spec.seed}"
        fail(one if one in kinds else f"seed {spec.seed}")
        return real_simulate(spec)

    deliver.plan_day, fleet._simulate = plan_day, simulate


def _first_try(mark) -> bool:
    try:
        mark.touch(exist_ok=False)
    except FileExistsError:
        return False
    return True


def failing_workers(monkeypatch, kinds: dict[str, str], marks=None) -> None:
    """In the test's process: the local pools started from now on run
    :func:`fail_in_workers` with ``kinds`` in each worker; two workers on any machine
    for ``--jobs 2`` (the CLI caps workers at the CPU count)."""
    import os
    from functools import partial

    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    monkeypatch.setattr("skyroute.jobs.executor._leave_sigint",
                        partial(fail_in_workers, kinds,
                                None if marks is None else str(marks)))


def die_below_zero(x: int) -> int:
    """An executor task: ``x`` back; -9 kills its own process with SIGKILL, another
    negative ``x`` ends it with exit code ``-x`` (as a crash in compiled code might)."""
    import os
    import signal

    if x == -9:
        os.kill(os.getpid(), signal.SIGKILL)
    if x < 0:
        os._exit(-x)
    return x


def die_once(mark: str) -> str:
    """An executor task that returns ``mark``, a path; but if its file name starts with
    ``die``, it first kills its own process (SIGKILL) the first time it is run for it
    (the file made remembers it)."""
    import os
    import signal
    from pathlib import Path

    if Path(mark).name.startswith("die") and _first_try(Path(mark)):
        os.kill(os.getpid(), signal.SIGKILL)
    return mark


def die_or_raise(x: int) -> int:
    """An executor task: -9 kills its own process with SIGKILL at once; any other ``x``
    raises ValueError naming its process id half a second in (so it is still running
    when a worker beside it dies)."""
    import os
    import signal
    import time

    if x == -9:
        os.kill(os.getpid(), signal.SIGKILL)
    time.sleep(0.5)
    raise ValueError(f"task {x} failed in process {os.getpid()}")


def fleet_dies_on_seed(seed: int) -> None:
    """A local pool's initializer (in place of ``_leave_sigint``): in each worker, a fleet
    run (a sweep's or a fleet job's) of ``seed`` kills its own process with SIGKILL."""
    import os
    import signal

    from skyroute.jobs import executor, fleet

    executor._leave_sigint()  # what the pool's own initializer does
    real = fleet._simulate

    def simulate(spec):
        if spec.seed == seed:
            os.kill(os.getpid(), signal.SIGKILL)
        return real(spec)

    fleet._simulate = simulate


class LosingExecutor:
    """An executor running its tasks in this process, one after another, that loses the
    tasks at ``lose`` (item indices) as a pool whose worker died under them each time
    does (their result None, :class:`~skyroute.jobs.executor.TasksLostError` at the end),
    or raises KeyboardInterrupt before task ``interrupt_at`` (a Ctrl-C)."""

    kind, workers, aborted = "local", 1, False

    def __init__(self, lose=(), interrupt_at: int | None = None) -> None:
        self.lose, self.interrupt_at = set(lose), interrupt_at

    def map(self, fn, items, *, on_result=None):
        from skyroute.jobs.executor import TasksLostError

        out, lost = [], {}
        for i, item in enumerate(items):
            if i == self.interrupt_at:
                raise KeyboardInterrupt
            if i in self.lose:
                out.append(None)
                lost[i] = "its worker process died (killed by SIGKILL), also when run again alone"
                continue
            out.append(fn(item))
            if on_result:
                on_result(i, out[-1])
        if lost:
            raise TasksLostError(lost, out)
        return out

    def close(self) -> None:
        pass

    def abort(self) -> None:
        self.aborted = True

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        pass


def raise_days_failed(x: int) -> int:
    """An executor task: ``x`` back, but 0 raises a :class:`DaysFailedError` (an error
    whose constructor takes other arguments than its message)."""
    import datetime as dt

    from skyroute.jobs.deliver import DayFailed, DaysFailedError

    if x == 0:
        day = dt.date(2024, 1, 1)
        raise DaysFailedError([], [DayFailed(day, f"{day}: the planner failed", True)], 2)
    return x
