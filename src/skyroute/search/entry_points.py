"""Compiled entry points: call a numba kernel's overload without the dispatcher.

A dispatcher call types every argument on every call (about half a microsecond for a
search kernel's eleven arguments, measured on a 32x32 map); a query's arrays never
change, so its overload is resolved once (from numba's cache when it has it) and called
directly.
"""

from __future__ import annotations


def entry_point(kernel, *samples):
    """The compiled entry of ``kernel`` for arguments typed like ``samples`` (a sample
    value for each parameter: the arrays themselves, 0 for an int64, 0.0 for a float)."""
    from numba import typeof

    return kernel.compile(tuple(typeof(a) for a in samples))
