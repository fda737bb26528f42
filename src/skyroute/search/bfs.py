"""Breadth-first search, 4-connected, unit step cost, compiled with numba."""

from __future__ import annotations

import numpy as np
from numba import njit

from skyroute.search.result import BUDGET_EXHAUSTED, FOUND, NO_PATH
from skyroute.search.trace import trace


@njit(cache=True)
def bfs_kernel(blk, Wp, start, goal, max_expansions, stamp, g, parent, mark, queue):
    """FIFO search over the 4 orthogonal moves; return (status, expanded, max_frontier, path).

    ``queue`` needs one slot per cell; ``g`` receives step counts.
    """
    offs = (1, -1, Wp, -Wp)
    mark[start] = stamp
    parent[start] = start
    g[start] = 0.0
    head, tail = 0, 1
    queue[0] = start
    expanded = 0
    max_frontier = 1
    while head < tail:
        c = queue[head]
        head += 1
        if c == goal:
            return FOUND, expanded, max_frontier, trace(parent, start, goal)
        if expanded >= max_expansions:
            return BUDGET_EXHAUSTED, expanded, max_frontier, np.empty(0, np.int64)
        expanded += 1
        for k in range(4):
            n = c + offs[k]
            if blk[n] or mark[n] == stamp:
                continue
            mark[n] = stamp
            parent[n] = c
            g[n] = g[c] + 1.0
            queue[tail] = n
            tail += 1
        if tail - head > max_frontier:
            max_frontier = tail - head
    return NO_PATH, expanded, max_frontier, np.empty(0, np.int64)
