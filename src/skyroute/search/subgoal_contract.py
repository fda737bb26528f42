"""Contract a subgoal graph into a contraction hierarchy (Geisberger et al. 2008), compiled.

Large subgoal graphs (random maps: 60-90 thousand subgoals) are too big for an all-pairs
table, and A* over them, even with landmarks, expands about a thousand nodes a query. A
contraction hierarchy orders the nodes and removes them one at a time, lowest first: when
node v goes, every pair (u, w) of its remaining neighbours whose shortest path may run
u -> v -> w gets a shortcut edge u - w of that length, unless a *witness* search (Dijkstra
from u without v, bounded in length, settled nodes and hops) finds a path no longer. Every
shortest path then has an up-down form (ranks rising, then falling), so a query is two
small upward Dijkstras (see :mod:`skyroute.search.subgoal_ch_query`). This is Uras &
Koenig's SUB-CH idea: the hierarchy sits on top of the subgoal graph, not the grid.

The graph is undirected (h-reachability is symmetric and edge costs are octile
distances), so one upward edge list per node serves both directions. A bounded witness
search that gives up only adds shortcuts, so the limits trade build time and shortcut
count, never exactness. Pairs whose turn at v always has a strictly shorter way around
it (:mod:`skyroute.search.subgoal_taut`, a local test on v's cell) are no shortest path:
they need neither a shortcut nor a witness search. The order is lazy (Geisberger's "lazy
updates"): the next node's priority, edge difference plus contracted neighbours, is
recomputed when it comes to the top and it goes back if it is no longer the smallest;
its neighbours are re-estimated after each contraction. The estimates (every node's at
the start, the neighbours' after each contraction: most of the witness searches) only
read the working graph, so they run on two of numba's threads, each with its own
scratch; the order, and so the index, is the same on any thread count.

Contraction stops at a core of as many nodes as the all-pairs table holds (2048): the
last nodes are the costliest to contract (on grid-like graphs the remaining graph
grows dense) and the table answers between them without a search. The densest subgoal
graphs (random maps at 10%: 1.3 billion edge scans, 20 s to reach that core) are not
tried, or the contraction gives up at a budget of edge scans, and the landmark A*
answers there.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from skyroute.search.heap import grow, grow_rows, pop_plain, push_plain
from skyroute.search.subgoal_landmarks import edge_lengths
from skyroute.search.subgoal_table import all_pairs
from skyroute.search.subgoal_taut import edge_first_steps, free_around, shorten_table

HOPS = 6  # witness searches: edges at most
SETTLE = 60  # witness searches: nodes settled at most
SIM_HOPS = 3  # the same while only estimating a priority
SIM_SETTLE = 30
BUDGET = 120_000_000  # edges the witness searches may scan (random 512 at 30%: 96 million)
# Graphs with nodes x (mean degree)^2 above this are not tried. Boston_0_256 (0.67e6) and
# random 512 at 30% (1.04e6) contract in 75 and 96 million edge scans (86 and 98 without
# the tautness test). Random 20% (1.95e6) needs 947 million with the test also in the
# priorities, 181 million with cheaper neighbour updates too, but then builds in 4.7-6.5 s
# (over the 5 s budget); Paris_1_512 (2.5e6) 441 (25) million, its queries no faster than
# the landmark A*'s; random 10% and random512-10-0 (3.2e6) 1.3 billion or more.
# Round 6 (docs/benchmarks.md section 12): with these limits 958 of random 20%'s 1,036
# million scans are the neighbours' re-estimates, 64 million the contraction's own.
# One-hop estimates (Geisberger's early limit) with the test in them: 191 million, 3.6 s
# for the contraction and a 5.1 s build on a loaded VM (queries 1.6x faster than the
# jump index's); on random 10% 20 billion (the order collapses). Weaker contraction
# witnesses densify the graph (settle 20, hops 3: 1.07 billion); an indexed order heap,
# smaller witness state, priority weights and degree-dependent estimates did not pay.
DENSE = 1_500_000
HEAP_CAP = 1 << 14  # witness heap entries; a search that would need more gives up
SHORTEN = shorten_table()
EPS = 1e-9  # a witness this much longer still counts (lengths a + b sqrt2 differ by far more)
WORKERS = 2  # priority estimates run on this many threads, each with its own scratch
# Fewer nodes to estimate than this: one thread. A parallel region needs both threads
# scheduled at once; with the cores busy elsewhere each of the thousands of small regions
# (one a contraction) waited for a time slice: random 512 at 30% built in 17-107 s
# instead of 2 s. At 64 only the few large re-estimates are split (docs/benchmarks.md,
# section 12, "Contraction under load").
SERIAL = 64


@njit(cache=True)
def _shortcuts(v, st, ln, to, wt, dm, free, table, wd, wstamp, whop, tmark, tvia, stamp,
               hk, hn, hops, settle, su, sw, sd):
    """The shortcuts that contracting v needs: (su, sw, sd)[:count] the positions of the
    two neighbours in v's edge list and the length; returns (count, stamp after the
    searches, edges scanned). The working graph holds live nodes only; ``dm`` is each
    edge's first step directions (see :mod:`skyroute.search.subgoal_taut`).

    A pair whose turn at v always shortens locally needs neither a shortcut nor a
    witness. The witness search from u stops as soon as every remaining target w has a
    path no longer than u - v - w (on dense subgoal graphs often the direct edge u - w:
    no search beyond u's own edges), or at its limits."""
    d, s0 = ln[v], st[v]
    fv = free[v]
    count = work = 0
    for i in range(d - 1):
        u = to[s0 + i]
        stamp += 1
        bound = 0.0
        left = 0  # targets without a witness yet
        for j in range(i + 1, d):
            if table[dm[s0 + i], dm[s0 + j]] & fv:
                continue  # never a shortest path: u - v - w shortens at v
            w = to[s0 + j]
            via = wt[s0 + i] + wt[s0 + j]
            bound = max(bound, via)
            tmark[w], tvia[w] = stamp, via + EPS
            left += 1
        if left == 0:
            continue
        wd[u], wstamp[u], whop[u] = 0.0, stamp, 0
        wd[v], wstamp[v] = -1.0, stamp  # v is no way through: "seen" shorter than any
        push_plain(hk, hn, 0, 0.0, u)
        size = 1
        settled = 0
        while size > 0 and left > 0:
            k = hk[0]
            x = pop_plain(hk, hn, size)
            size = size - 1
            if k > wd[x]:
                continue  # outdated entry
            if k > bound:
                break
            settled += 1
            if settled > settle:
                break
            hx = whop[x] + 1
            work += ln[x]
            for j in range(st[x], st[x] + ln[x]):
                y = to[j]
                nd = k + wt[j]
                if nd > bound + EPS:
                    continue
                if wstamp[y] == stamp and nd >= wd[y]:
                    continue  # also v, whose distance is negative
                wd[y], wstamp[y], whop[y] = nd, stamp, hx
                if tmark[y] == stamp and nd <= tvia[y]:
                    tmark[y] = 0  # witnessed
                    left -= 1
                if hx < hops and size < hk.size:  # a node at the hop limit is not
                    push_plain(hk, hn, size, nd, y)  # expanded: needs no entry
                    size = size + 1
        for j in range(i + 1, d):
            w = to[s0 + j]
            if tmark[w] != stamp:
                continue  # pruned or witnessed
            su[count], sw[count], sd[count] = i, j, wt[s0 + i] + wt[s0 + j]
            count += 1
    return count, stamp, work


@njit(cache=True)
def _estimate_range(nodes, first, stop, step, w, st, ln, to, wt, dm, free, table, deleted,
                    wd, wstamp, whop, tmark, tvia, stamps, hk, hn, hops, settle, su, sw, sd,
                    out, work):
    """Priorities of nodes[first:stop:step] into ``out`` with worker w's scratch rows:
    shortcuts a simulated contraction would add, minus edges removed, plus contracted
    neighbours (``deleted``)."""
    for i in range(first, stop, step):
        u = nodes[i]
        count, stamps[w], scanned = _shortcuts(u, st, ln, to, wt, dm, free, table, wd[w],
                                               wstamp[w], whop[w], tmark[w], tvia[w],
                                               stamps[w], hk[w], hn[w], hops, settle,
                                               su[w], sw[w], sd[w])
        out[i] = count - ln[u] + deleted[u]
        work[w] += scanned


@njit(cache=True, parallel=True)
def _estimate_parallel(nodes, k, st, ln, to, wt, dm, free, table, deleted, wd, wstamp,
                       whop, tmark, tvia, stamps, hk, hn, hops, settle, su, sw, sd, out,
                       work):
    """:func:`_estimate_range` over nodes[:k], interleaved among WORKERS threads. The
    estimates only read the working graph, and each worker marks its searches in its
    own scratch rows, so the priorities are those of one thread."""
    for w in prange(WORKERS):
        _estimate_range(nodes, w, k, WORKERS, w, st, ln, to, wt, dm, free, table, deleted,
                        wd, wstamp, whop, tmark, tvia, stamps, hk, hn, hops, settle, su, sw,
                        sd, out, work)


@njit(cache=True)
def contract(m, offs, nbr, length, fwd, back, free, table, hops, settle, sim_hops, sim_settle,
             core, budget):
    """Contract the CSR graph (``length`` per edge, taken as undirected) down to ``core``
    uncontracted nodes. ``fwd``, ``back`` are each edge's first steps from either end,
    ``free`` the nodes' free neighbours and ``table`` the shortening table of
    :mod:`skyroute.search.subgoal_taut`.

    Returns the upward graph as CSR: (offsets (m + 1) int64, head int32, length float64,
    middle node int32 (-1 for an edge of the subgoal graph itself)), each contracted
    node's edges to the nodes contracted after it and each core node's edges to the
    other core nodes; each node's rank (-1 in the core); the edges the witness searches
    scanned. Once they scanned more than ``budget`` it gives up: the arrays are empty.
    """
    # the working graph: per node a slice [st, st + ln) of a pool with room for cp entries
    deg = np.zeros(m, np.int64)
    for u in range(m):
        for j in range(offs[u], offs[u + 1]):
            deg[u] += 1
            deg[nbr[j]] += 1
    st = np.empty(m, np.int64)
    ln = np.zeros(m, np.int64)
    cp = np.empty(m, np.int64)
    end = 0
    for u in range(m):
        st[u], cp[u] = end, max(8, deg[u])
        end += cp[u]
    to = np.empty(2 * end, np.int32)
    wt = np.empty(2 * end, np.float64)
    mid = np.empty(2 * end, np.int32)
    dm = np.empty(2 * end, np.uint8)  # per edge: the directions of its first step
    for u in range(m):
        for j in range(offs[u], offs[u + 1]):
            for side in range(2):
                a, b = (u, nbr[j]) if side == 0 else (nbr[j], u)
                found = a == b
                for e in range(st[a], st[a] + ln[a]):
                    found = found or to[e] == b
                if not found:
                    e = st[a] + ln[a]
                    to[e], wt[e], mid[e] = b, length[j], -1
                    dm[e] = fwd[j] if side == 0 else back[j]
                    ln[a] += 1
    # priority estimates ignore the tautness test: pruned pairs made nodes look cheap,
    # and that order slowed Boston_0_256's queries by about 30%
    unpruned = np.zeros_like(table)
    # witness-search scratch, a row per worker (row 0 also contracts)
    tmark = np.zeros((WORKERS, m), np.int64)
    tvia = np.zeros((WORKERS, m), np.float64)
    wd = np.zeros((WORKERS, m), np.float64)
    wstamp = np.zeros((WORKERS, m), np.int64)
    whop = np.zeros((WORKERS, m), np.int64)
    hk = np.empty((WORKERS, HEAP_CAP), np.float64)
    hn = np.empty((WORKERS, HEAP_CAP), np.int64)
    su = np.empty((WORKERS, 64), np.int64)
    sw = np.empty((WORKERS, 64), np.int64)
    sd = np.empty((WORKERS, 64), np.float64)
    stamps = np.zeros(WORKERS, np.int64)
    scans = np.zeros(WORKERS, np.int64)
    deleted = np.zeros(m, np.int64)
    rank = np.full(m, -1, np.int64)
    nb = np.empty(16, np.int64)
    nbdm = np.empty(16, np.uint8)  # per neighbour u of v: the first step of u -> v
    est = np.empty(16, np.float64)  # the neighbours' new priorities
    work = 0
    # the upward edges, appended per node as it leaves the working graph
    up_st = np.zeros(m, np.int64)
    up_ln = np.zeros(m, np.int64)
    uto = np.empty(2 * nbr.size + 64, np.int32)
    uwt = np.empty(uto.size, np.float64)
    umid = np.empty(uto.size, np.int32)
    uend = 0
    # the priority queue: lazy, an entry is current when its key equals prio[v]
    prio = np.zeros(m, np.float64)
    qk = np.empty(2 * m + 16, np.float64)
    qn = np.empty(2 * m + 16, np.int64)
    qs = 0
    n2 = 0
    for v in range(m):
        n2 = max(n2, ln[v] * ln[v])
    su, sw, sd = grow_rows(su, n2), grow_rows(sw, n2), grow_rows(sd, n2)
    _estimate_parallel(np.arange(m), m, st, ln, to, wt, dm, free, unpruned, deleted, wd,
                       wstamp, whop, tmark, tvia, stamps, hk, hn, sim_hops, sim_settle, su, sw,
                       sd, prio, scans)
    for v in range(m):
        push_plain(qk, qn, qs, prio[v], v)
        qs = qs + 1
    order = 0
    while qs > 0 and order < m - core:
        if work + scans.sum() > budget:
            e0 = np.empty(0, np.int64)
            return e0, np.empty(0, np.int32), np.empty(0), np.empty(0, np.int32), e0, work
        k = qk[0]
        v = pop_plain(qk, qn, qs)
        qs = qs - 1
        if rank[v] >= 0 or k != prio[v]:
            continue
        d = ln[v]
        su, sw, sd = grow_rows(su, d * d), grow_rows(sw, d * d), grow_rows(sd, d * d)
        count, stamps[0], w = _shortcuts(v, st, ln, to, wt, dm, free, table, wd[0], wstamp[0],
                                         whop[0], tmark[0], tvia[0], stamps[0], hk[0], hn[0],
                                         hops, settle, su[0], sw[0], sd[0])
        work += w
        p = count - d + deleted[v]
        if qs > 0 and p > qk[0]:
            prio[v] = p  # no longer the smallest: back into the queue
            qk, qn = grow(qk, qs + 1), grow(qn, qs + 1)
            push_plain(qk, qn, qs, p, v)
            qs = qs + 1
            continue
        # contract v: its edges become its upward edges and leave its neighbours' lists
        rank[v] = order
        order += 1
        uto, uwt, umid = grow(uto, uend + d), grow(uwt, uend + d), grow(umid, uend + d)
        up_st[v], up_ln[v] = uend, d
        nb, nbdm = grow(nb, d), grow(nbdm, d)
        for j in range(d):
            e = st[v] + j
            uto[uend], uwt[uend], umid[uend] = to[e], wt[e], mid[e]
            uend += 1
            u = to[e]
            nb[j] = u
            for f in range(st[u], st[u] + ln[u]):
                if to[f] == v:
                    nbdm[j] = dm[f]
                    last = st[u] + ln[u] - 1
                    to[f], wt[f], mid[f], dm[f] = to[last], wt[last], mid[last], dm[last]
                    ln[u] -= 1
                    break
            deleted[u] += 1
        ln[v] = 0
        su0, sw0, sd0 = su[0], sw[0], sd[0]
        for i in range(count):
            for side in range(2):
                p, q = (su0[i], sw0[i]) if side == 0 else (sw0[i], su0[i])
                a, b, first = nb[p], nb[q], nbdm[p]
                found = False
                for e in range(st[a], st[a] + ln[a]):
                    if to[e] == b:
                        found = True
                        if sd0[i] < wt[e]:
                            wt[e], mid[e], dm[e] = sd0[i], v, first
                        break
                if found:
                    continue
                if ln[a] == cp[a]:  # full: move to the pool's end with twice the room
                    grown = end + 2 * cp[a]
                    to, wt = grow(to, grown), grow(wt, grown)
                    mid, dm = grow(mid, grown), grow(dm, grown)
                    for j in range(ln[a]):  # a loop: see heap._copy_into
                        to[end + j], wt[end + j] = to[st[a] + j], wt[st[a] + j]
                        mid[end + j], dm[end + j] = mid[st[a] + j], dm[st[a] + j]
                    st[a], cp[a] = end, 2 * cp[a]
                    end += cp[a]
                e = st[a] + ln[a]
                to[e], wt[e], mid[e], dm[e] = b, sd0[i], v, first
                ln[a] += 1
        # the neighbours: a fresh priority each (counting only the contracted neighbour
        # and leaving the rest to the lazy updates cuts random 20%'s scans from 947 to
        # 181 million, but Boston_0_256's queries were 10-30% slower: kept)
        n2 = 0
        for i in range(d):
            n2 = max(n2, ln[nb[i]] * ln[nb[i]])
        su, sw, sd = grow_rows(su, n2), grow_rows(sw, n2), grow_rows(sd, n2)
        est = grow(est, d)
        if d < SERIAL:
            _estimate_range(nb, 0, d, 1, 0, st, ln, to, wt, dm, free, unpruned, deleted, wd,
                            wstamp, whop, tmark, tvia, stamps, hk, hn, sim_hops, sim_settle,
                            su, sw, sd, est, scans)
        else:
            _estimate_parallel(nb, d, st, ln, to, wt, dm, free, unpruned, deleted, wd, wstamp,
                               whop, tmark, tvia, stamps, hk, hn, sim_hops, sim_settle, su, sw,
                               sd, est, scans)
        for i in range(d):
            u = nb[i]
            prio[u] = est[i]
            qk, qn = grow(qk, qs + 1), grow(qn, qs + 1)
            push_plain(qk, qn, qs, prio[u], u)
            qs = qs + 1
    # the core: nodes left uncontracted keep their edges among themselves
    for v in range(m):
        if rank[v] < 0:
            d = ln[v]
            uto, uwt, umid = grow(uto, uend + d), grow(uwt, uend + d), grow(umid, uend + d)
            up_st[v], up_ln[v] = uend, d
            for e in range(st[v], st[v] + d):
                uto[uend], uwt[uend], umid[uend] = to[e], wt[e], mid[e]
                uend += 1
    uo = np.zeros(m + 1, np.int64)
    for v in range(m):
        uo[v + 1] = uo[v] + up_ln[v]
    un = np.empty(uo[m], np.int32)
    uw = np.empty(uo[m], np.float64)
    um = np.empty(uo[m], np.int32)
    for v in range(m):
        a, n = up_st[v], up_ln[v]
        un[uo[v]:uo[v] + n] = uto[a:a + n]
        uw[uo[v]:uo[v] + n] = uwt[a:a + n]
        um[uo[v]:uo[v] + n] = umid[a:a + n]
    return uo, un, uw, um, rank, work + scans.sum()


def hierarchy(blk: np.ndarray, cells: np.ndarray, offs: np.ndarray, nbr: np.ndarray,
              Wp: int, core: int) -> dict | None:
    """The index arrays of a hierarchy over a subgoal graph, contracted down to ``core``
    nodes: the upward graph ``ch_offs``, ``ch_nbr``, ``ch_len``, ``ch_mid`` (see
    :func:`contract`), ``ch_core`` (each node's core number, -1 if contracted) and the
    core's all-pairs ``ch_dist`` (float64) and ``ch_pred`` (int16). None when
    the contraction would scan more than BUDGET edges (dense graphs: the build would take
    too long), or without trying when nodes x mean degree squared exceeds DENSE."""
    if nbr.size ** 2 > DENSE * max(cells.size, 1):
        return None
    length = edge_lengths(cells, offs, nbr, Wp)
    fwd, back = edge_first_steps(blk, Wp, cells, offs, nbr)
    uo, un, uw, um, rank, _ = contract(cells.size, offs, nbr, length, fwd, back,
                                       free_around(cells, blk, Wp), SHORTEN, HOPS, SETTLE,
                                       SIM_HOPS, SIM_SETTLE, core, BUDGET)
    if uo.size == 0:
        return None
    cnodes = np.flatnonzero(rank < 0)
    k = cnodes.size
    cid = np.full(rank.size, -1, np.int32)
    cid[cnodes] = np.arange(k, dtype=np.int32)
    # the core's own graph (each core node's edges lead to core nodes) and its table
    coffs = np.zeros(k + 1, np.int64)
    coffs[1:] = np.cumsum(uo[cnodes + 1] - uo[cnodes])
    idx = np.concatenate([np.arange(uo[v], uo[v + 1]) for v in cnodes] + [[]]).astype(int)
    dist, pred = all_pairs(coffs, cid[un[idx]], uw[idx])
    return {"ch_offs": uo, "ch_nbr": un, "ch_len": uw, "ch_mid": um, "ch_core": cid,
            "ch_dist": dist, "ch_pred": pred}
