"""A lazy binary min-heap for the subgoal-graph query, inlined into its kernel.

Entries are (f, g, node) in three flat arrays; smaller f first, and among equal f the
larger g (the node nearer the goal), which cuts expansions on open maps. "Lazy": a node
whose g improves is pushed again instead of moving its entry, and the query skips
entries of nodes already closed. A graph search pushes at most once per edge relaxation,
so the arrays are sized once per index (edges + 2 x nodes) and never grow. Unlike the
grid searches' indexed heap (search/heap.py) it needs no per-node slot array to keep up,
and every helper is inlined, since the small maps' queries are a few microseconds long
and a compiled call that passes several arrays costs about 0.1 us.
"""

from __future__ import annotations

from numba import njit


@njit(cache=True, inline="always")
def _before(hf, hg, i, f, g):
    """True when entry i comes strictly before (f, g)."""
    return hf[i] < f or (hf[i] == f and hg[i] > g)


@njit(cache=True, inline="always")
def push(hf, hg, hn, size, f, g, node):
    """Insert (f, g, node); return the new size."""
    i = size
    while i > 0:
        p = (i - 1) >> 1
        if _before(hf, hg, p, f, g):
            break
        hf[i], hg[i], hn[i] = hf[p], hg[p], hn[p]
        i = p
    hf[i], hg[i], hn[i] = f, g, node
    return size + 1


@njit(cache=True, inline="always")
def pop(hf, hg, hn, size):
    """Remove the first entry; return (its node, the new size)."""
    top = hn[0]
    size -= 1
    if size > 0:
        f, g, node = hf[size], hg[size], hn[size]
        i = 0
        while True:
            b = 2 * i + 1
            if b >= size:
                break
            if b + 1 < size and _before(hf, hg, b + 1, hf[b], hg[b]):
                b += 1
            if not _before(hf, hg, b, f, g):
                break
            hf[i], hg[i], hn[i] = hf[b], hg[b], hn[b]
            i = b
        hf[i], hg[i], hn[i] = f, g, node
    return top, size
