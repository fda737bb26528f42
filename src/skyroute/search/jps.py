"""Jump Point Search, 8-connected, without corner cutting (MovingAI's move rule).

Harabor & Grastien's pruning for the no-corner-cutting model ("Improving Jump Point
Search", ICAPS 2014): a diagonal move has no forced neighbours; a straight move stops at
the goal or where a side cell is free while the cell behind it is blocked, which forces
the perpendicular step and the diagonal beside it. The pruning reads the canonical
successor table shared with A* (:mod:`skyroute.search.canonical`). As in that paper, a
diagonal scan queues no intermediate jump points: every straight jump point its two
straight scans find from a diagonal cell is a successor of the expanded cell itself
(reached diagonal steps first), and the diagonal scan goes on to the wall.

Straight scans are answered in O(1) from a table built once per grid (the JPS+ idea):
for each cell and each of the 4 straight directions, the steps to the first cell with a
forced neighbour, or minus the free steps to the wall when none comes first. Only the
goal depends on the query: a scan also stops on it when it lies on the ray within
reach. Costs are octile, equal to A*'s; the path returned is every cell, as for A*.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from skyroute.result import FOUND, stop_code
from skyroute.search import heap
from skyroute.search.astar import ON_LEVEL, U0, U1, U2, U4
from skyroute.search.cache_lines import prefetch_row
from skyroute.search.canonical import LOWEST, START
from skyroute.search.moves import MDX, MDY, h_of, offsets, xy
from skyroute.search.trace import to_cells, trace

NO_PIVOTS = np.empty((0, 0))  # online JPS: the octile heuristic alone

# Straight directions: 0 east (+x), 1 west (-x), 2 south (+y), 3 north (-y), as moves 0-3.


@njit(cache=True)
def jump_tables(blk, Wp):
    """An (n, 4) int32 table for the padded grid ``blk``: for each cell and straight
    direction, the steps to the first cell with a forced neighbour if one comes before
    the wall, else minus the free steps to the wall (0: blocked at once)."""
    n = blk.size
    table = np.zeros((n, 4), np.int32)
    for dirn in range(4):
        d = (1, -1, Wp, -Wp)[dirn]
        side = Wp if dirn < 2 else 1
        # visit cells so that c + d is done before c
        first, step = (n - 1, -1) if dirn == 0 or dirn == 2 else (0, 1)
        for i in range(n):
            c = first + step * i
            nb = c + d
            if nb < 0 or nb >= n or blk[c] or blk[nb]:
                continue
            if (blk[nb + side] == 0 and blk[nb - d + side] != 0) or \
                    (blk[nb - side] == 0 and blk[nb - d - side] != 0):
                table[c, dirn] = 1
            elif table[nb, dirn] > 0:
                table[c, dirn] = table[nb, dirn] + 1
            else:
                table[c, dirn] = table[nb, dirn] - 1
    return table


@njit(cache=True)
def _steps(v, dirn, cx, cy, gx, gy):
    """Steps from (cx, cy) in straight direction ``dirn``, whose jump-table entry is
    ``v``, to the goal or the first jump point, whichever comes first; 0 when the scan
    meets a wall first. Scalars only: array arguments would cost numba two atomic
    reference-count updates per call, which dominated the kernel's time."""
    reach = v if v > 0 else -v
    if dirn == 0:
        if cy == gy and 0 < gx - cx <= reach:
            return gx - cx
    elif dirn == 1:
        if cy == gy and 0 < cx - gx <= reach:
            return cx - gx
    elif dirn == 2:
        if cx == gx and 0 < gy - cy <= reach:
            return gy - cy
    elif cx == gx and 0 < cy - gy <= reach:
        return cy - gy
    return v if v > 0 else 0


@njit(cache=True)
def _sign(v):
    return (v > 0) - (v < 0)


