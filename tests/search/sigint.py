"""Ctrl-C inside a compiled search (:mod:`skyroute.search.interrupt`), for the tests of
each search that polls for it."""

from __future__ import annotations

import gc
import signal


def interrupted(monkeypatch, module, call, handler, *, kernel: str = "search", at: int = 1):
    """``call()`` with ``handler`` as SIGINT's, and a SIGINT raised as the ``at``-th call
    of the compiled ``kernel`` of ``module`` begins: it is pending when the kernel starts
    (noted by :func:`~skyroute.search.interrupt.interruptible`, or run by ``handler`` on
    code that does not hold it), so the kernel's first poll sees it.

    Returns (what ``call`` returned or the exception it raised, the statuses the kernel's
    calls returned, numba's runtime allocations and frees during the call)."""
    from numba.core.runtime import _nrt_python, rtsys

    search = getattr(module, kernel)
    statuses = []

    def spy(*args):
        if len(statuses) + 1 == at:
            signal.raise_signal(signal.SIGINT)
        out = search(*args)
        statuses.append(int(out[0]))
        return out

    monkeypatch.setattr(module, kernel, spy)
    old = signal.signal(signal.SIGINT, handler)
    _nrt_python.memsys_enable_stats()
    try:
        before = rtsys.get_allocation_stats()
        try:
            out = call()
        except Exception as exc:  # returned for the test to check
            out = exc
            out.__traceback__ = None  # (its frames hold what the search returned)
        gc.collect()
        after = rtsys.get_allocation_stats()
    finally:
        _nrt_python.memsys_disable_stats()
        signal.signal(signal.SIGINT, old)
    return out, statuses, (after.alloc - before.alloc, after.free - before.free)
