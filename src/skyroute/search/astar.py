"""A* (and Dijkstra, its zero-heuristic case) on a grid, compiled with numba.

4- or 8-connected; orthogonal steps cost 1, diagonal sqrt 2. Heuristics: 0 none
(Dijkstra), 1 octile, 2 Euclidean, 3 Manhattan (admissible only 4-connected); ``weight``
>= 1 inflates h (weighted A*, cost at most ``weight`` x optimal). On 8-connected grids without
corner cutting only canonical successors are generated (:mod:`skyroute.search.canonical`),
which skips most neighbours a parent already reached. A new successor with its
parent's f (the common case along a good line) is expanded next without a trip through
the heap. Each cell is expanded
at most once: a closed cell is never reopened, which is exact for a consistent heuristic
and weight 1. Legal moves come from a per-cell bit mask built once per grid
(:meth:`SearchSpace.move_mask`), and h from the expanded cell's coordinates, so the
inner loop does no division and no corner tests.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from skyroute.result import BUDGET_EXHAUSTED, FOUND, NO_PATH
from skyroute.search import heap
from skyroute.search.canonical import LOWEST, START
from skyroute.search.moves import COSTS, MDX, MDY, SQRT2_M1, h_of, offsets, xy
from skyroute.search.trace import to_cells, trace_moves

ON_LEVEL = np.iinfo(np.int32).max  # state of a cell on the equal-f stack
U0, U1, U2, U4 = np.uint64(0), np.uint64(1), np.uint64(2), np.uint64(4)  # unsigned constants


@njit(cache=True)
def astar_kernel(mask, succ, Wp, start, goal, hkind, weight, max_expansions, floats, ints,
                 keys, fs):
    """Search from flat ``start`` to ``goal``; return (status, expanded, max_frontier,
    path, length): ``path`` the (x, y) cells, empty unless found (:func:`to_cells`).

    floats, ints, keys: the workspace of :meth:`SearchSpace.workspace`; its ``state``
    row must be all zeros on entry and is all zeros again on return; ``ints[0]`` receives
    each reached cell's entering move. ``succ``: the successor table of
    :mod:`skyroute.search.canonical` for the move rule. The open list is a 4-ary form of
    :mod:`skyroute.search.heap`, written out in this loop: as calls (even inlined by
    numba) its operations cost about 10% more here, binary-heap calls 1.2-1.8x
    (docs/architecture.md). ``fs``: the keys' unit of f (:func:`heap.f_scale` of a bound
    on every f, :meth:`SearchSpace.f_scale`).
    """
    g = floats[0]
    entered, state, touched, hc, level = ints[0], ints[1], ints[2], ints[3], ints[4]
    hk = keys
    offs = offsets(Wp)
    # Cells and heap slots are unsigned in the loop: numba indexes with a signed integer
    # through a wrap-around test for negative indices, and these loads are most of an
    # expansion (about 18% less kernel time on random 512 maps, the same expansions;
    # docs/benchmarks.md section 11). Negative offsets wrap modulo 2**64, so c +
    # uoffs[k] is still the neighbour; constants are U0..U4, since numba types a sum of
    # a signed and an unsigned integer as a float.
    uoffs = np.empty(8, np.uint64)
    for k in range(8):
        uoffs[k] = np.uint64(offs[k])
    ugoal = np.uint64(goal)
    inv = 1.0 / Wp
    gx, gy = goal % Wp, goal // Wp
    g[start] = 0.0
    entered[start] = START
    touched[0] = start
    nt = 1
    f0 = weight * h_of(hkind, abs(start % Wp - gx), abs(start // Wp - gy))
    hc[0] = start
    keys[0] = heap.key(f0, 0.0, fs)
    state[start] = 1
    size = 1
    expanded = 0
    max_frontier = 1
    code = NO_PATH
    # New successors whose f equals the expanded cell's go on a stack (``level``), not
    # the heap, and are expanded before the heap's next pop: nothing open has a smaller
    # f (consistent h, weight 1). Last in, first out: the deepest first, as the g
    # tie-break in the heap keys.
    can_hold = weight == 1.0 and (hkind == 1 or hkind == 2)
    nl = 0
    ck = keys[0]
    while True:
        if nl > 0:
            nl -= 1
            c = np.uint64(level[nl])
        elif size > 0:
            # pop the minimum (hole sifts down) and close it
            c = np.uint64(hc[0])
            ck = hk[0]
            size -= 1
            if size > 0:
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
        cf = ck >> heap.TIE_BITS  # unchanged while the stack of equal f empties
        if c == ugoal:
            code = FOUND
            break
        if expanded >= max_expansions:
            code = BUDGET_EXHAUSTED
            break
        expanded += 1
        gc = g[c]
        m = succ[entered[c], mask[c]]
        cx, cy = xy(np.int64(c), Wp, inv)
        cx -= gx
        cy -= gy
        while m:  # the mask holds the connectivity: no diagonal bits when 4
            k = LOWEST[m]
            m &= m - 1
            n = c + uoffs[k]
            st = state[n]
            if st < 0:
                continue
            gn = gc + COSTS[k]
            if st == 0:
                touched[nt] = n
                nt += 1
            elif gn >= g[n]:
                continue
            g[n] = gn
            entered[n] = k
            if st == ON_LEVEL:  # an equal cost by another float sum: already queued
                continue
            dx = abs(cx + MDX[k])
            dy = abs(cy + MDY[k])
            if hkind == 1:  # octile, written out: the common case
                hn = max(dx, dy) + SQRT2_M1 * min(dx, dy)
            else:
                hn = h_of(hkind, dx, dy)
            key = (int((gn + weight * hn) * fs + 0.5) << heap.TIE_BITS) | \
                (heap.TIE_MAX - min(int(gn * 4.0), heap.TIE_MAX))
            if st == 0:
                if can_hold and key >> heap.TIE_BITS == cf:
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
    heap.reset(state, touched, nt)
    if code == FOUND:
        path, length = to_cells(trace_moves(entered, offs, start, goal), Wp)
        return code, expanded, max_frontier, path, length
    return code, expanded, max_frontier, np.empty((0, 2)), np.inf
