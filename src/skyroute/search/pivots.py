"""Differential heuristics from a few pivot cells, and the prepared JPS that uses them.

For a pivot p the triangle inequality gives ``d(n, t) >= |d(p, n) - d(p, t)|`` (grid
distances are symmetric), so the largest of these bounds and the octile distance is an
admissible and consistent heuristic (Sturtevant et al.'s differential heuristic, ALT on
the grid cells rather than on a graph). It sharpens the octile guess most where paths
wind round scattered obstacles, which is where an online search expands most. The
pivots are chosen farthest first within the largest free region; the distances are
float64 (as exact as the octile distance) and node-major, so one node's bounds share
two (16 pivots) or three (24) cache lines.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from skyroute.result import NO_PATH
from skyroute.search import heap
from skyroute.search.astar import astar_kernel
from skyroute.search.cache_lines import aligned_empty
from skyroute.search.canonical import CANONICAL
from skyroute.search.jps import jps_kernel
from skyroute.search.space import workspace

MAX_EXPANSIONS = 1 << 62
PIVOTS = 16  # 16 x 8 bytes a cell: 34 MB for 512 x 512 (section 12 of the benchmarks)
# Where no contraction hierarchy was built (graphs too dense to contract, the jump index
# alone), the build has time for more pivots: 24 (51 MB for 512 x 512) answer random
# 512 maps at 10-20% blocked about a tenth faster (section 12, round 9).
DENSE_PIVOTS = 24


def distances_from(mask: np.ndarray, Wp: int, source: int, ws: tuple) -> np.ndarray:
    """Each padded cell's distance from flat cell ``source`` (inf: unreachable): the
    A* kernel as Dijkstra (h = 0, canonical successors, which keep an optimal path to
    every cell) run to exhaustion towards the blocked border cell 0; every cell it
    touched was expanded, with its final g. ``ws``: a :func:`space.workspace`."""
    floats, ints, keys = ws
    # f = g here, below sqrt 2 a padded cell (SearchSpace.f_bound's bound, h = 0)
    fs = heap.f_scale(mask.size * math.sqrt(2.0))
    _, expanded, _, _, _ = astar_kernel(mask, CANONICAL, Wp, source, 0, 0, 1.0,
                                        MAX_EXPANSIONS, floats, ints, keys, fs)
    out = np.full(mask.size, np.inf)
    reached = ints[2][:expanded]
    out[reached] = floats[0][reached]
    return out


def largest_region(label: np.ndarray) -> np.ndarray:
    """The flat cells of the largest free region (``label``: each padded cell's region,
    -1 blocked); empty when no cell is free."""
    free = label >= 0
    if not free.any():
        return np.empty(0, np.int64)
    return np.flatnonzero(label == np.argmax(np.bincount(label[free])))


def pivot_distances(mask: np.ndarray, label: np.ndarray, Wp: int,
                    count: int = PIVOTS) -> np.ndarray:
    """(cells, count) float64 distances from ``count`` pivots chosen farthest first in
    the largest free region (:func:`largest_region`); inf where a pivot cannot reach.
    (cells, 0) when the grid has no free cell."""
    region = largest_region(label)
    if not region.size:
        return np.empty((mask.size, 0))
    count = min(count, region.size)
    out = aligned_empty((mask.size, count))  # rows on cache lines: see cache_lines
    ws = workspace(mask.size)
    nearest = distances_from(mask, Wp, int(region[0]), ws)
    for j in range(count):
        p = int(region[np.argmax(nearest[region])])
        out[:, j] = distances_from(mask, Wp, p, ws)
        nearest = np.minimum(nearest, out[:, j])
    return out


@njit(cache=True)
def jump_query(mask, succ, table, label, piv, floats, ints, keys, fs, Wp, s, t):
    """One exact query from flat cell s to t for a prepared index: the component labels
    answer "no path" at once, else JPS with the pivots' bounds (``fs``: the keys'
    unit of f, :meth:`SearchSpace.f_scale` with pivots). Returns (code, path
    (k, 2) cells, cost, expanded, max_frontier), as the subgoal queries do."""
    if label[s] != label[t]:
        return NO_PATH, np.empty((0, 2)), math.inf, 0, 0
    code, expanded, frontier, path, cost = jps_kernel(mask, succ, table, Wp, s, t,
                                                      MAX_EXPANSIONS, floats, ints, keys, piv,
                                                      fs)
    # same labels, so the kernel reaches t; were it not, its path is empty and cost inf
    return code, path, cost, expanded, frontier
