"""How long commands (``deliver`` ranges, ``fleet sweep``) choose where their tasks run:
``--executor local|dask``, ``--dask ADDRESS`` and ``--jobs N`` (the workers)."""

from __future__ import annotations

import contextlib
import logging
import os
from typing import Annotated

import typer

from skyroute.errors import OptionError, check_choice
from skyroute.jobs.executor import KINDS, open_executor

Executor = Annotated[str | None, typer.Option(
    "--executor", metavar="local|dask",
    help="local: --jobs processes on this machine; dask: a Dask cluster (in-process with "
         "--jobs worker processes, or the scheduler at --dask). Default: dask with --dask, "
         "else local.")]
DaskAddress = Annotated[str | None, typer.Option(
    "--dask", metavar="ADDRESS",
    help="An existing Dask scheduler, e.g. tcp://10.0.0.5:8786 (its workers run the "
         "tasks; --jobs is then unused).")]


def executor_kind(executor: str | None, dask: str | None, jobs: int) -> str:
    """The executor's kind the flags ask for (checked before any work starts)."""
    if dask is not None and not dask.strip():  # (read as no address: "drop --executor
        # local", which was not given)
        raise OptionError(f"--dask {dask!r}: expected a scheduler address like "
                          "tcp://HOST:8786")
    kind = executor or ("dask" if dask is not None else "local")
    check_choice("executor", kind, KINDS)
    if kind == "local" and dask is not None:
        raise OptionError("--dask ADDRESS runs on a Dask cluster; drop --executor local")
    if jobs < 1:
        raise OptionError(f"--jobs {jobs} must be at least 1")
    return kind


def open_from_flags(executor: str | None, dask: str | None, jobs: int, tasks: int):
    """The executor the flags ask for, for ``tasks`` tasks: local processes are capped
    at the CPU count and the task count, an in-process Dask cluster at the task count."""
    kind = executor_kind(executor, dask, jobs)
    cap = max(1, tasks)
    workers = min(jobs, os.cpu_count() or 1, cap) if kind == "local" else min(jobs, cap)
    return open_executor(kind, address=dask, workers=None if dask else workers)


@contextlib.contextmanager
def executor_warnings(console):
    """The ``skyroute.jobs`` logger's warnings (the executor's: a worker process died,
    its tasks run again) as ``skyroute: ...`` lines on ``console`` (a progress bar's)
    while in the block; the CLI sets up no logging, and Python's last resort printed
    them bare (``fleet sweep``), or over the progress bar."""

    class Say(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            console.print(f"skyroute: {record.getMessage()}", soft_wrap=True)

    logger, handler = logging.getLogger("skyroute.jobs"), Say(logging.WARNING)
    logger.addHandler(handler)
    try:
        yield
    finally:
        logger.removeHandler(handler)
