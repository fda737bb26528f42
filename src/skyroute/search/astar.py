"""A* (and Dijkstra, its zero-heuristic case) on a grid, compiled with numba.

4- or 8-connected; orthogonal steps cost 1, diagonal sqrt 2. Heuristics: 0 none
(Dijkstra), 1 octile, 2 Euclidean, 3 Manhattan (admissible only 4-connected); ``weight``
>= 1 inflates h (weighted A*, cost at most ``weight`` x optimal). Each cell is expanded
at most once: a closed cell is never reopened, which is exact for a consistent heuristic
and weight 1.
"""

from __future__ import annotations

import math

from numba import njit

from skyroute.search import heap
from skyroute.search.result import BUDGET_EXHAUSTED, FOUND, NO_PATH

HEURISTICS = {"zero": 0, "octile": 1, "euclidean": 2, "manhattan": 3}
_SQRT2_M1 = math.sqrt(2.0) - 1.0


@njit(cache=True)
def heuristic(kind, c, goal, Wp):
    if kind == 0:
        return 0.0
    dx = abs(c % Wp - goal % Wp)
    dy = abs(c // Wp - goal // Wp)
    if kind == 1:
        return max(dx, dy) + _SQRT2_M1 * min(dx, dy)
    if kind == 2:
        return math.sqrt(dx * dx + dy * dy)
    return float(dx + dy)


@njit(cache=True)
def move_ok(blk, c, k, offs, side_a, side_b, rule):
    """True when move k from free cell c is legal (target free; corner rule)."""
    if blk[c + offs[k]]:
        return False
    if k < 4:
        return True
    if rule == 0:
        return (blk[c + side_a[k]] | blk[c + side_b[k]]) == 0
    return (blk[c + side_a[k]] & blk[c + side_b[k]]) == 0


@njit(cache=True)
def astar_kernel(blk, Wp, start, goal, nmoves, offs, costs, side_a, side_b, rule,
                 hkind, weight, max_expansions,
                 stamp, g, h, parent, mark, pos, hc, hk, hg):
    """Search from flat ``start`` to ``goal``; return (status, expanded, max_frontier)."""
    mark[start] = stamp
    g[start] = 0.0
    h[start] = weight * heuristic(hkind, start, goal, Wp)
    parent[start] = start
    pos[start] = -1
    size = heap.push(hc, hk, hg, pos, 0, start, h[start], 0.0)
    expanded = 0
    max_frontier = 1
    closed = stamp + 1
    while size > 0:
        c, size = heap.pop(hc, hk, hg, pos, size)
        if c == goal:
            return FOUND, expanded, max_frontier
        if expanded >= max_expansions:
            return BUDGET_EXHAUSTED, expanded, max_frontier
        mark[c] = closed
        expanded += 1
        gc = g[c]
        for k in range(nmoves):
            n = c + offs[k]
            if blk[n]:
                continue
            if k >= 4:  # the corner rule, written out: this loop is the hot one
                if rule == 0:
                    if blk[c + side_a[k]] | blk[c + side_b[k]]:
                        continue
                elif blk[c + side_a[k]] & blk[c + side_b[k]]:
                    continue
            m = mark[n]
            if m == closed:
                continue
            gn = gc + costs[k]
            if m != stamp:
                mark[n] = stamp
                pos[n] = -1
                h[n] = weight * heuristic(hkind, n, goal, Wp)
            elif gn >= g[n]:
                continue
            g[n] = gn
            parent[n] = c
            size = heap.push(hc, hk, hg, pos, size, n, gn + h[n], gn)
        if size > max_frontier:
            max_frontier = size
    return NO_PATH, expanded, max_frontier
