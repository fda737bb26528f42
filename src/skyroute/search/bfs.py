"""Breadth-first search, 4-connected, unit step cost, compiled with numba."""

from __future__ import annotations

import numpy as np
from numba import njit

from skyroute.result import FOUND, NO_PATH, stop_code
from skyroute.search.heap import reset
from skyroute.search.trace import to_cells, trace


@njit(cache=True)
def bfs_kernel(blk, Wp, start, goal, max_expansions, floats, ints):
    """FIFO search over the 4 orthogonal moves; return (status, expanded, max_frontier,
    path, length), ``path`` the (x, y) cells (empty unless found).

    floats, ints: the workspace of :meth:`SearchSpace.workspace` (its ``state`` row all
    zeros on entry and on return). The queue doubles as the list of touched cells; ``g``
    receives step counts.
    """
    g = floats[0]
    parent, state, queue = ints[0], ints[1], ints[2]
    offs = (1, -1, Wp, -Wp)
    state[start] = -1
    parent[start] = start
    g[start] = 0.0
    head, tail = 0, 1
    queue[0] = start
    expanded = 0
    max_frontier = 1
    code = -1
    while head < tail:
        c = queue[head]
        head += 1
        code = stop_code(c, goal, expanded, max_expansions)
        if code >= 0:
            break
        expanded += 1
        for k in range(4):
            n = c + offs[k]
            if blk[n] or state[n] != 0:
                continue
            state[n] = -1
            parent[n] = c
            g[n] = g[c] + 1.0
            queue[tail] = n
            tail += 1
        if tail - head > max_frontier:
            max_frontier = tail - head
    if code < 0:  # the open list ran dry
        code = NO_PATH
    reset(state, queue, tail)
    if code == FOUND:
        path, length = to_cells(trace(parent, start, goal), Wp)
        return code, expanded, max_frontier, path, length
    return code, expanded, max_frontier, np.empty((0, 2)), np.inf
