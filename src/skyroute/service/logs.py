"""The server's logging: skyroute's own loggers (``skyroute`` and its children: the
warm-up, the jobs, a response cut short, an unhandled error) printed as uvicorn prints
its lines, at the server's ``--log-level``.

uvicorn configures its own loggers alone (``uvicorn``, ``uvicorn.error``,
``uvicorn.access``). Without a handler of their own, skyroute's records fell through to
Python's last-resort handler: a bare message with no level, and nothing below WARNING,
so an operator never saw an INFO line (a job that failed on bad input, the warm-up's
time). :func:`log_config` is uvicorn's dictConfig with a ``skyroute`` logger added on
uvicorn's ``default`` handler (stderr, ``LEVEL:    message``); uvicorn applies it in each
server process, ``--workers`` ones included.
"""

from __future__ import annotations

import copy

LEVELS = ("critical", "error", "warning", "info", "debug", "trace")  # uvicorn's
TRACE = 5  # uvicorn's TRACE level, below DEBUG


def log_config(level: str = "info") -> dict:
    """uvicorn's ``LOGGING_CONFIG`` with the ``skyroute`` logger at ``level`` (one of
    :data:`LEVELS`) on uvicorn's stderr handler, not propagating (a root handler another
    program set up would print each line twice)."""
    from uvicorn.config import LOGGING_CONFIG

    config = copy.deepcopy(LOGGING_CONFIG)
    config["loggers"]["skyroute"] = {
        "handlers": ["default"], "propagate": False,
        "level": TRACE if level == "trace" else level.upper()}
    return config
