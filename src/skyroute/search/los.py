"""Exact line of sight between cell centres, compiled with numba.

A segment between two cell centres is legal when it passes through no blocked cell and
does not squeeze between two blocked cells that touch only at a corner. The walk uses
integers only: with doubled coordinates every centre is odd and every cell border even,
so the order in which the segment crosses column and row borders (and whether it
crosses both at once, through a grid vertex) is decided by exact products.
"""

from __future__ import annotations

from numba import njit


@njit(cache=True)
def line_of_sight(blk, Wp, a, b):
    """True when the segment from flat cell ``a`` to flat cell ``b`` is legal."""
    x, y = a % Wp, a // Wp
    dx = b % Wp - x
    dy = b // Wp - y
    sx = 1 if dx > 0 else -1
    sy = Wp if dy > 0 else -Wp
    adx, ady = abs(dx), abs(dy)
    c = a
    k = 0  # column borders crossed
    m = 0  # row borders crossed
    while k < adx or m < ady:
        # next column border at t = (2k+1)/(2 adx), next row border at (2m+1)/(2 ady)
        if k < adx and m < ady:
            tx = (2 * k + 1) * ady
            ty = (2 * m + 1) * adx
        elif k < adx:
            tx, ty = 0, 1
        else:
            tx, ty = 1, 0
        if tx == ty:  # through a grid vertex: no squeeze between two blocked cells
            if blk[c + sx] and blk[c + sy]:
                return False
            c += sx + sy
            k += 1
            m += 1
        elif tx < ty:
            c += sx
            k += 1
        else:
            c += sy
            m += 1
        if blk[c]:
            return False
    return True
