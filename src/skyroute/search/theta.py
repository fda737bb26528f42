"""Theta* and Lazy Theta*: any-angle search on the grid, compiled with numba.

Nash, Daniel, Koenig & Felner, "Theta*: Any-Angle Path Planning on Grids" (JAIR 2010) and
Nash, Koenig & Tovey, "Lazy Theta*" (AAAI 2010). Nodes are cell centres; a node may take
its parent's parent as its own parent when the two see each other (see ``los``), so
path segments run at any angle. With the Euclidean heuristic every node is expanded with
a g no larger than its octile grid distance, so the cost never exceeds A*'s. Lazy Theta*
assumes sight when a node is generated and checks it once, on expansion; if the check
fails and the repaired g makes the node no longer the best, it goes back on the open
list instead of being expanded, which keeps that same bound.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from skyroute.result import FOUND, stop_code
from skyroute.search import heap
from skyroute.search.los import line_of_sight
from skyroute.search.moves import COSTS, heuristic, move_ok, offsets
from skyroute.search.trace import to_cells, trace


@njit(cache=True)
def _dist(a, b, Wp):
    dx = a % Wp - b % Wp
    dy = a // Wp - b // Wp
    return math.sqrt(dx * dx + dy * dy)


@njit(cache=True)
def theta_kernel(blk, mask, Wp, start, goal, hkind, weight, max_expansions, lazy,
                 floats, ints, keys, fs):
    """Return (status, expanded, max_frontier, los_checks, path, length): ``path`` the
    (x, y) cells (empty unless found).

    floats, ints, keys: the workspace of :meth:`SearchSpace.workspace` (its ``state`` row all
    zeros on entry and on return); ``fs``: the keys' unit of f, as for the A* kernel.
    """
    g, h = floats[0], floats[1]
    parent, state, touched, hc = ints[0], ints[1], ints[2], ints[3]
    hk = keys
    offs = offsets(Wp)
    g[start] = 0.0
    h[start] = weight * heuristic(hkind, start, goal, Wp)
    parent[start] = start
    touched[0] = start
    nt = 1
    size = heap.push(hc, hk, state, 0, start, heap.key(h[start], 0.0, fs))
    expanded = 0
    max_frontier = 1
    los = 0
    code = -1
    while size > 0:
        c, size = heap.pop(hc, hk, state, size)
        if lazy and parent[c] != c:
            p = parent[c]
            los += 1
            if not line_of_sight(blk, Wp, p, c):
                # Repair: the best closed grid neighbour becomes the parent.
                best = math.inf
                for k in range(8):  # the mask holds the connectivity
                    n = c + offs[k]
                    if state[n] < 0 and move_ok(mask, c, k) and g[n] + COSTS[k] < best:
                        best = g[n] + COSTS[k]
                        parent[c] = n
                old = g[c]
                g[c] = best
                if best > old and size > 0:  # no longer surely the best: queue it again
                    size = heap.push(hc, hk, state, size, c, heap.key(best + h[c], best, fs))
                    if hc[0] != c:
                        continue
                    c, size = heap.pop(hc, hk, state, size)
        code = stop_code(c, goal, expanded, max_expansions)
        if code >= 0:
            break
        expanded += 1
        pc = parent[c]
        for k in range(8):  # the mask holds the connectivity
            if not move_ok(mask, c, k):
                continue
            n = c + offs[k]
            st = state[n]
            if st < 0:
                continue
            if st == 0:
                touched[nt] = n
                nt += 1
                h[n] = weight * heuristic(hkind, n, goal, Wp)
                g[n] = math.inf
            if lazy:
                gn = g[pc] + _dist(pc, n, Wp)
                par = pc
            else:
                sight = False
                if pc != c:
                    los += 1
                    sight = line_of_sight(blk, Wp, pc, n)
                if sight:
                    gn = g[pc] + _dist(pc, n, Wp)
                    par = pc
                else:
                    gn = g[c] + COSTS[k]
                    par = c
            if gn < g[n]:
                g[n] = gn
                parent[n] = par
                size = heap.push(hc, hk, state, size, n, heap.key(gn + h[n], gn, fs))
        if size > max_frontier:
            max_frontier = size
    code = heap.finish(code, state, touched, nt)
    if code == FOUND:
        path, length = to_cells(trace(parent, start, goal), Wp)
        return code, expanded, max_frontier, los, path, length
    return code, expanded, max_frontier, los, np.empty((0, 2)), np.inf
