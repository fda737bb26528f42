"""Compiled A* over a visibility graph: corners joined by free bitangent edges (CSR),
plus a query's start edges and the corners that see its goal.

Keys are exact floats (f = g + Euclidean distance to the goal, consistent), in the
plain re-queueing heap of :mod:`skyroute.search.heap`, so the cost returned is the
shortest path's length in the graph to the last bit of the sums, as Dijkstra's.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from skyroute.result import BUDGET_EXHAUSTED, FOUND, NO_PATH
from skyroute.search.heap import pop_plain, push_plain
from skyroute.search.trace import trace


@njit(cache=True)
def corner_astar(corners, indptr, indices, weights, start_ids, start_len, goal_len, sx, sy,
                 tx, ty, budget):
    """Shortest path from point s to point t through the corners.

    ``start_ids``/``start_len``: the corners s sees (tangent, free) and their distances;
    ``goal_len[c]``: |c - t| where corner c sees t, else inf. Nodes n and n + 1 are s
    and t. Returns (code, node path, cost, expanded, largest open list)."""
    n = corners.shape[0]
    S, T = n, n + 1
    g = np.full(n + 2, np.inf)
    parent = np.full(n + 2, -1, np.int64)
    closed = np.zeros(n + 2, np.bool_)
    cap = start_ids.shape[0] + indices.shape[0] + n + 2
    hk = np.empty(cap)
    hn = np.empty(cap, np.int64)
    g[S] = 0.0
    push_plain(hk, hn, 0, math.hypot(sx - tx, sy - ty), S)
    size = 1
    frontier = 1
    expanded = 0
    code = NO_PATH
    while size > 0:
        u = pop_plain(hk, hn, size)
        size -= 1
        if closed[u]:
            continue
        closed[u] = True
        if u == T:
            code = FOUND
            break
        if expanded >= budget:
            code = BUDGET_EXHAUSTED
            break
        expanded += 1
        gu = g[u]
        if u == S:
            lo, hi = 0, start_ids.shape[0]
        else:
            lo, hi = indptr[u], indptr[u + 1]
            if goal_len[u] < np.inf and gu + goal_len[u] < g[T]:
                g[T] = gu + goal_len[u]
                parent[T] = u
                push_plain(hk, hn, size, g[T], T)
                size += 1
        for k in range(lo, hi):
            if u == S:
                v, w = start_ids[k], start_len[k]
            else:
                v, w = indices[k], weights[k]
            gv = gu + w
            if gv < g[v] and not closed[v]:
                g[v] = gv
                parent[v] = u
                push_plain(hk, hn, size,
                           gv + math.hypot(corners[v, 0] - tx, corners[v, 1] - ty), v)
                size += 1
        frontier = max(frontier, size)
    if code != FOUND:
        return code, np.empty(0, np.int64), np.inf, expanded, frontier
    return code, trace(parent, S, T), g[T], expanded, frontier
