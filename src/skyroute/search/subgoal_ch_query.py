"""Answer one query through a contraction hierarchy over a subgoal graph, compiled.

The hierarchy (:mod:`skyroute.search.subgoal_contract`) keeps, per subgoal, its edges
to higher-ranked subgoals: original edges and shortcuts, each with its middle node.
A query first takes the same steps as the A* query (component labels, the direct
answer, the start's and the goal's direct subgoals, joined at their octile distance),
then runs Dijkstra upward from the start's subgoals and upward from the goal's, one
settled node at a time from whichever side has the smaller key. A node both sides have
reached is a meeting; a side stops once its smallest key reaches the best meeting.
Neither side goes on from a core node (the nodes left uncontracted): the core's table
joins each core node the start side settled to each the goal side settled, and the
best of those sums and the meetings is the optimum (Geisberger's core-based CH, with a
table for the core). Stall-on-demand: a node that a higher neighbour already reaches
more cheaply is not expanded (its key is not its distance). The parent chains, the
table's predecessors between the two core nodes, then each shortcut unpack into
subgoal hops, and those into cells as in :func:`skyroute.search.subgoal_query._path`.
The graph is undirected, so both sides use the same upward edges. Per-node state is
stamped per query; nothing is reset.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from skyroute.result import FOUND, NO_PATH
from skyroute.search.heap import indexed_pop, indexed_up
from skyroute.search.subgoal_build import direct_subgoals
from skyroute.search.subgoal_query import _oct, _path, direct_answer

STALL_EPS = 1e-9  # stall only on a strictly shorter way (float sums of equal paths differ)
WS_ROWS = 12  # per side (0, 1): mark, parent, heap position, heap nodes; start, goal
# lists; each side's core nodes reached


@njit(cache=True, inline="always")
def _owner(uo, e):
    """The node whose upward edge list holds edge e (binary search in the offsets)."""
    lo, hi = 0, uo.size - 1
    while hi - lo > 1:
        mid = (lo + hi) >> 1
        if uo[mid] <= e:
            lo = mid
        else:
            hi = mid
    return lo


@njit(cache=True)
def _unpack(uo, un, um, e, rev, cells, out, n, stack):
    """Append to ``out[n:]`` the subgoal cells along upward edge e, shortcuts unpacked:
    from its owner to its head, or back when ``rev``, the first end left out. Return
    the new count. ``stack`` entries are 2 e + rev."""
    stack[0] = 2 * e + rev
    top = 1
    while top > 0:
        top -= 1
        e, rev = stack[top] >> 1, stack[top] & 1
        o, h = _owner(uo, e), un[e]
        a, b = (h, o) if rev else (o, h)
        x = um[e]
        if x < 0:
            out[n] = cells[b]
            n += 1
            continue
        ea = eb = -1
        for j in range(uo[x], uo[x + 1]):
            if un[j] == a:
                ea = j
            elif un[j] == b:
                eb = j
        stack[top] = 2 * eb  # x -> b comes after a -> x: pushed first
        stack[top + 1] = 2 * ea + 1
        top += 2
    return n


@njit(cache=True)
def ch_query(blk, sg, clr, label, cells, uo, un, uw, um, cid, cnodes, dtab, ptab, ws, gs, hk,
             Wp, s, t):
    """One exact query from flat cell s to flat cell t through the hierarchy.

    ``ws`` (WS_ROWS, m + 2) int64: per side a mark (stamped: seen 2q, closed 2q + 1 in
    query q, counted in ``ws[0, m]``), the parent edge (-1: a first node, joined to the
    query's end), the heap slot and the heap; then the start's and the goal's subgoals,
    and scratch for the hops and the unpacking stack. ``gs`` (2, m) float64 holds each
    side's distances and ``hk`` (2, m) their heap keys. Returns the tuple of
    :func:`~skyroute.search.subgoal_query.subgoal_query` (``expanded`` counts the
    nodes settled on both sides).
    """
    code, path, cost = direct_answer(blk, clr, label, ws[8], Wp, s, t)
    if code >= 0:
        return code, path, cost, 0, 0
    m = cells.size
    q = ws[0, m] + 1
    ws[0, m] = q
    seen, closed = 2 * q, 2 * q + 1
    lists = ws[8:10]
    sizes = np.zeros(2, np.int64)
    ends = (s, t)
    for side in range(2):
        c = ends[side]
        lst = lists[side]
        if sg[c] >= 0:
            lst[0], n = sg[c], 1
        else:
            n = direct_subgoals(blk, sg, clr, c, Wp, lst, 0)
        mark, par, pos, hn, g, k = ws[4 * side], ws[4 * side + 1], ws[4 * side + 2], \
            ws[4 * side + 3], gs[side], hk[side]
        cx, cy = c % Wp, c // Wp
        size = 0
        for i in range(n):
            v = lst[i]
            d = _oct(cells[v] % Wp - cx, cells[v] // Wp - cy)
            if mark[v] == seen:
                if d >= g[v]:
                    continue
                g[v] = d
                indexed_up(k, hn, pos, pos[v], d, v)
            else:
                mark[v], g[v], par[v] = seen, d, -1
                indexed_up(k, hn, pos, size, d, v)
                size += 1
        sizes[side] = size
    best, meet = math.inf, -1
    expanded = frontier = 0
    ents = ws[10:12]
    nent = np.zeros(2, np.int64)
    while True:
        # the side with the smaller key; a side is done once it reaches the best meeting
        k0 = hk[0, 0] if sizes[0] > 0 else math.inf
        k1 = hk[1, 0] if sizes[1] > 0 else math.inf
        if min(k0, k1) >= best:
            break
        side = 0 if k0 <= k1 else 1
        mark, par, pos, hn, g, k = ws[4 * side], ws[4 * side + 1], ws[4 * side + 2], \
            ws[4 * side + 3], gs[side], hk[side]
        omark, og = ws[4 - 4 * side], gs[1 - side]
        u, sizes[side] = indexed_pop(k, hn, pos, sizes[side])
        mark[u] = closed
        gu = g[u]
        if omark[u] >= seen and gu + og[u] < best:
            best, meet = gu + og[u], u
        stalled = False
        for j in range(uo[u], uo[u + 1]):
            w = un[j]
            if mark[w] >= seen and g[w] + uw[j] < gu - STALL_EPS:
                stalled = True
                break
        if stalled:
            continue  # a core node too: the table joins through w no longer
        if cid[u] >= 0:  # a core node: the table goes on from here
            ents[side, nent[side]] = u
            nent[side] += 1
            continue
        expanded += 1
        size = sizes[side]
        for j in range(uo[u], uo[u + 1]):
            w = un[j]
            mw = mark[w]
            if mw == closed:
                continue
            d = gu + uw[j]
            if mw == seen:
                if d >= g[w]:
                    continue
                g[w], par[w] = d, j
                indexed_up(k, hn, pos, pos[w], d, w)
            else:
                mark[w], g[w], par[w] = seen, d, j
                indexed_up(k, hn, pos, size, d, w)
                size += 1
        sizes[side] = size
        frontier = max(frontier, sizes[0] + sizes[1])
    ba = bb = -1
    for i in range(nent[0]):
        a = ents[0, i]
        ga = gs[0, a]
        if ga >= best:
            continue
        row = dtab[cid[a]]
        for j in range(nent[1]):
            b = ents[1, j]
            c = ga + row[cid[b]] + gs[1, b]
            if c < best:
                best, ba, bb = c, a, b
    if ba >= 0:
        meet = -1
    elif meet < 0:
        return NO_PATH, np.empty((0, 2)), math.inf, expanded, frontier
    # the hops: s, the start side's chain up to meet, the goal side's back down, t
    fpar, bpar = ws[1], ws[5]
    hops, chain, stack = ws[3], ws[7], ws[2]  # the heaps and one slot row are spent
    nc = 0
    v = meet if meet >= 0 else ba
    while True:  # the start side's chain, its top first
        chain[nc] = v
        nc += 1
        if fpar[v] < 0:
            break
        v = _owner(uo, fpar[v])
    n = 0
    if cells[v] != s:
        hops[n] = s
        n += 1
    hops[n] = cells[v]
    n += 1
    for i in range(nc - 2, -1, -1):
        n = _unpack(uo, un, um, fpar[chain[i]], 0, cells, hops, n, stack)
    if meet < 0:  # through the core: the table's predecessors from ba to bb
        nc = 0
        v = bb
        while v != ba:
            chain[nc] = v
            nc += 1
            v = cnodes[ptab[cid[ba], cid[v]]]
        chain[nc] = ba
        for i in range(nc, 0, -1):
            x, y = chain[i], chain[i - 1]
            for e in range(uo[x], uo[x + 1]):
                if un[e] == y:
                    n = _unpack(uo, un, um, e, 0, cells, hops, n, stack)
                    break
        meet = bb
    v = meet
    while bpar[v] >= 0:
        n = _unpack(uo, un, um, bpar[v], 1, cells, hops, n, stack)
        v = _owner(uo, bpar[v])
    if cells[v] != t:
        hops[n] = t
        n += 1
    path, cost = _path(blk, hops, n, Wp)
    return FOUND, path, cost, expanded, frontier
