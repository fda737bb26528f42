"""Answer one query on a subgoal graph (see :mod:`skyroute.search.subgoal_build`), compiled.

Cells of different connected components have no path: the labels answer at once. Start
and goal otherwise connect to the subgoals they reach directly (the same bounded scan as
the build, which also notices when the goal itself is directly h-reachable: then the
answer is the octile distance). A* with the octile heuristic runs on the graph plus the
two query nodes; each edge then expands into its cells, diagonal steps first from the
end its scan started at. The cost is the sum of the steps, as the grid searches sum it.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from skyroute.result import FOUND, NO_PATH
from skyroute.search import heap
from skyroute.search.subgoal_build import DX, DY, direct_subgoals, step

SQRT2 = math.sqrt(2.0)
SQRT2_M1 = SQRT2 - 1.0


@njit(cache=True, inline="always")
def _octile(a, b, Wp):
    dx = abs(a % Wp - b % Wp)
    dy = abs(a // Wp - b // Wp)
    return max(dx, dy) + SQRT2_M1 * min(dx, dy)


@njit(cache=True, inline="always")
def _moves(a, b, Wp):
    """Diagonal-first moves from a to b: (diagonal k, count, cardinal c, count)."""
    dx = b % Wp - a % Wp
    dy = b // Wp - a // Wp
    ax, ay = abs(dx), abs(dy)
    k = 4 + (1 if dx < 0 else 0) + (2 if dy < 0 else 0)
    if ax > ay:
        c = 0 if dx > 0 else 1
    else:
        c = 2 if dy > 0 else 3
    return k, min(ax, ay), c, max(ax, ay) - min(ax, ay)


@njit(cache=True, inline="always")
def goal_direct(clr, o, t, Wp):
    """True when the scan from o, with t taken as a subgoal, reaches t."""
    k, nd, c, nc = _moves(o, t, Wp)
    if nd == 0:
        return nc <= clr[o, c]
    if nc == 0:
        return nd <= clr[o, k]
    if nd > clr[o, k]:
        return False
    bound = clr[o, c]
    cell, sk = o, step(k, Wp)
    for _r in range(nd - 1):
        cell += sk
        bound = min(bound, clr[cell, c])
    cell += sk
    return nc <= clr[cell, c] and nc <= bound


@njit(cache=True, inline="always")
def _walk(blk, a, b, Wp, out, at, forward):
    """Write the diagonal-first cells after a up to b into ``out`` (from ``at`` on when
    ``forward``, else backwards ending at ``at``); False if a step is illegal."""
    k, nd, c, nc = _moves(a, b, Wp)
    sx, sy = DX[k], DY[k] * Wp
    sc = step(c, Wp)
    cur = a
    for i in range(nd + nc):
        if i < nd:
            if blk[cur + sx] or blk[cur + sy] or blk[cur + sx + sy]:
                return False
            cur += sx + sy
        else:
            if blk[cur + sc]:
                return False
            cur += sc
        if forward:
            out[at + i] = cur
        else:
            out[at - 1 - i] = cur
    return True


@njit(cache=True)
def _cells_path(blk, hops, Wp):
    """Flat cells of the hop sequence; each hop walked diagonal-first from its tail, or
    else from its head (one of the two is the scan that found the edge)."""
    total = 1
    for i in range(len(hops) - 1):
        a, b = hops[i], hops[i + 1]
        total += max(abs(a % Wp - b % Wp), abs(a // Wp - b // Wp))
    flat = np.empty(total, np.int64)
    flat[0] = hops[0]
    at = 1
    for i in range(len(hops) - 1):
        a, b = hops[i], hops[i + 1]
        steps = max(abs(a % Wp - b % Wp), abs(a // Wp - b // Wp))
        if not _walk(blk, a, b, Wp, flat, at, True):
            _walk(blk, b, a, Wp, flat, at + steps - 1, False)  # ends on a
            flat[at + steps - 1] = b
        at += steps
    return flat


@njit(cache=True)
def _to_xy(flat, Wp):
    """(K, 2) float (x, y) cells and the summed step lengths (as the grid searches)."""
    out = np.empty((len(flat), 2))
    length = 0.0
    for i in range(len(flat)):
        out[i, 0] = flat[i] % Wp - 1
        out[i, 1] = flat[i] // Wp - 1
        if i:
            dx = out[i, 0] - out[i - 1, 0]
            dy = out[i, 1] - out[i - 1, 1]
            length += math.sqrt(dx * dx + dy * dy)
    return out, length


@njit(cache=True)
def subgoal_query(blk, sg, cells, clr, offs, nbr, label, ws, gs, Wp, s, t):
    """One exact query from flat cell s to flat cell t.

    ``Wp`` is the padded row length; ``ws`` (8, m + 2) int64 and ``gs`` (m + 2) float64
    are the workspace: rows parent, state, heap cells, heap keys, start list, goal list,
    goal flags, seen; the state and flag rows are zero between queries. Returns (code,
    path (K, 2), cost, expanded, max_frontier).
    """
    if label[s] != label[t] or label[s] < 0:
        return NO_PATH, np.empty((0, 2)), math.inf, 0, 0
    if s == t or goal_direct(clr, s, t, Wp) or goal_direct(clr, t, s, Wp):
        hops = np.array([s, t], np.int64) if s != t else np.array([s], np.int64)
        path, cost = _to_xy(_cells_path(blk, hops, Wp), Wp)
        return FOUND, path, cost, 0, 0
    m = cells.size
    S, G = m, m + 1
    parent, state, hc, hk = ws[0], ws[1], ws[2], ws[3]
    slist, glist, gflag = ws[4], ws[5], ws[6]
    ns = direct_subgoals(blk, sg, clr, s, Wp, slist, 0)
    ng = direct_subgoals(blk, sg, clr, t, Wp, glist, 0)
    for i in range(ng):
        gflag[glist[i]] = 1
    seen = ws[7]  # nodes given a state, cleared before returning
    nseen = 1
    seen[0] = S
    gs[S] = 0.0
    size = heap.push(hc, hk, state, 0, S, heap.key(_octile(s, t, Wp), 0.0))
    expanded = 0
    frontier = 1
    code = NO_PATH
    goal_node = -1
    while size > 0:
        u, size = heap.pop(hc, hk, state, size)
        cu = s if u == S else (t if u == G else cells[u])
        if cu == t:
            code = FOUND
            goal_node = u
            break
        expanded += 1
        if u == S:
            lo, hi = 0, ns
        else:
            lo, hi = offs[u], offs[u + 1]
        extra = 1 if u < m and gflag[u] else 0
        for j in range(lo, hi + extra):
            if j == hi:
                v = G
                cv = t
            else:
                v = slist[j] if u == S else nbr[j]
                cv = cells[v]
            st = state[v]
            if st == heap.CLOSED:
                continue
            gv = gs[u] + _octile(cu, cv, Wp)
            if st == 0:
                seen[nseen] = v
                nseen += 1
            elif gv >= gs[v]:
                continue
            gs[v] = gv
            parent[v] = u
            size = heap.push(hc, hk, state, size, v, heap.key(gv + _octile(cv, t, Wp), gv))
            frontier = max(frontier, size)
    for i in range(ng):
        gflag[glist[i]] = 0
    heap.reset(state, seen, nseen)
    if code != FOUND:
        return NO_PATH, np.empty((0, 2)), math.inf, expanded, frontier
    count = 1
    v = goal_node
    while v != S:
        v = parent[v]
        count += 1
    hops = np.empty(count, np.int64)
    v = goal_node
    for i in range(count - 1, -1, -1):
        hops[i] = s if v == S else (t if v == G else cells[v])
        if i:
            v = parent[v]
    path, cost = _to_xy(_cells_path(blk, hops, Wp), Wp)
    return FOUND, path, cost, expanded, frontier