@njit(cache=True)
def jps_kernel(mask, succ, table, Wp, start, goal, max_expansions, floats, ints, keys, piv,
               fs):
    """Search from flat ``start`` to ``goal``.

    ``mask``: the 8-connected, no-corner-cutting move mask; ``succ``: the canonical
    successor table (:mod:`skyroute.search.canonical`, the same pruning rules); ``table``:
    :func:`jump_tables`. Returns (status, expanded, max_frontier, path, length) with
    ``path`` every cell as (x, y), empty unless found. floats, ints, keys: the workspace
    of :meth:`SearchSpace.workspace` (its ``state`` row all zeros on entry and on
    return). ``piv``: (cells, P) distances from P pivots (:mod:`skyroute.search.pivots`)
    whose differential bounds sharpen the octile heuristic; (0, 0) for the octile
    distance alone. ``fs``: the keys' unit of f, as for the A* kernel.

    An expansion first lists its jump points (cell, x, y, entering move) in ``found``,
    prefetches their ``state``, ``g`` and pivot rows (cache misses on large maps, now
    overlapping), then relaxes them in one loop. The heap is the A* kernel's 4-ary one,
    written out: no call in the loop takes an array (the prefetch is an intrinsic).
    """
    g = floats[0]
    parent, state, touched, hc, entered = ints[0], ints[1], ints[2], ints[3], ints[4]
    level = ints[5]
    hk = keys
    offs = offsets(Wp)
    inv = 1.0 / Wp
    gx, gy = xy(goal, Wp, inv)
    npiv = piv.shape[1]
    dt = np.empty(npiv)  # the goal's pivot distances
    for p in range(npiv):
        dt[p] = piv[goal, p]
    found = np.empty((8 * (Wp + len(mask) // Wp) + 8, 4), np.int64)
    g[start] = 0.0
    parent[start] = start
    entered[start] = START
    touched[0] = start
    nt = 1
    sx0, sy0 = xy(start, Wp, inv)
    hc[0] = start
    hk[0] = heap.key(h_of(1, abs(sx0 - gx), abs(sy0 - gy)), 0.0, fs)
    state[start] = 1
    size = 1
    expanded = 0
    max_frontier = 1
    code = -1
    nl = 0  # new jump points with their parent's f: a stack expanded first, as in A*
    ck = hk[0]
    while True:
        if nl > 0:
            nl -= 1
            c = level[nl]
        elif size > 0:
            # pop the minimum (hole sifts down) and close it
            c = hc[0]
            ck = hk[0]
            size -= 1
            if size > 0:  # slots unsigned, as in the A* kernel
                usz = np.uint64(size)
                last = np.uint64(hc[usz])
                lk = hk[usz]
                i = U0
                while True:
                    b = U4 * i + U1
                    if b >= usz:
                        break
                    kb = hk[b]
                    e = min(b + U4, usz)
                    j = b + U1
                    while j < e:
                        if hk[j] < kb:
                            kb = hk[j]
                            b = j
                        j += U1
                    if kb >= lk:
                        break
                    moved = np.uint64(hc[b])
                    hc[i] = moved
                    hk[i] = kb
                    state[moved] = i + U1
                    i = b
                hc[i] = last
                hk[i] = lk
                state[last] = i + U1
        else:
            break
        state[c] = -1
        cf = ck >> heap.TIE_BITS
        code = stop_code(c, goal, expanded, max_expansions)
        if code >= 0:
            break
        expanded += 1
        cx, cy = xy(c, Wp, inv)
        m = succ[entered[c], mask[c]]
        nf = 0
        while m:
            k = LOWEST[m]
            m &= m - 1
            sx, sy = MDX[k], MDY[k]
            if k < 4:
                v = _steps(table[c, k], k, cx, cy, gx, gy)
                if v:
                    found[nf, 0] = c + v * offs[k]
                    found[nf, 1] = cx + v * sx
                    found[nf, 2] = cy + v * sy
                    found[nf, 3] = k
                    nf += 1
                continue
            # Diagonal: every straight jump point seen from the diagonal is a successor
            # of c itself (the diagonal cell in between is not queued: arrived at
            # diagonally, it would only continue these same three scans).
            hdir = 0 if sx > 0 else 1
            vdir = 2 if sy > 0 else 3
            d, dx, dy = c, cx, cy
            while (mask[d] >> k) & 1:
                d += offs[k]
                dx += sx
                dy += sy
                if d == goal:
                    found[nf, 0] = d
                    found[nf, 1] = dx
                    found[nf, 2] = dy
                    found[nf, 3] = k
                    nf += 1
                    break
                v = _steps(table[d, hdir], hdir, dx, dy, gx, gy)
                if v:
                    found[nf, 0] = d + v * sx
                    found[nf, 1] = dx + v * sx
                    found[nf, 2] = dy
                    found[nf, 3] = hdir
                    nf += 1
                v = _steps(table[d, vdir], vdir, dx, dy, gx, gy)
                if v:
                    found[nf, 0] = d + v * sy * Wp
                    found[nf, 1] = dx
                    found[nf, 2] = dy + v * sy
                    found[nf, 3] = vdir
                    nf += 1
        for q in range(nf):  # every new jump point's state, g and pivot row, together
            prefetch_row(state, found[q, 0])
            prefetch_row(g, found[q, 0])
            if npiv:
                prefetch_row(piv, found[q, 0])
        gc = g[c]
        for q in range(nf):
            n = np.uint64(found[q, 0])
            st = state[n]
            if st < 0:
                continue
            nx, ny = found[q, 1], found[q, 2]
            gn = gc + h_of(1, abs(nx - cx), abs(ny - cy))
            if st == 0:
                touched[nt] = n
                nt += 1
            elif gn >= g[n]:
                continue
            g[n] = gn
            parent[n] = c
            entered[n] = found[q, 3]
            if st == ON_LEVEL:  # an equal cost by another float sum: already queued
                continue
            hn = h_of(1, abs(nx - gx), abs(ny - gy))
            for pv in range(npiv):  # differential bounds (NaN, never larger, off region)
                bound = abs(piv[n, pv] - dt[pv])
                if bound > hn:
                    hn = bound
            key = heap.key(gn + hn, gn, fs)
            if st == 0:
                if key >> heap.TIE_BITS == cf:
                    level[nl] = n
                    nl += 1
                    state[n] = ON_LEVEL
                    continue
                i = np.uint64(size)
                size += 1
            else:
                i = np.uint64(st - 1)
            # push or decrease-key (hole sifts up)
            while i > U0:
                p = (i - U1) >> U2
                kp = hk[p]
                if key >= kp:
                    break
                moved = np.uint64(hc[p])
                hc[i] = moved
                hk[i] = kp
                state[moved] = i + U1
                i = p
            hc[i] = n
            hk[i] = key
            state[n] = i + U1
        if size + nl > max_frontier:
            max_frontier = size + nl
    code = heap.finish(code, state, touched, nt)
    if code == FOUND:
        path, length = to_cells(fill(trace(parent, start, goal), Wp), Wp)
        return code, expanded, max_frontier, path, length
    return code, expanded, max_frontier, np.empty((0, 2)), np.inf


@njit(cache=True)
def fill(points, Wp):
    """Expand a chain of jump points into every cell: each leg takes its diagonal steps
    first, then its straight ones (the route the scans took)."""
    total = 1
    for i in range(1, len(points)):
        a, b = points[i - 1], points[i]
        total += max(abs(b % Wp - a % Wp), abs(b // Wp - a // Wp))
    out = np.empty(total, np.int64)
    out[0] = points[0]
    k = 1
    for i in range(1, len(points)):
        a, b = points[i - 1], points[i]
        dx, dy = b % Wp - a % Wp, b // Wp - a // Wp
        diag = min(abs(dx), abs(dy))
        step = _sign(dx) + _sign(dy) * Wp
        straight = _sign(dx) if abs(dx) > abs(dy) else _sign(dy) * Wp
        c = a
        for s in range(max(abs(dx), abs(dy))):
            c += step if s < diag else straight
            out[k] = c
            k += 1
    return out
