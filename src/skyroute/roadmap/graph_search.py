"""A* over a roadmap whose edges are checked lazily (plain Python heapq: roadmaps have
thousands of nodes, not millions, and edge checks dominate the time).

Open-list entries are edges (u -> v) with the optimistic cost g(u) + |uv|; an edge is
checked (``valid(u, v)``) only when it is popped, as in Lazy A* / LazySP. Every path
returned consists of checked edges, and it is optimal: an unchecked edge only ever
under-estimates, and a popped, valid edge to an unclosed node is the best way there.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Callable

import numpy as np


def lazy_astar(points: np.ndarray, start: int, goal: int,
               candidates: Callable[[int, int], tuple[np.ndarray, np.ndarray]],
               valid: Callable[[int, int], bool], max_expansions: int | None = None):
    """Euclidean A* from node ``start`` to ``goal``.

    ``candidates(u, parent)`` returns (node ids, edge lengths) that may be edges out of
    u, reached from ``parent`` (u itself for the start); ``valid(u, v)`` decides.
    Returns (status code, node path, cost, expanded, max_frontier, checks) with codes
    0 found, 1 no path, 2 budget exhausted.
    """
    gx, gy = points[goal]

    def h(v: int) -> float:
        return math.hypot(points[v][0] - gx, points[v][1] - gy)

    parent = {start: start}
    closed = set()
    heap = [(h(start), -0.0, start, start)]  # (f, -g: deeper first on ties, node, parent)
    expanded = checks = 0
    frontier = 1
    budget = math.inf if max_expansions is None else max_expansions
    while heap:
        _, neg_g, v, u = heapq.heappop(heap)
        gv = -neg_g
        if v in closed:
            continue
        if u != v:
            checks += 1
            if not valid(u, v):
                continue
        parent[v] = u
        if v == goal:
            path = [v]
            while path[-1] != start:
                path.append(parent[path[-1]])
            return 0, path[::-1], gv, expanded, frontier, checks
        if expanded >= budget:
            return 2, [], math.inf, expanded, frontier, checks
        closed.add(v)
        expanded += 1
        ids, lengths = candidates(v, u)
        for w, d in zip(ids.tolist(), lengths.tolist(), strict=True):
            if w not in closed:
                gw = gv + d
                heapq.heappush(heap, (gw + h(w), -gw, w, v))
        frontier = max(frontier, len(heap))
    return 1, [], math.inf, expanded, frontier, checks
