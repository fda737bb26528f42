"""All-pairs distances over a small subgoal graph: prepared queries without a search.

On small maps a query's graph search is most of its few microseconds. With m subgoals,
a table of the m x m graph distances (a compiled Dijkstra from every subgoal, with its
predecessor matrix for the hops) turns a query into a minimum over the start's and the
goal's direct subgoals: ``oct(s, a) + D[a, b] + oct(b, t)``. The table is exact (graph
distances equal the grid's), and kept only while it is small: ``TABLE_MAX`` subgoals
(2048: 32 MB of float64 distances and 8 MB of int16 predecessors at most).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from skyroute.result import FOUND, NO_PATH
from skyroute.search.heap import indexed_pop, indexed_up
from skyroute.search.subgoal_build import direct_subgoals
from skyroute.search.subgoal_landmarks import edge_lengths
from skyroute.search.subgoal_query import _oct, _path, direct_answer

TABLE_MAX = 2048


def distance_table(cells: np.ndarray, offs: np.ndarray, nbr: np.ndarray,
                   Wp: int) -> tuple[np.ndarray, np.ndarray]:
    """(dist (m, m) float64, pred (m, m) int16) for a graph of at most TABLE_MAX
    subgoals: ``pred[a, b]`` is b's predecessor on a shortest a -> b path (-1: none);
    two empty (0, 0) arrays for a larger graph."""
    m = cells.size
    if m == 0 or m > TABLE_MAX:
        return np.empty((0, 0)), np.empty((0, 0), np.int16)
    return all_pairs(offs, nbr, edge_lengths(cells, offs, nbr, Wp))

@njit(cache=True)
def table_query(blk, sg, clr, label, cells, dist, pred, ws, Wp, s, t):
    """One exact query from flat cell s to flat cell t through the table; ``ws`` (3,
    m + 2) int64 is scratch (start list, goal list, hops). Returns the same tuple as
    :func:`~skyroute.search.subgoal_query.subgoal_query` (``expanded`` counts the
    (start, goal) subgoal pairs tried)."""
    code, path, cost = direct_answer(blk, clr, label, ws[2], Wp, s, t)
    if code >= 0:
        return code, path, cost, 0, 0
    slist, glist, hops = ws[0], ws[1], ws[2]
    if sg[s] >= 0:
        slist[0], ns = sg[s], 1
    else:
        ns = direct_subgoals(blk, sg, clr, s, Wp, slist, 0)
    if sg[t] >= 0:
        glist[0], ng = sg[t], 1
    else:
        ng = direct_subgoals(blk, sg, clr, t, Wp, glist, 0)
    sx, sy, tx, ty = s % Wp, s // Wp, t % Wp, t // Wp
    best, ba, bb = math.inf, -1, -1
    for j in range(ng):  # goal side first: its octile part is shared by the inner loop
        b = glist[j]
        cb = _oct(cells[b] % Wp - tx, cells[b] // Wp - ty)
        for i in range(ns):
            a = slist[i]
            c = dist[a, b] + cb + _oct(cells[a] % Wp - sx, cells[a] // Wp - sy)
            if c < best:
                best, ba, bb = c, a, b
    if ba < 0:
        return NO_PATH, np.empty((0, 2)), math.inf, ns * ng, 0
    n = 0  # the hops t, b ... a, s backwards (t or s left out when it is b or a itself)
    if cells[bb] != t:
        hops[n] = t
        n += 1
    v = bb
    while True:
        hops[n] = cells[v]
        n += 1
        if v == ba:
            break
        v = pred[ba, v]
    if cells[ba] != s:
        hops[n] = s
        n += 1
    for i in range(n // 2):  # reversed in place (a slice assignment compiles for seconds)
        hops[i], hops[n - 1 - i] = hops[n - 1 - i], hops[i]
    path, cost = _path(blk, hops, n, Wp)
    return FOUND, path, cost, ns * ng, 0

ROW_SETS = 8  # all_pairs: sets of sources, shared out among numba's threads


@njit(cache=True)
def _rows(offs, nbr, length, dist, pred, first, step):
    """Dijkstra from the sources first, first + step, ... into their rows of ``dist`` and
    ``pred``, with one indexed heap (a node moves up when its distance drops: at most n
    entries)."""
    n = offs.size - 1
    hk = np.empty(n)
    hn = np.empty(n, np.int64)
    pos = np.full(n, -1, np.int64)  # heap slot, -1 outside, -2 settled (per source)
    for s in range(first, n, step):
        d, p = dist[s], pred[s]
        pos[:] = -1
        d[s] = 0.0
        hk[0], hn[0], pos[s] = 0.0, s, 0
        size = 1
        while size > 0:
            u, k = hn[0], hk[0]
            pos[u] = -2
            u, size = indexed_pop(hk, hn, pos, size)
            for j in range(offs[u], offs[u + 1]):
                v = nbr[j]
                nd = k + length[j]
                if nd >= d[v]:
                    continue
                d[v], p[v] = nd, u
                i = pos[v]
                if i < 0:
                    i = size
                    size += 1
                indexed_up(hk, hn, pos, i, nd, v)


@njit(cache=True, parallel=True)
def all_pairs(offs, nbr, length):
    """(dist (n, n) float64, pred (n, n) int16) of a CSR graph with n <= 32767 nodes, by
    a compiled Dijkstra from every node (-1: no predecessor). The rows are independent:
    numba's threads take ROW_SETS interleaved sets of sources (the same table on any
    thread count)."""
    n = offs.size - 1
    dist = np.full((n, n), np.inf)
    pred = np.full((n, n), -1, np.int16)
    for t in prange(ROW_SETS):
        _rows(offs, nbr, length, dist, pred, np.int64(t), np.int64(ROW_SETS))
    return dist, pred
