"""Build a simple subgoal graph (Uras, Koenig & Hernandez, ICAPS 2013) over a padded grid.

Subgoals are the free cells at convex obstacle corners: a diagonal neighbour is blocked
while both cells beside that diagonal step are free. Two cells are h-reachable when a
path of octile length joins them; the graph links each subgoal to the subgoals it
reaches directly (no other subgoal in between), found by the paper's clearance scan:
along each cardinal and diagonal ray, then from each cell of a diagonal ray along its two
cardinal directions, each sweep bounded by the one before it. An edge u -> v is always
walkable as "diagonal steps first, then straight steps" from u, which is how a query
turns it back into cells. Edge costs are octile distances, computed from coordinates.

Everything is compiled: the grid in, flat int32 arrays out (CSR adjacency).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from skyroute.search.moves import MDX, MDY

# Moves in skyroute.search.moves order: 0 E, 1 W, 2 S, 3 N (cardinal), 4..7 diagonal, as
# tuples (compile-time constants for numba: scalar steps, no array lookups in hot loops).
# The cardinal parts of diagonal k are moves XC[k] (along x) and YC[k] (along y).
DX = tuple(int(v) for v in MDX)
DY = tuple(int(v) for v in MDY)
XC = tuple(0 if dx > 0 else 1 for dx in DX)
YC = tuple(2 if dy > 0 else 3 for dy in DY)


@njit(cache=True)
def step(k, Wp):
    """Flat offset of move k on a padded grid of row length Wp."""
    return DY[k] * Wp + DX[k]


@njit(cache=True, inline="always")
def legal(blk, c, k, Wp):
    """True when move k from free cell c obeys the no-corner-cutting rule."""
    sx, sy = DX[k], DY[k] * Wp
    if blk[c + sx + sy]:
        return False
    return k < 4 or (blk[c + sx] == 0 and blk[c + sy] == 0)


@njit(cache=True)
def subgoal_ids(blk, Wp):
    """(sg_id per padded cell, -1 where none; flat cell of each subgoal)."""
    n = blk.size
    sg = np.full(n, -1, np.int32)
    cells = np.empty(n, np.int32)
    m = 0
    for c in range(Wp, n - Wp):
        if blk[c]:
            continue
        for k in range(4, 8):
            sx, sy = DX[k], DY[k] * Wp
            if blk[c + sx + sy] and blk[c + sx] == 0 and blk[c + sy] == 0:
                sg[c] = m
                cells[m] = c
                m += 1
                break
    return sg, cells[:m].copy()


@njit(cache=True)
def clearances(blk, sg, Wp):
    """(n, 8) int32: legal steps from each free cell along each move before the next cell
    is blocked (or the step cuts a corner) or is a subgoal."""
    n = blk.size
    clr = np.zeros((n, 8), np.int32)
    for k in range(8):
        d = step(k, Wp)
        first, inc = (n - 1, -1) if d > 0 else (0, 1)
        for i in range(n):
            c = first + inc * i
            if blk[c]:
                continue
            nb = c + d
            if nb < 0 or nb >= n or not legal(blk, c, k, Wp) or sg[nb] >= 0:
                continue
            clr[c, k] = clr[nb, k] + 1
    return clr


@njit(cache=True, inline="always")
def _ray_end(blk, sg, clr, o, k, Wp):
    """The subgoal at the end of ray k from o (one step past its clearance), or -1."""
    d = step(k, Wp)
    c = o + (clr[o, k] + 1) * d
    if c < 0 or c >= blk.size or sg[c] < 0:
        return -1
    if not legal(blk, c - d, k, Wp):
        return -1
    return sg[c]


@njit(cache=True)
def direct_subgoals(blk, sg, clr, o, Wp, out, count):
    """Append to ``out[count:]`` the subgoals directly h-reachable from cell o (the
    paper's bounded clearance scan); return the new count. ``out`` must hold them."""
    for k in range(8):
        s = _ray_end(blk, sg, clr, o, k, Wp)
        if s >= 0:
            out[count] = s
            count += 1
    for k in range(4, 8):
        dk, sk = clr[o, k], step(k, Wp)
        for side in range(2):
            c = XC[k] if side == 0 else YC[k]
            sc = step(c, Wp)
            bound = clr[o, c]
            cell = o
            for _i in range(dk):
                cell += sk
                ext = clr[cell, c]
                if ext < bound:
                    t = cell + (ext + 1) * sc
                    if sg[t] >= 0:
                        out[count] = sg[t]
                        count += 1
                    bound = ext
    return count


@njit(cache=True)
def link(blk, sg, cells, clr, Wp):
    """CSR (offsets, targets) of every subgoal's directly h-reachable subgoals."""
    m = cells.size
    deg = np.zeros(m + 1, np.int64)
    buf = np.empty(max(m, 1), np.int32)
    for u in range(m):
        deg[u + 1] = direct_subgoals(blk, sg, clr, cells[u], Wp, buf, 0)
    offs = np.cumsum(deg).astype(np.int64)
    nbr = np.empty(offs[m], np.int32)
    for u in range(m):
        direct_subgoals(blk, sg, clr, cells[u], Wp, nbr[offs[u]:], 0)
    return offs, nbr
