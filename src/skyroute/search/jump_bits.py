"""Bit-packed rows for Jump Point Search's straight scans (block-based, Harabor & Grastien,
"Improving Jump Point Search", ICAPS 2014).

One bit per cell, 64 cells to a ``uint64`` word, for the padded grid of
:mod:`skyroute.search.space`: the grid by rows and its transpose (columns as rows), so a
vertical scan is a row scan too. For each straight direction a "stop" row marks where a
scan in that direction ends: a blocked cell (the wall: the scan stops one short) or a free
cell with a forced neighbour (a jump point). Without corner cutting a cell entered
eastward has a forced neighbour where the row above (or below) turns from blocked to
free: bit x of ``up & ~(up << 1)``. The first stop past a cell is one count of trailing
zeros per word, so a scan costs a few word operations, not a step per cell.

``bits`` is one flat array (one argument for numba, whose dispatch costs about a
microsecond per array) of word triples, so that a scan reads one cache line per 64
cells: for rows, (free, forced entering east, forced entering west) for word w of row y
at ``3 * (y * nw + w)``; then, from ``cols`` on, the same for columns (free, forced
entering south, forced entering north). A scan stops at ``~free | forced``. The padded
border is blocked, so every scan meets a stop inside its own row or column.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numba.cpython.unsafe.numbers import leading_zeros, trailing_zeros

ALL = np.uint64(0xFFFFFFFFFFFFFFFF)
ONE = np.uint64(1)


def words(cells: int) -> int:
    """Words for a line of ``cells`` bits."""
    return (cells + 63) // 64


@njit(cache=True)
def jump_bits(blk, Wp):
    """The ``uint64`` scan words of the padded grid ``blk`` (flat, rows of ``Wp``)."""
    Hp = blk.size // Wp
    nw, nh, cols = layout(Wp, blk.size)
    bits = np.zeros(cols + 3 * Wp * nh, np.uint64)
    for y in range(1, Hp - 1):
        for x in range(1, Wp - 1):
            c = y * Wp + x
            if blk[c]:
                continue
            row = 3 * (y * nw + (x >> 6))
            col = cols + 3 * (x * nh + (y >> 6))
            rb = ONE << np.uint64(x & 63)
            cb = ONE << np.uint64(y & 63)
            bits[row] |= rb
            bits[col] |= cb
            # forced neighbour entering eastward: a side cell free, the one behind it
            # (to the west) blocked; the same mirrored and turned for the other three
            if (not blk[c - Wp] and blk[c - Wp - 1]) or (not blk[c + Wp] and blk[c + Wp - 1]):
                bits[row + 1] |= rb
            if (not blk[c - Wp] and blk[c - Wp + 1]) or (not blk[c + Wp] and blk[c + Wp + 1]):
                bits[row + 2] |= rb
            if (not blk[c - 1] and blk[c - 1 - Wp]) or (not blk[c + 1] and blk[c + 1 - Wp]):
                bits[col + 1] |= cb
            if (not blk[c - 1] and blk[c - 1 + Wp]) or (not blk[c + 1] and blk[c + 1 + Wp]):
                bits[col + 2] |= cb
    return bits


@njit(cache=True, inline="always")
def jump(bits, nw, nh, cols, dirn, cx, cy):
    """Steps from free cell (cx, cy) in straight direction ``dirn`` (0 east, 1 west,
    2 south, 3 north) to the first jump point, or minus the free steps to the wall when
    the wall comes first (0: blocked at once); the same numbers as a JPS+ jump table.
    ``cols``: where the columns' words start (:func:`layout`)."""
    if dirn < 2:
        base, pos, part = 3 * cy * nw, cx, 1 + dirn
    else:
        base, pos, part = cols + 3 * cx * nh, cy, dirn - 1
    if dirn == 0 or dirn == 2:
        p = pos + 1
        w = p >> 6
        word = (~bits[base + 3 * w] | bits[base + 3 * w + part]) & (ALL << np.uint64(p & 63))
        while word == 0:
            w += 1
            word = ~bits[base + 3 * w] | bits[base + 3 * w + part]
        p = (w << 6) + int(trailing_zeros(word))
        dist = p - pos
    else:
        p = pos - 1
        w = p >> 6
        word = (~bits[base + 3 * w] | bits[base + 3 * w + part]) & \
            (ALL >> np.uint64(63 - (p & 63)))
        while word == 0:
            w -= 1
            word = ~bits[base + 3 * w] | bits[base + 3 * w + part]
        p = (w << 6) + 63 - int(leading_zeros(word))
        dist = pos - p
    if (bits[base + 3 * (p >> 6)] >> np.uint64(p & 63)) & ONE:
        return dist
    return 1 - dist


@njit(cache=True)
def layout(Wp, n):
    """(nw, nh, cols) of the padded grid of ``n`` cells in rows of ``Wp``: words a row,
    words a column, and the index of the columns' first word."""
    Hp = n // Wp
    nw, nh = (Wp + 63) // 64, (Hp + 63) // 64
    return nw, nh, 3 * Hp * nw
