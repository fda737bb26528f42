"""The step drone's A* in move space, compiled whole: plain arrays in, a parent tree out.

States are positions reachable by steps; two positions in the same ``merge``-wide lattice
cell (relative to the start) are one state. Moves cost 1; ``h`` is the admissible bound
of :class:`skyroute.motion.step_drone.DistanceBound`, evaluated here from its corner
table. The open list is a binary heap of packed int64 keys (f above the tie-break "deeper
first") with lazy deletion; a state not yet expanded takes a shorter route found later
(its position becomes that route's end), so first discovery never fixes a longer g.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, types
from numba.typed import Dict

from skyroute.motion.corner_distance import approximate, beyond, exact
from skyroute.motion.zone_kernels import expand, sight
from skyroute.result import BUDGET_EXHAUSTED, FOUND, NO_PATH
from skyroute.search import heap, interrupt

_TIE = (1 << 20) - 1
_HALF = 1 << 31


# numba caches the kernels below with corner_distance's first pass (approximate, beyond,
# exact), zone_kernels' tests, the heap and interrupt's poll compiled in, keyed by this
# file's date alone: edit this file when one of those changes, or a checkout keeps
# running the old code.


@njit(cache=True)
def distance(qx, qy, sees, tx, ty, cols, cdist, edges, meta, start, ids, vals, order):
    """A lower bound on the obstacle-avoiding distance from q to the target; (meta, start,
    ids) the edges' bucket grid (:mod:`skyroute.motion.edge_grid`).

    The straight distance when q sees the target, else min over the corners q sees of
    |q - v| + D(v), D the corner's shortest distance to the target: every path from q
    bends first at a corner in sight. Corners are tried cheapest first (a binary heap of
    their values: a city's point may test hundreds of its thousands of corners before one
    is in sight), so usually the first sight test settles it. The heap holds the values'
    approximations (:func:`corner_distance.approximate`, ``sqrt`` and vectorised, where
    ``hypot`` for every corner was a tenth of a city's ``skyroute fly``); a corner taken
    from it gets its exact value, and once the approximations left are beyond the least
    exact value in sight (:func:`corner_distance.beyond`) none can be less: the answer is
    the exact values' minimum, as a heap of them gives. ``cols``: the corners as (2, N)
    rows of x and y; ``vals`` (N,) float and ``order`` (N,) int64: workspace.
    """
    d = math.hypot(qx - tx, qy - ty)
    n = cols.shape[1]
    if sees or n == 0:
        return d
    approximate(qx, qy, cols, cdist, vals)
    m = 0
    for c in range(n):
        if vals[c] < np.inf:
            vals[m], order[m] = vals[c], c
            m += 1
    for i in range(m // 2 - 1, -1, -1):
        heap.sift_down(vals, order, i, m)
    best = np.inf
    while m > 0 and vals[0] <= beyond(best):
        c = heap.pop_plain(vals, order, m)
        m -= 1
        v = exact(qx, qy, cols, cdist, c)
        if v < best and sight(qx, qy, cols[0, c], cols[1, c], edges, meta, start, ids):
            best = v
    return max(d, best) if best < np.inf else d


@njit(cache=True)
def moves_left(d, step):
    """At least max(0, ceil(d / step - 1)) moves: each covers ``step``, and the flight
    may stop anywhere closer than ``step`` to the target."""
    h = math.ceil(d / step - 1.0 - 1e-12)
    return h if h > 0 else 0


@njit(cache=True)
def bound(qx, qy, sees, tx, ty, cols, cdist, edges, meta, start, ids, step):
    """:func:`moves_left` of :func:`distance`: A*'s heuristic."""
    n = cols.shape[1]
    return moves_left(distance(qx, qy, sees, tx, ty, cols, cdist, edges, meta, start, ids,
                               np.empty(n), np.empty(n, np.int64)), step)


@njit(cache=True)
def search(sx, sy, tx, ty, sees0, deltas, edges, owner, nzones, bedges, meta, start, ids,
           cols, cdist, step, merge, max_expansions, eps):
    """A* from (sx, sy) to closer than ``step`` to (tx, ty).

    The heuristic is evaluated lazily: a new state gets the cheap bound max(|q - t|,
    d(parent) - step) (the obstacle-avoiding distance is 1-Lipschitz along a free move),
    and the exact :func:`distance` only when it reaches the top of the heap; if that
    raises its f it goes back in. Most generated states are never popped, so most
    sight tests are never made.

    Returns (status, goal node, expanded, x, y, parent, move index); parent -1 at the start;
    status :data:`skyroute.search.interrupt.INTERRUPTED` when its poll saw a SIGINT.
    """
    cap = 4096
    x = np.empty(cap)
    y = np.empty(cap)
    parent = np.empty(cap, np.int64)
    move = np.empty(cap, np.int64)
    g = np.empty(cap, np.int64)
    dist = np.empty(cap)
    closed = np.zeros(cap, np.bool_)
    exact = np.zeros(cap, np.bool_)
    hk = np.empty(cap, np.int64)
    hn = np.empty(cap, np.int64)
    seen = Dict.empty(key_type=types.int64, value_type=types.int64)
    vals = np.empty(cols.shape[1])  # the bound's workspace
    order = np.empty(cols.shape[1], np.int64)
    x[0], y[0], parent[0], move[0], g[0] = sx, sy, -1, -1, 0
    dist[0] = distance(sx, sy, sees0, tx, ty, cols, cdist, edges, meta, start, ids, vals,
                       order)
    exact[0] = True
    n = 1
    seen[np.int64(_HALF) * (1 << 32) + _HALF] = 0
    hk[0] = (np.int64(moves_left(dist[0], step)) << 20) | _TIE
    hn[0] = 0
    size = 1
    expanded = 0
    while size > 0:
        top = hk[0]
        i = heap.pop_plain(hk, hn, size)
        size -= 1
        if closed[i]:
            continue
        if math.hypot(tx - x[i], ty - y[i]) < step:
            return FOUND, i, expanded, x[:n], y[:n], parent[:n], move[:n]
        if not exact[i]:
            exact[i] = True
            sees = sight(x[i], y[i], tx, ty, edges, meta, start, ids)
            dist[i] = max(dist[i], distance(x[i], y[i], sees, tx, ty, cols, cdist, edges,
                                            meta, start, ids, vals, order))
            f = g[i] + moves_left(dist[i], step)
            if f > (top >> 20):
                if size + 1 > hk.shape[0]:
                    hk, hn = heap.grow(hk, size + 2), heap.grow(hn, size + 2)
                heap.push_plain(hk, hn, size, (np.int64(f) << 20) | (_TIE - min(g[i], _TIE)), i)
                size += 1
                continue
        closed[i] = True
        if interrupt.stop(expanded):  # nothing of the tree kept (see interrupt)
            none = np.empty(0, np.int64)
            return interrupt.INTERRUPTED, -1, expanded, np.empty(0), np.empty(0), none, none
        if expanded >= max_expansions:
            return BUDGET_EXHAUSTED, -1, expanded, x[:n], y[:n], parent[:n], move[:n]
        expanded += 1
        ok, _ = expand(x[i], y[i], deltas, tx, ty, edges, owner, nzones, bedges, meta, start,
                       ids, eps, False)
        gi = g[i] + 1
        for k in range(deltas.shape[0]):
            if not ok[k]:
                continue
            qx, qy = x[i] + deltas[k, 0], y[i] + deltas[k, 1]
            key = (np.int64(round((qx - sx) / merge)) + _HALF) * (1 << 32) + \
                np.int64(round((qy - sy) / merge)) + _HALF
            j = -1
            if key in seen:
                j = seen[key]
            if j >= 0 and (closed[j] or g[j] <= gi):
                continue
            if j < 0:
                j = n
                n += 1
                if n > x.shape[0]:
                    x, y = heap.grow(x, n + 1), heap.grow(y, n + 1)
                    parent, move = heap.grow(parent, n + 1), heap.grow(move, n + 1)
                    g, dist = heap.grow(g, n + 1), heap.grow(dist, n + 1)
                    closed = heap.grow_zeroed(closed, x.shape[0])
                    exact = heap.grow_zeroed(exact, x.shape[0])
                seen[key] = j
            x[j], y[j], parent[j], move[j], g[j] = qx, qy, i, k, gi
            dist[j] = max(math.hypot(qx - tx, qy - ty), dist[i] - step)
            exact[j] = False
            f = gi + moves_left(dist[j], step)
            if size + 1 > hk.shape[0]:
                hk, hn = heap.grow(hk, size + 2), heap.grow(hn, size + 2)
            heap.push_plain(hk, hn, size, (np.int64(f) << 20) | (_TIE - min(gi, _TIE)), j)
            size += 1
    return NO_PATH, -1, expanded, x[:n], y[:n], parent[:n], move[:n]
