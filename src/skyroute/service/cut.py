"""A response cut short on purpose: a streamed file whose source changed after its
headers (its length among them) were sent.

HTTP has no way to say "this body is wrong" after the headers: the server closes the
connection before the body reaches its ``Content-Length`` (or, chunked, before the last
chunk), and every client sees the body incomplete (httpx: ``RemoteProtocolError``,
"peer closed connection without sending complete message body"; curl: "transfer
closed with N bytes remaining to read", exit 18). In ASGI a response is ended so by
returning without its last ``http.response.body`` message; the server then closes the
connection, and uvicorn logs an ERROR, "ASGI callable returned without completing
response.", as it would for a bug. The response that cuts itself logs one WARNING saying
why; :func:`install` keeps uvicorn's line for such a response out of the log.

How it tells them apart: :func:`begin` (called by the response, in the request's own
task, the one uvicorn logs from) puts a marker in a context variable; :func:`mark`
(where the stream stops, perhaps in a task of its own, which shares the marker) sets it;
the filter drops uvicorn's errors logged where it is set.
"""

from __future__ import annotations

import logging
from contextvars import ContextVar

_CUT: ContextVar[list[bool] | None] = ContextVar("skyroute_cut", default=None)
SERVER_LOGGER = "uvicorn.error"  # where uvicorn reports an application's errors


def begin() -> None:
    """A response that may cut itself short starts (in the request's task)."""
    _CUT.set([False])


def mark() -> None:
    """The response has cut itself short, and logged why."""
    marker = _CUT.get()
    if marker is not None:
        marker[0] = True


def is_cut() -> bool:
    marker = _CUT.get()
    return bool(marker and marker[0])


class _KeepCutsOut(logging.Filter):
    def filter(self, record: logging.LogRecord) -> bool:
        return not (record.levelno >= logging.ERROR and is_cut())


FILTER = _KeepCutsOut()


def install() -> None:
    """Keep uvicorn's error for a response cut short on purpose out of its log (once per
    process; called at the app's start-up, after the server has set up its logging)."""
    logging.getLogger(SERVER_LOGGER).addFilter(FILTER)
