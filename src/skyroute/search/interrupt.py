"""Ctrl-C for a search compiled whole: the kernel polls every :data:`POLL` expansions
and returns :data:`INTERRUPTED` when a SIGINT has come; the handler in place runs after.

A compiled loop never reaches a line of Python, where CPython runs a signal's handler,
so Ctrl-C waited for the search's end (minutes for Hybrid A*'s default budget). Run in
the kernel's poll, the handler's KeyboardInterrupt went up through the compiled frames,
which numba does not clean up: the search's arrays stayed allocated for as long as the
process lived (about 27 MB a Ctrl-C a few seconds into an ILP search). So, while
:func:`interruptible` holds it, the main thread's SIGINT is only noted; the poll sees
it, the kernel returns (freeing its arrays), and the handler runs as the block ends.

A kernel calls :func:`stop` with its expansion count and, when it is True, returns
:data:`INTERRUPTED` as its status with nothing of its tree (a traceback may hold what it
returns); :func:`run` calls it under :func:`interruptible`, again if the handler did not
raise. numba caches each kernel with :func:`stop` compiled in, keyed by the kernel's file
alone: edit those files when it changes.
"""

from __future__ import annotations

import contextlib
import signal
import sys
import threading

from numba import njit, objmode

POLL = 4096  # expansions between two returns to the interpreter
INTERRUPTED = -1  # a kernel's status when its poll saw a SIGINT noted
_noted = [False]  # a SIGINT came while interruptible() held the main thread's handler


def _note(signum, frame) -> None:
    _noted[0] = True


def _poll() -> int:
    """Called from the compiled search now and then: the interpreter runs a pending
    signal's handler here; 1 when a SIGINT was noted (:func:`interruptible`) and this is
    the main thread's search (a search in another thread goes on)."""
    return 1 if _noted[0] and threading.current_thread() is threading.main_thread() else 0


@njit(cache=True)
def _ask():
    with objmode(answer="int64"):
        answer = _poll()
    return answer != 0


@njit(cache=True, inline="always")
def stop(expanded):
    """True when the kernel with ``expanded`` expansions so far should return
    :data:`INTERRUPTED`: every :data:`POLL` expansions it asks the interpreter. Inlined
    (numba's IR): a call each expansion cost 3 ns, the test alone nothing measurable."""
    return expanded & (POLL - 1) == POLL - 1 and _ask()  # (POLL a power of two)


@contextlib.contextmanager
def interruptible():
    """Hold SIGINT while the block runs a compiled search: in the main thread, with a
    handler set from Python, the signal is only noted (the search's poll sees it and
    returns, freeing its arrays), and the handler that was in place runs as the block
    ends: Ctrl-C raises its KeyboardInterrupt from there. Elsewhere nothing changes (no
    handler runs in another thread's poll). A handler that returns without raising lets
    the caller search again (:func:`run`)."""
    old = signal.getsignal(signal.SIGINT)
    if threading.current_thread() is not threading.main_thread() or not callable(old):
        yield
        return
    _noted[0] = False
    signal.signal(signal.SIGINT, _note)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)
        noted, _noted[0] = _noted[0], False
    if noted:
        old(signal.SIGINT, sys._getframe(2))  # the frame of the block's caller


def run(kernel, *args):
    """``kernel(*args)`` under :func:`interruptible`, whose result's first item is its
    status: called again while it is :data:`INTERRUPTED` (the SIGINT's handler returned
    without raising, as the CLI's does for a second Ctrl-C while the first unwinds)."""
    while True:
        with interruptible():
            out = kernel(*args)
        if out[0] != INTERRUPTED:
            return out
