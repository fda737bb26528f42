"""Differential heuristics from a few pivot cells, and the prepared JPS that uses them.

For a pivot p the triangle inequality gives ``d(n, t) >= |d(p, n) - d(p, t)|`` (grid
distances are symmetric), so the largest of these bounds and the octile distance is an
admissible and consistent heuristic (Sturtevant et al.'s differential heuristic, ALT on
the grid cells rather than on a graph). It sharpens the octile guess most where paths
wind round scattered obstacles, which is where an online search expands most. The
pivots are chosen farthest first within the largest free region; the distances are
float64 (as exact as the octile distance) and node-major, so one node's bounds share
one or two cache lines.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from skyroute.result import FOUND, NO_PATH
from skyroute.search import heap
from skyroute.search.jps import jps_kernel
from skyroute.search.moves import COSTS, offsets
from skyroute.search.space import to_cells

MAX_EXPANSIONS = 1 << 62
PIVOTS = 16  # 16 x 8 bytes a cell: 34 MB for 512 x 512 (section 12 of the benchmarks)


@njit(cache=True)
def distances_from(mask, Wp, source, out, col):
    """Dijkstra from flat cell ``source`` over the move mask (8-connected, no corner
    cutting); ``out[:, col]`` receives each cell's distance (inf: unreachable). The
    heap's keys are quantised to 2**-20 cells, which cannot reorder the settling: every
    step costs at least 1."""
    n = mask.size
    offs = offsets(Wp)
    state = np.zeros(n, np.int32)
    hc = np.empty(n, np.int32)
    hk = np.empty(n, np.int64)
    for c in range(n):
        out[c, col] = math.inf
    out[source, col] = 0.0
    size = heap.push(hc, hk, state, 0, source, heap.key(0.0, 0.0))
    while size > 0:
        c, size = heap.pop(hc, hk, state, size)
        dc = out[c, col]
        m = mask[c]
        for k in range(8):
            if not (m >> k) & 1:
                continue
            nb = c + offs[k]
            if state[nb] < 0:
                continue
            d = dc + COSTS[k]
            if d < out[nb, col]:
                out[nb, col] = d
                size = heap.push(hc, hk, state, size, nb, heap.key(d, 0.0))
    return out


def pivot_distances(mask: np.ndarray, label: np.ndarray, Wp: int,
                    count: int = PIVOTS) -> np.ndarray:
    """(cells, count) float64 distances from ``count`` pivots chosen farthest first in
    the largest free region (``label``: each padded cell's region, -1 blocked); inf
    where a pivot cannot reach. (cells, 0) when the grid has no free cell."""
    free = label >= 0
    if not free.any():
        return np.empty((mask.size, 0))
    largest = np.argmax(np.bincount(label[free]))
    region = np.flatnonzero(label == largest)
    count = min(count, region.size)
    out = np.empty((mask.size, count))
    seed = np.empty((mask.size, 1))
    nearest = distances_from(mask, Wp, int(region[0]), seed, 0)[:, 0]
    for j in range(count):
        p = int(region[np.argmax(nearest[region])])
        distances_from(mask, Wp, p, out, j)
        nearest = np.minimum(nearest, out[:, j])
    return out


@njit(cache=True)
def jump_query(mask, succ, table, label, piv, floats, ints, keys, Wp, s, t):
    """One exact query from flat cell s to t for a prepared index: the component labels
    answer "no path" at once, else JPS with the pivots' bounds. Returns (code, path
    (k, 2) cells, cost, expanded, max_frontier), as the subgoal queries do."""
    if label[s] != label[t]:
        return NO_PATH, np.empty((0, 2)), math.inf, 0, 0
    code, expanded, frontier, flat = jps_kernel(mask, succ, table, Wp, s, t, MAX_EXPANSIONS,
                                                floats, ints, keys, piv)
    if code != FOUND:  # not reached: the labels put both ends in one region
        return code, np.empty((0, 2)), math.inf, expanded, frontier
    path, cost = to_cells(flat, Wp)
    return code, path, cost, expanded, frontier
