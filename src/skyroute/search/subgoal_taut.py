"""Which turns at a subgoal no shortest path takes: a local test that spares contraction work.

When a contraction hierarchy removes subgoal v, a pair (u, w) of its neighbours needs a
shortcut (and a witness search) only if u -> v -> w may be a shortest path. Unpacked,
that path leaves v towards u along an edge of the subgoal graph (v to its first hop x,
octile length) and towards w along another (v to y). Each such edge is walkable in a few
ways; :func:`first_steps` records which first steps from v two of them take (diagonals
first from either end). If for some first step a towards u and some b towards w the
steps v + a -> v -> v + b have a strictly shorter way between v + a and v + b, then
that walk from u to w is strictly longer than another, so u -> v -> w is no shortest
path: no shortcut and no witness are needed. This is Uras & Koenig's tautness rule (N-level
subgoal graphs, SUB-CH) kept to turns that shorten strictly, so exactness needs no
argument about equally long paths. On an 8-connected grid without corner cutting, by the
angle between a and b:

- 0 degrees (a = b): the walk goes back where it came from; drop the loop.
- 45 degrees: v + a and v + b are cardinal neighbours: one step of 1 < 1 + sqrt 2.
- 90 degrees, both diagonal: two cardinal steps through the cardinal cell between them
  cost 2 < 2 sqrt 2, if that cell is free (it is whenever a diagonal step into v was
  legal; checked anyway).
- 90 degrees, both cardinal: one diagonal step, sqrt 2 < 2, if the diagonal cell between
  them is free. When it is blocked the walk wraps v's corner: a real turn, kept.
- more than 90 degrees: the steps turn by 45 degrees or less, which the octile metric
  does not shorten locally: kept.

Directions are numbered anticlockwise in 45 degree steps from +x: 0 (1, 0), 1 (1, 1),
2 (0, 1), 3 (-1, 1), 4 (-1, 0), 5 (-1, -1), 6 (0, -1), 7 (1, -1) (x, y in cells; only
the cyclic order matters). A set of directions is an 8-bit mask.
"""

from __future__ import annotations

import numpy as np
from numba import njit

DIRS = ((1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1))
ALWAYS = 256  # in the shortening table: some pair of steps shortens on any grid


@njit(cache=True)
def _bit(sx, sy):
    """The mask bit of unit step (sx, sy), each in -1, 0, 1 and not both 0."""
    if sy == 0:
        return 1 if sx > 0 else 16
    if sx == 0:
        return 4 if sy > 0 else 64
    if sx > 0:
        return 2 if sy > 0 else 128
    return 8 if sy > 0 else 32


@njit(cache=True, inline="always")
def _free_walk(blk, Wp, c, dx, dy):
    """True when the walk from flat cell c along (dx, dy), diagonal steps first, then
    straight ones, is legal (free cells, no corner cut)."""
    sx = (dx > 0) - (dx < 0)
    sy = (dy > 0) - (dy < 0)
    ax, ay = abs(dx), abs(dy)
    nd = min(ax, ay)
    for _ in range(nd):
        if blk[c + sx + sy * Wp] or blk[c + sx] or blk[c + sy * Wp]:
            return False
        c += sx + sy * Wp
    st = sx if ax > ay else sy * Wp
    for _ in range(max(ax, ay) - nd):
        if blk[c + st]:
            return False
        c += st
    return True


@njit(cache=True)
def first_steps(blk, Wp, a, b):
    """Mask of first steps from flat cell a that begin an octile-length walk to cell b
    (two walks checked: diagonals first from a, and from b; 0 if neither is free)."""
    dx, dy = b % Wp - a % Wp, b // Wp - a // Wp
    sx = (dx > 0) - (dx < 0)
    sy = (dy > 0) - (dy < 0)
    ax, ay = abs(dx), abs(dy)
    diag = _bit(sx, sy) if ax and ay else 0
    card = _bit(sx, 0) if ax > ay else (_bit(0, sy) if ay > ax else 0)
    mask = 0
    if _free_walk(blk, Wp, a, dx, dy):
        mask |= diag if diag else card
    if _free_walk(blk, Wp, b, -dx, -dy):
        mask |= card if card else diag  # that walk's last step, reversed
    return mask


@njit(cache=True)
def edge_first_steps(blk, Wp, cells, offs, nbr):
    """Per CSR edge u -> v: (first steps from u towards v, first steps from v towards u),
    uint8 masks (see :func:`first_steps`)."""
    fwd = np.zeros(nbr.size, np.uint8)
    back = np.zeros(nbr.size, np.uint8)
    for u in range(cells.size):
        for j in range(offs[u], offs[u + 1]):
            a, b = cells[u], cells[nbr[j]]
            fwd[j] = first_steps(blk, Wp, a, b)
            back[j] = first_steps(blk, Wp, b, a)
    return fwd, back


@njit(cache=True)
def shorten_table():
    """(256, 256) int16: for first-step masks A and B, ALWAYS when some a in A and b in B
    are 0 or 45 degrees apart, else the mask of v's neighbour cells of which any one
    free gives some pair a strictly shorter way (0: none does)."""
    table = np.zeros((256, 256), np.int16)
    for ma in range(1, 256):
        for mb in range(1, 256):
            t = 0
            for i in range(8):
                for j in range(8):
                    if not (ma >> i) & 1 or not (mb >> j) & 1:
                        continue
                    gap = (i - j) % 8
                    if min(gap, 8 - gap) < 2:
                        t |= ALWAYS
                    elif gap == 2:
                        t |= 1 << ((j + 1) % 8)
                    elif gap == 6:
                        t |= 1 << ((i + 1) % 8)
            table[ma, mb] = t
    return table


def free_around(cells: np.ndarray, blk: np.ndarray, Wp: int) -> np.ndarray:
    """int16 per subgoal: the mask of its free neighbour cells, with ALWAYS set, so that
    ``table[A, B] & free_around[v]`` is non-zero exactly when the turn shortens."""
    out = np.full(cells.size, ALWAYS, np.int16)
    for i, (sx, sy) in enumerate(DIRS):
        out |= (blk[cells + sy * Wp + sx] == 0).astype(np.int16) << np.int16(i)
    return out
