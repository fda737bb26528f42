"""Answer one query on a subgoal graph (see :mod:`skyroute.search.subgoal_build`), compiled.

Cells of different connected components have no path: the labels answer at once. Start
and goal otherwise connect to the subgoals they reach directly (the same bounded scan as
the build, which also notices when the goal itself is directly h-reachable: then the
answer is the octile distance). A* runs on the graph plus the two query nodes, its
heuristic the larger of the octile distance and the landmark bounds (see
:mod:`skyroute.search.subgoal_landmarks`); each edge then expands into its cells,
diagonal steps first from the end its scan started at. The cost is the sum of the steps,
as the grid searches sum it. Per-node state is stamped per query (no reset), node
coordinates are kept (no divisions in the loop) and the heap is inlined: on small graphs
the whole query is microseconds. Graphs small enough for an all-pairs table skip the
search altogether (:mod:`skyroute.search.subgoal_table`).
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
F32_ERR = 2.0 ** -23  # twice float32's relative rounding
ACTIVE = 16  # landmarks a query uses at most (of the index's up to 64)


@njit(cache=True)
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
def _path(blk, hops, nh, Wp):
    """The (K, 2) float (x, y) cells of the first ``nh`` hops and their summed step
    lengths (as the grid searches sum them). Each hop is walked diagonal-first from its
    tail, or else from its head (one of the two is the scan that found the edge); the
    flat cells go into column 0 first and become (x, y) in place: one allocation."""
    total = 1
    for i in range(nh - 1):
        a, b = hops[i], hops[i + 1]
        total += max(abs(a % Wp - b % Wp), abs(a // Wp - b // Wp))
    out = np.empty((total, 2))
    flat = out[:, 0]
    flat[0] = hops[0]
    at = 1
    for i in range(nh - 1):
        a, b = hops[i], hops[i + 1]
        steps = max(abs(a % Wp - b % Wp), abs(a // Wp - b // Wp))
        if not _walk(blk, a, b, Wp, flat, at, True):
            _walk(blk, b, a, Wp, flat, at + steps - 1, False)  # ends on a
            flat[at + steps - 1] = b
        at += steps
    length = 0.0
    for i in range(total):
        c = int(out[i, 0])
        out[i, 0] = c % Wp - 1
        out[i, 1] = c // Wp - 1
        if i:
            dx = out[i, 0] - out[i - 1, 0]
            dy = out[i, 1] - out[i - 1, 1]
            length += math.sqrt(dx * dx + dy * dy)
    return out, length


@njit(cache=True, inline="always")
def _landmarks_to(lmd, xs, ys, ends, n, node, x, y, d):
    """Fill ``d`` with each landmark's distance to a query end: ``node`` itself when it
    is a subgoal, else the cell (x, y) joined to the ``n`` subgoals of ``ends``; inf
    when unreachable."""
    m, k = lmd.shape
    for j in range(k):
        d[j] = lmd[node, j] if node < m else np.inf
    for i in range(n):
        g = ends[i]
        c = _oct(xs[g] - x, ys[g] - y)
        for j in range(k):
            d[j] = min(d[j], lmd[g, j] + c)


@njit(cache=True)
def _active(lmd, xs, ys, slist, ns, S, glist, ng, G, tx, ty, lw, act):
    """Landmark distances to the goal into ``lw[1]``; the landmarks the query uses into
    ``act``; return their count. All that reach the goal, or with more than ACTIVE the
    ACTIVE whose bound is largest at the start (ALT's usual choice: each costs time on
    every push)."""
    k = lmd.shape[1]
    ds, dg, score = lw[0], lw[1], lw[2]
    _landmarks_to(lmd, xs, ys, glist, ng, G, tx, ty, dg)
    if k > ACTIVE:
        _landmarks_to(lmd, xs, ys, slist, ns, S, xs[S], ys[S], ds)
    na = 0
    for j in range(k):
        score[j] = -1.0
        if dg[j] < np.inf:
            score[j] = abs(ds[j] - dg[j]) if k > ACTIVE else 0.0
            act[na] = j
            na += 1
    if na <= ACTIVE:
        return na
    for a in range(ACTIVE):  # partial selection sort: the ACTIVE largest scores
        best = a
        for b in range(a + 1, na):
            if score[act[b]] > score[act[best]]:
                best = b
        act[a], act[best] = act[best], act[a]
    return ACTIVE


@njit(cache=True, inline="always")
def direct_answer(blk, clr, label, hops, Wp, s, t):
    """(code, path, cost) when no graph search is needed: different free regions (no
    path), or start and goal the same or directly h-reachable (the straight octile
    path); code -1 otherwise. ``hops`` is scratch for two cells."""
    if label[s] != label[t] or label[s] < 0:
        return NO_PATH, np.empty((0, 2)), math.inf
    if s == t or goal_direct(clr, s, t, Wp) or goal_direct(clr, t, s, Wp):
        hops[0], hops[1] = s, t
        path, cost = _path(blk, hops, 2 if s != t else 1, Wp)
        return FOUND, path, cost
    return -1, np.empty((0, 2)), math.inf


WS_ROWS = 8  # parent, mark, goal mark, x, y, start list, goal list, landmarks


def heap_capacity(nodes: int, edges: int) -> int:
    """Entries the lazy heap may need: one per relaxation, so one per edge, one per
    start and goal connection (each at most one per subgoal) and the start itself."""
    return edges + 2 * nodes + 4


@njit(cache=True)
def subgoal_query(blk, sg, clr, offs, nbr, label, lmd, lw, ws, gs, hfg, hn, Wp, s, t):
    """One exact query from flat cell s to flat cell t.

    ``Wp`` is the padded row length; m subgoals. ``ws`` (WS_ROWS, m + 3) int64 holds per
    node: parent, mark, goal mark, x, y (subgoals' filled once, columns m and m + 1 are
    the start and goal), then the start and goal connection lists; ``ws[0, m + 2]`` counts
    queries, so marks tell seen (2q) and closed (2q + 1) in query q and nothing is reset
    between queries. ``lmd`` (m, k) holds landmark distances (see subgoal_landmarks; the
    heuristic is the largest of their bounds and the octile distance; ``lw`` (3, k) float64
    is their scratch). ``gs`` (m + 2) float64 is g; ``hfg`` (2, cap) and ``hn`` (cap) the
    lazy heap (:func:`heap_capacity`). Returns (code, path (K, 2), cost, expanded,
    max_frontier).
    """
    code, path, cost = direct_answer(blk, clr, label, ws[5], Wp, s, t)
    if code >= 0:
        return code, path, cost, 0, 0
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
    act = ws[7]
    na = _active(lmd, xs, ys, slist, ns, S, glist, ng, G, tx, ty, lw, act)
    dg = lw[1]
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
            h = _oct(vx - tx, vy - ty)
            if v < m:
                for a in range(na):
                    dv = np.float64(lmd[v, act[a]])
                    # lmd is float32, each value within 2**-24 of its own size of the
                    # true distance: take that off so the bound stays a lower bound
                    h = max(h, abs(dv - dg[act[a]]) - (dv + dg[act[a]]) * F32_ERR)
            size = sgheap.push(hf, hg, hn, size, gv + h, gv, v)
            frontier = max(frontier, size)
    if code != FOUND:
        return NO_PATH, np.empty((0, 2)), math.inf, expanded, frontier
    count = 1
    v = G
    while v != S:
        v = parent[v]
        count += 1
    hops = slist  # the start's list is spent: reuse it for the hops
    v = G
    for i in range(count - 1, -1, -1):
        hops[i] = ys[v] * Wp + xs[v]
        if i:
            v = parent[v]
    path, cost = _path(blk, hops, count, Wp)
    return FOUND, path, cost, expanded, frontier
