"""Days that fail inside real pool workers: an initializer for the local executor's
spawned processes that makes ``plan_day`` raise on chosen dates there, so a test of a
range with ``--jobs 2`` meets a failed day where it happens, in a worker process (a
monkeypatch in the test's own process never reaches a spawned worker).

A test puts ``partial(fail_in_workers, {date: kind})`` in place of
``skyroute.jobs.executor._leave_sigint``, the initializer the local pool runs in each
worker. Kinds: ``skyroute`` (a SkyrouteError naming the day, as the planner's own
errors do), ``file`` (an InputFormatError naming a file: its pickle does not load, and
a pool handed it back as a worker 'terminated abruptly'), ``bug`` (a ZeroDivisionError).
"""

from __future__ import annotations


def fail_in_workers(kinds: dict[str, str]) -> None:
    from skyroute.errors import InputFormatError, SkyrouteError
    from skyroute.jobs import deliver, executor

    executor._leave_sigint()  # what the pool's own initializer does
    real = deliver.plan_day

    def plan_day(site, date, orders, **kw):
        kind = kinds.get(str(date))
        if kind == "skyroute":
            raise SkyrouteError(f"{date}: the planner failed")
        if kind == "file":
            raise InputFormatError("website/menus/menus.json", "cannot read: gone")
        if kind == "bug":
            return 1 / 0
        return real(site, date, orders, **kw)

    deliver.plan_day = plan_day


def failing_workers(monkeypatch, kinds: dict[str, str]) -> None:
    """In the test's process: the local pools started from now on run
    :func:`fail_in_workers` with ``kinds`` in each worker; two workers on any machine
    for ``--jobs 2`` (the CLI caps workers at the CPU count)."""
    import os
    from functools import partial

    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    monkeypatch.setattr("skyroute.jobs.executor._leave_sigint",
                        partial(fail_in_workers, kinds))
