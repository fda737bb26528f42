"""Visibility graph: the exact shortest path among polygon obstacles.

A shortest path that avoids polygon interiors is a polyline whose bends sit on convex
obstacle corners (interior angle below 180 degrees), and each of its edges is tangent to
the obstacles at both ends. The graph's nodes are those corners of the union of the
obstacles; an edge joins two corners that see each other (:meth:`World.segments_free`).
Edges are checked lazily: A* puts every tangent candidate edge on its open list with
its length and tests the segment only when it pops it (:func:`lazy_astar`), and each
verdict between two corners is kept, so a graph is built once and queried many times,
and a query pays only for the few edges at the front of its search.
"""

from __future__ import annotations

import time

import numpy as np

from skyroute.result import STATUS_OF_CODE, PlanResult
from skyroute.roadmap.graph_search import lazy_astar
from skyroute.world.geometry import convex_corners
from skyroute.world.world import World


class VisibilityGraph:
    """Build once per world (and altitude), query many times with :meth:`plan`."""

    def __init__(self, world: World) -> None:
        self.world = world.merged()
        self.corners, self._prev, self._next = convex_corners(self.world)
        if world.boundary is not None and len(self.corners):
            keep = self.world.inside(self.corners)  # corners outside the boundary: useless
            self.corners, self._prev, self._next = (a[keep] for a in
                                                    (self.corners, self._prev, self._next))
        self._candidates: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        self._verdicts: dict[tuple[int, int], bool] = {}
        self.segment_tests = 0

    def _tangent_ids(self, p: np.ndarray, exclude: int = -1) -> np.ndarray:
        """Corners v where the line p->v leaves both ring neighbours of v on one side
        (only such edges can lie on a shortest path)."""
        ids = np.arange(len(self.corners))
        if exclude >= 0:
            ids = ids[ids != exclude]
        d = self.corners[ids] - p
        a = self._prev[ids] - p
        b = self._next[ids] - p
        s1 = d[:, 0] * a[:, 1] - d[:, 1] * a[:, 0]
        s2 = d[:, 0] * b[:, 1] - d[:, 1] * b[:, 0]
        return ids[s1 * s2 >= 0]

    def _corner_candidates(self, i: int) -> np.ndarray:
        """Corners that may follow corner i on a shortest path: the edge must be tangent
        at both ends (a bitangent)."""
        c = self._candidates.get(i)
        if c is None:
            u = self.corners[i]
            ids = self._tangent_ids(u, exclude=i)
            d = self.corners[ids] - u
            a, b = self._prev[i] - u, self._next[i] - u
            s1 = d[:, 0] * a[1] - d[:, 1] * a[0]
            s2 = d[:, 0] * b[1] - d[:, 1] * b[0]
            c = self._candidates[i] = ids[s1 * s2 >= 0]
        return c

    def _taut(self, i: int, p: np.ndarray, targets: np.ndarray) -> np.ndarray:
        """Keep targets v for which the path p -> corner i -> v bends around i's obstacle
        (turns towards the obstacle's side) or goes straight on: a shortest path never
        bends away from the corner it touches."""
        u = self.corners[i]
        inward = (self._prev[i] - u) / np.hypot(*(self._prev[i] - u)) + \
            (self._next[i] - u) / np.hypot(*(self._next[i] - u))
        din = u - p
        side = din[0] * inward[1] - din[1] * inward[0]
        d = targets - u
        turn = din[0] * d[:, 1] - din[1] * d[:, 0]
        return turn * side >= 0

    def checked_edges(self) -> np.ndarray:
        """(E, 2, 2) plane segments between corners that queries have checked and found
        free (the part of the graph searched so far, for plots)."""
        pairs = np.array([k for k, ok in self._verdicts.items() if ok], dtype=np.int64)
        return self.corners[pairs] if len(pairs) else np.empty((0, 2, 2))

    def plan(self, start, goal, *, max_expansions: int | None = None) -> PlanResult:
        """Exact shortest path from plane point ``start`` to ``goal`` (the plane is the
        world's; :func:`skyroute.plan` converts from and to the world's frame)."""
        w = self.world
        s = w.check_plane_point(start, "start")
        t = w.check_plane_point(goal, "goal")
        t0 = time.perf_counter()
        n = len(self.corners)
        S, T = n, n + 1
        points = np.vstack([self.corners, s, t])
        from_start = self._tangent_ids(s)
        to_goal = set(self._tangent_ids(t).tolist())
        tests = 0

        def candidates(u: int, parent: int):
            if u == S:
                ids = np.append(from_start, T)
            else:
                ids = self._corner_candidates(u)
                if u in to_goal:
                    ids = np.append(ids, T)
                ids = ids[self._taut(u, points[parent], points[ids])]
            return ids, np.hypot(*(points[ids] - points[u]).T)

        def valid(u: int, v: int) -> bool:
            nonlocal tests
            key = (min(u, v), max(u, v))
            corner_pair = key[1] < n
            if corner_pair and key in self._verdicts:
                return self._verdicts[key]
            tests += 1
            ok = w.segment_free(points[u], points[v])
            if corner_pair:
                self._verdicts[key] = ok
            return ok

        code, path, cost, expanded, frontier, _ = lazy_astar(points, S, T, candidates, valid,
                                                             max_expansions)
        seconds = time.perf_counter() - t0
        self.segment_tests += tests
        coords = points[path] if path else np.empty((0, 2))
        return PlanResult(STATUS_OF_CODE[code], coords, cost, expanded, frontier, tests,
                          seconds, "visibility",
                          {"corners": n, "known_edges": len(self._verdicts)})
