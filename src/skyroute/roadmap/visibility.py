"""Visibility graph: the exact shortest path among polygon obstacles.

A shortest path that avoids polygon interiors is a polyline whose bends sit on convex
obstacle corners (interior angle below 180 degrees), and each of its edges is tangent to
the obstacles at both ends. The graph's nodes are those corners of the union of the
obstacles; an edge joins two corners that see each other. The graph is built eagerly,
once per world: every bitangent pair of corners is tested by the compiled sight test of
:mod:`skyroute.roadmap.sight_kernels` (shapely settles the few cases within rounding of
a touch), the free ones become a CSR adjacency, and scipy labels its connected
components. A city's graph is kept on disk (:mod:`skyroute.roadmap.visibility_cache`).

A query connects its start and goal to the corners they see (tangent, free), answers
"no path" at once when no corner seen from the start shares a component with one seen
from the goal (different free regions), and otherwise runs the compiled A* of
:mod:`skyroute.roadmap.corner_search`.
"""

from __future__ import annotations

import time

import numpy as np
import shapely
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from skyroute.errors import budget
from skyroute.result import STATUS_OF_CODE, PlanResult
from skyroute.roadmap import sight_kernels as sk
from skyroute.roadmap.corner_search import corner_astar
from skyroute.roadmap.visibility_cache import graph_key, load_graph, save_graph
from skyroute.world.geometry import convex_corners
from skyroute.world.world import World

SAVE_AFTER = 0.1  # seconds: with cache=None, keep graphs that took longer to build


