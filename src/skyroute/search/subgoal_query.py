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
from skyroute.search import subgoal_heap as sgheap
from skyroute.search.subgoal_build import DX, DY, direct_subgoals, step

SQRT2 = math.sqrt(2.0)
SQRT2_M1 = SQRT2 - 1.0


@njit(cache=True, inline="always")
def _oct(dx, dy):
    """Octile length of a (dx, dy) offset."""
    dx, dy = abs(dx), abs(dy)
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


WS_ROWS = 7  # parent, mark, goal mark, x, y, start list, goal list


def heap_capacity(nodes: int, edges: int) -> int:
    """Entries the lazy heap may need: one per relaxation, so one per edge, one per
    start and goal connection (each at most one per subgoal) and the start itself."""
    return edges + 2 * nodes + 4


@njit(cache=True)
def subgoal_query(blk, sg, clr, offs, nbr, label, ws, gs, hfg, hn, Wp, s, t):
    """One exact query from flat cell s to flat cell t.

    ``Wp`` is the padded row length; m subgoals. ``ws`` (WS_ROWS, m + 3) int64 holds per
    node: parent, mark, goal mark, x, y (subgoals' filled once, columns m and m + 1 are
    the start and goal), then the start and goal connection lists; ``ws[0, m + 2]`` counts
    queries, so marks tell seen (2q) and closed (2q + 1) in query q and nothing is reset
    between queries. ``gs`` (m + 2) float64 is g; ``hfg`` (2, cap) and ``hn`` (cap) the
    lazy heap (:func:`heap_capacity`). Returns (code, path (K, 2), cost, expanded,
    max_frontier).
    """
    if label[s] != label[t] or label[s] < 0:
        return NO_PATH, np.empty((0, 2)), math.inf, 0, 0
    if s == t or goal_direct(clr, s, t, Wp) or goal_direct(clr, t, s, Wp):
        hops = np.array([s, t], np.int64) if s != t else np.array([s], np.int64)
        path, cost = _to_xy(_cells_path(blk, hops, Wp), Wp)
        return FOUND, path, cost, 0, 0
    m = ws.shape[1] - 3
    # A start or goal that is itself a subgoal is that node; otherwise it is node m
    # (start) or m + 1 (goal), joined to the subgoals its scan reaches.
    S = sg[s] if sg[s] >= 0 else m
    G = sg[t] if sg[t] >= 0 else m + 1
    parent, mark, gmark, xs, ys = ws[0], ws[1], ws[2], ws[3], ws[4]
    slist, glist = ws[5], ws[6]
    hf, hg = hfg[0], hfg[1]
    q = ws[0, m + 2] + 1
    ws[0, m + 2] = q
    seen, closed = 2 * q, 2 * q + 1
    xs[S], ys[S], xs[G], ys[G] = s % Wp, s // Wp, t % Wp, t // Wp
    tx, ty = xs[G], ys[G]
    ns = direct_subgoals(blk, sg, clr, s, Wp, slist, 0) if m == S else 0
    ng = direct_subgoals(blk, sg, clr, t, Wp, glist, 0) if m + 1 == G else 0
    for i in range(ng):
        gmark[glist[i]] = q
    gs[S] = 0.0
    mark[S] = seen
    size = sgheap.push(hf, hg, hn, 0, _oct(xs[S] - tx, ys[S] - ty), 0.0, S)
    expanded = 0
    frontier = 1
    code = NO_PATH
    while size > 0:
        u, size = sgheap.pop(hf, hg, hn, size)
        if mark[u] == closed:
            continue  # an outdated entry of a node already expanded
        mark[u] = closed
        if u == G:
            code = FOUND
            break
        expanded += 1
        ux, uy, gu = xs[u], ys[u], gs[u]
        if u == m:
            lo, hi = 0, ns
        else:
            lo, hi = offs[u], offs[u + 1]
        to_goal = u < m and gmark[u] == q
        for j in range(lo, hi + (1 if to_goal else 0)):
            if j == hi:
                v = m + 1
            else:
                v = slist[j] if u == m else nbr[j]
            mv = mark[v]
            if mv == closed:
                continue
            vx, vy = xs[v], ys[v]
            gv = gu + _oct(vx - ux, vy - uy)
            if mv == seen and gv >= gs[v]:
                continue
            mark[v] = seen
            gs[v] = gv
            parent[v] = u
            size = sgheap.push(hf, hg, hn, size, gv + _oct(vx - tx, vy - ty), gv, v)
            frontier = max(frontier, size)
    if code != FOUND:
        return NO_PATH, np.empty((0, 2)), math.inf, expanded, frontier
    count = 1
    v = G
    while v != S:
        v = parent[v]
        count += 1
    hops = np.empty(count, np.int64)
    v = G
    for i in range(count - 1, -1, -1):
        hops[i] = ys[v] * Wp + xs[v]
        if i:
            v = parent[v]
    path, cost = _to_xy(_cells_path(blk, hops, Wp), Wp)
    return FOUND, path, cost, expanded, frontier
