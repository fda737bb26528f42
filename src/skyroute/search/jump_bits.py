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

``bits`` is one (6, L) array (one argument for numba, whose dispatch costs about a
microsecond per array): rows 0 and 1 the free cells by rows and by columns; rows 2-5 the
stops east, west, south and north. Row y of the grid is words ``y * nw ...`` of rows 0, 2
and 3, column x is words ``x * nh ...`` of rows 1, 4 and 5. The padded border is blocked,
so every scan meets a stop inside its own row or column.
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
    """The (6, L) ``uint64`` scan rows of the padded grid ``blk`` (flat, rows of ``Wp``)."""
    Hp = blk.size // Wp
    nw, nh = (Wp + 63) // 64, (Hp + 63) // 64
    bits = np.zeros((6, max(Hp * nw, Wp * nh)), np.uint64)
    for y in range(Hp):
        for x in range(Wp):
            c = y * Wp + x
            row = y * nw + (x >> 6)
            col = x * nh + (y >> 6)
            rb = ONE << np.uint64(x & 63)
            cb = ONE << np.uint64(y & 63)
            if blk[c]:
                for r in (2, 3):
                    bits[r, row] |= rb
                for r in (4, 5):
                    bits[r, col] |= cb
                continue
            bits[0, row] |= rb
            bits[1, col] |= cb
            # forced neighbour entering eastward: a side cell free, the one behind it
            # (to the west) blocked; the same mirrored and turned for the other three
            if (not blk[c - Wp] and blk[c - Wp - 1]) or (not blk[c + Wp] and blk[c + Wp - 1]):
                bits[2, row] |= rb
            if (not blk[c - Wp] and blk[c - Wp + 1]) or (not blk[c + Wp] and blk[c + Wp + 1]):
                bits[3, row] |= rb
            if (not blk[c - 1] and blk[c - 1 - Wp]) or (not blk[c + 1] and blk[c + 1 - Wp]):
                bits[4, col] |= cb
            if (not blk[c - 1] and blk[c - 1 + Wp]) or (not blk[c + 1] and blk[c + 1 + Wp]):
                bits[5, col] |= cb
    return bits


@njit(cache=True, inline="always")
def jump(bits, nw, nh, dirn, cx, cy):
    """Steps from free cell (cx, cy) in straight direction ``dirn`` (0 east, 1 west,
    2 south, 3 north) to the first jump point, or minus the free steps to the wall when
    the wall comes first (0: blocked at once); the same numbers as a JPS+ jump table."""
    if dirn < 2:
        base, pos, free = cy * nw, cx, 0
    else:
        base, pos, free = cx * nh, cy, 1
    stop = dirn + 2
    if dirn == 0 or dirn == 2:
        p = pos + 1
        w = p >> 6
        word = bits[stop, base + w] & (ALL << np.uint64(p & 63))
        while word == 0:
            w += 1
            word = bits[stop, base + w]
        p = (w << 6) + int(trailing_zeros(word))
        dist = p - pos
    else:
        p = pos - 1
        w = p >> 6
        word = bits[stop, base + w] & (ALL >> np.uint64(63 - (p & 63)))
        while word == 0:
            w -= 1
            word = bits[stop, base + w]
        p = (w << 6) + 63 - int(leading_zeros(word))
        dist = pos - p
    if (bits[free, base + (p >> 6)] >> np.uint64(p & 63)) & ONE:
        return dist
    return 1 - dist