class VisibilityGraph:
    """Build once per world (and altitude), query many times with :meth:`plan`.

    ``cache``: True reads the graph from the disk cache (``$SKYROUTE_CACHE``) or builds
    and writes it there; False neither reads nor writes; None (the default) reads, and
    writes graphs whose build took longer than :data:`SAVE_AFTER` seconds.
    ``build_seconds`` says how long this graph took to build or read; ``from_cache``
    whether it came from disk.
    """

    def __init__(self, world: World, *, cache: bool | None = None) -> None:
        t0 = time.perf_counter()
        key = graph_key(world) if cache is not False else None
        stored = load_graph(key) if key else None
        self.from_cache = stored is not None
        if stored is None:
            polygons, arrays = _build(world)
        else:
            polygons, arrays = stored
        self.world = World(polygons, np.full(len(polygons), -np.inf),
                           np.full(len(polygons), np.inf), tuple(arrays["names"].tolist()),
                           world.boundary, world.frame, world.home, world.name)
        self.corners, self._prev, self._next = arrays["corners"], arrays["prev"], \
            arrays["next"]
        self._indptr, self._indices, self._weights = arrays["indptr"], arrays["indices"], \
            arrays["weights"]
        self.labels = arrays["labels"]
        self._index = sk.edge_index(polygons)
        self._convex_boundary = _convex(world.boundary)
        self.build_seconds = time.perf_counter() - t0
        if key and stored is None and (cache or self.build_seconds > SAVE_AFTER):
            save_graph(key, polygons, arrays)

    @property
    def edge_count(self) -> int:
        """Free bitangent edges between corners."""
        return len(self._indices) // 2

    def edge_segments(self) -> np.ndarray:
        """(E, 2, 2) plane segments of the graph's edges (for plots)."""
        rows = np.repeat(np.arange(len(self.corners)), np.diff(self._indptr))
        keep = rows < self._indices
        return np.stack([self.corners[rows[keep]], self.corners[self._indices[keep]]], axis=1)

    def free(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Exact (shapely's) verdict for each segment a[k] -> b[k]: it meets no obstacle
        interior and lies strictly inside the boundary."""
        return _free(self.world, self._index, self._convex_boundary, a, b)

    def _seen(self, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Corners point p sees along a tangent: (ids, distances)."""
        ids = sk.tangent_ids(p[0], p[1], self.corners, self._prev, self._next)
        ids = ids[self.free(np.broadcast_to(p, (len(ids), 2)), self.corners[ids])]
        return ids, np.hypot(*(self.corners[ids] - p).T)

    def plan(self, start, goal, *, max_expansions: int | None = None) -> PlanResult:
        """Exact shortest path from plane point ``start`` to ``goal`` (the plane is the
        world's; :func:`skyroute.plan` converts from and to the world's frame)."""
        limit = budget(max_expansions)  # checked first: also when no search runs
        w = self.world
        s = w.check_plane_point(start, "start")
        t = w.check_plane_point(goal, "goal")
        t0 = time.perf_counter()
        n = len(self.corners)
        extra = {"corners": n, "edges": self.edge_count}
        direct = float(np.hypot(*(t - s)))
        if self.free(s[None], t[None])[0]:
            return PlanResult(STATUS_OF_CODE[0], np.array([s, t]), direct, 0, 1, 1,
                              time.perf_counter() - t0, "visibility", extra)
        from_s, len_s = self._seen(s)
        to_t, len_t = self._seen(t)
        tests = 1 + len(from_s) + len(to_t)
        if not np.intersect1d(self.labels[from_s], self.labels[to_t]).size:
            return PlanResult(STATUS_OF_CODE[1], np.empty((0, 2)), np.inf, 0, 0, tests,
                              time.perf_counter() - t0, "visibility", extra)
        goal_len = np.full(n, np.inf)
        goal_len[to_t] = len_t
        code, nodes, cost, expanded, frontier = corner_astar(
            self.corners, self._indptr, self._indices, self._weights, from_s, len_s,
            goal_len, s[0], s[1], t[0], t[1], limit)
        coords = np.vstack([self.corners, s, t])[nodes] if len(nodes) else np.empty((0, 2))
        return PlanResult(STATUS_OF_CODE[code], coords, float(cost), int(expanded),
                          int(frontier), tests, time.perf_counter() - t0, "visibility", extra)


def _convex(boundary) -> bool:
    """True without a boundary or with a convex one (no hole): a segment between points
    strictly inside it then lies strictly inside it."""
    if boundary is None:
        return True
    b = shapely.Polygon(boundary)
    return not b.interiors and b.convex_hull.area <= b.area * (1 + 1e-12)


def _free(world: World, index: sk.EdgeIndex, convex_boundary: bool, a, b) -> np.ndarray:
    """Segments a[k] -> b[k] free: the compiled test, shapely where it is unsure, and
    the boundary (when not convex: ends strictly inside are then not enough)."""
    a = np.ascontiguousarray(a, dtype=float).reshape(-1, 2)
    b = np.ascontiguousarray(b, dtype=float).reshape(-1, 2)
    codes = sk.segment_codes(a, b, *index.args(), *sk.scratch(index))
    ok = codes == sk.FREE
    unsure = np.flatnonzero(codes == sk.UNSURE)
    if len(unsure):
        ok[unsure] = world.segments_free(a[unsure], b[unsure])
    if not convex_boundary and ok.any():
        k = np.flatnonzero(ok)
        ok[k] = world.segments_free(a[k], b[k])
    return ok


def _build(world: World) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The merged obstacles and the graph's arrays: corners with their ring neighbours,
    the CSR adjacency of free bitangent edges (both directions) and component labels."""
    merged = world.merged()
    corners, prev, nxt = convex_corners(merged)
    if world.boundary is not None and len(corners):
        keep = merged.inside(corners)  # corners outside the boundary: useless
        corners, prev, nxt = corners[keep], prev[keep], nxt[keep]
    corners, prev, nxt = (np.ascontiguousarray(x, dtype=float).reshape(-1, 2)
                          for x in (corners, prev, nxt))
    n = len(corners)
    index = sk.edge_index(merged.obstacles)
    i, j = sk.corner_pairs(corners, prev, nxt)
    same = np.all(corners[i] == corners[j], axis=1)  # two obstacles meeting at a corner
    ok = same.copy()
    ok[~same] = _free(merged, index, _convex(world.boundary), corners[i[~same]],
                      corners[j[~same]])
    i, j = i[ok], j[ok]
    rows, cols = np.r_[i, j], np.r_[j, i]
    order = np.lexsort((cols, rows))
    rows, cols = rows[order], cols[order]
    indptr = np.searchsorted(rows, np.arange(n + 1)).astype(np.int64)
    weights = np.hypot(*(corners[cols] - corners[rows]).T)
    adjacency = csr_matrix((np.ones(len(cols)), cols, indptr), shape=(n, n))
    labels = connected_components(adjacency, directed=False)[1] if n else np.empty(0)
    names = np.array(merged.names if len(merged.names) else [], dtype=str)
    return merged.obstacles, {"corners": corners, "prev": prev, "next": nxt,
                              "indptr": indptr, "indices": cols.astype(np.int64),
                              "weights": weights, "labels": labels.astype(np.int64),
                              "names": names}
