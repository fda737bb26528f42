"""A* (and Dijkstra, its zero-heuristic case) on a grid, compiled with numba.

4- or 8-connected; orthogonal steps cost 1, diagonal sqrt 2. Heuristics: 0 none
(Dijkstra), 1 octile, 2 Euclidean, 3 Manhattan (admissible only 4-connected); ``weight``
>= 1 inflates h (weighted A*, cost at most ``weight`` x optimal). Each cell is expanded
at most once: a closed cell is never reopened, which is exact for a consistent heuristic
and weight 1. Legal moves come from a per-cell bit mask built once per grid
(:meth:`SearchSpace.move_mask`), and h from the expanded cell's coordinates, so the
inner loop does no division and no corner tests.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from skyroute.search import heap
from skyroute.search.result import BUDGET_EXHAUSTED, FOUND, NO_PATH
from skyroute.search.trace import trace

HEURISTICS = {"zero": 0, "octile": 1, "euclidean": 2, "manhattan": 3}
_SQRT2_M1 = math.sqrt(2.0) - 1.0


@njit(cache=True)
def h_of(kind, dx, dy):
    """Heuristic for absolute offsets (dx, dy) to the goal."""
    if kind == 1:
        return max(dx, dy) + _SQRT2_M1 * min(dx, dy)
    if kind == 2:
        return math.sqrt(dx * dx + dy * dy)
    if kind == 3:
        return float(dx + dy)
    return 0.0


@njit(cache=True)
def heuristic(kind, c, goal, Wp):
    """Heuristic between flat cells ``c`` and ``goal``."""
    return h_of(kind, abs(c % Wp - goal % Wp), abs(c // Wp - goal // Wp))


@njit(cache=True)
def move_ok(mask, c, k):
    """True when move k is legal from cell c."""
    return (mask[c] >> k) & 1


@njit(cache=True)
def astar_kernel(mask, Wp, start, goal, nmoves, offs, costs, mdx, mdy,
                 hkind, weight, max_expansions, stamp, g, parent, mark, pos, hc, hk):
    """Search from flat ``start`` to ``goal``; return (status, expanded, max_frontier, path)."""
    gx, gy = goal % Wp, goal // Wp
    mark[start] = stamp
    g[start] = 0.0
    parent[start] = start
    pos[start] = -1
    f0 = weight * h_of(hkind, abs(start % Wp - gx), abs(start // Wp - gy))
    size = heap.push(hc, hk, pos, 0, start, heap.key(f0, 0.0))
    expanded = 0
    max_frontier = 1
    closed = stamp + 1
    while size > 0:
        c, size = heap.pop(hc, hk, pos, size)
        if c == goal:
            return FOUND, expanded, max_frontier, trace(parent, start, goal)
        if expanded >= max_expansions:
            return BUDGET_EXHAUSTED, expanded, max_frontier, np.empty(0, np.int64)
        mark[c] = closed
        expanded += 1
        gc = g[c]
        m = mask[c]
        cx = c % Wp - gx
        cy = c // Wp - gy
        for k in range(nmoves):
            if not (m >> k) & 1:
                continue
            n = c + offs[k]
            state = mark[n]
            if state == closed:
                continue
            gn = gc + costs[k]
            if state != stamp:
                mark[n] = stamp
                pos[n] = -1
            elif gn >= g[n]:
                continue
            g[n] = gn
            parent[n] = c
            dx = abs(cx + mdx[k])
            dy = abs(cy + mdy[k])
            if hkind == 1:  # octile, written out: the common case in the hot loop
                hn = max(dx, dy) + _SQRT2_M1 * min(dx, dy)
            else:
                hn = h_of(hkind, dx, dy)
            fn = gn + weight * hn
            size = heap.push(hc, hk, pos, size, n, heap.key(fn, gn))
        if size > max_frontier:
            max_frontier = size
    return NO_PATH, expanded, max_frontier, np.empty(0, np.int64)
