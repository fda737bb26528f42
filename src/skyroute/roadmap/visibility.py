"""Visibility graph: the exact shortest path among polygon obstacles.

A shortest path that avoids polygon interiors is a polyline whose bends sit on convex
obstacle corners (interior angle below 180 degrees) and, inside a boundary that is not
convex, on its reflex corners (and its holes' convex ones); each of its edges is tangent
at both ends. The graph's nodes are those corners of the union of the obstacles and of
the boundary; an edge joins two corners that see each other. Paths must stay strictly
inside the boundary, so a bend at one of its corners is taken :data:`INSET` of the
world's size inside it (:func:`bend_points`): the path is longer than the infimum, which
touches the corner, by about that much. The graph is built eagerly,
once per world: every bitangent pair of corners is tested by the compiled sight test of
:mod:`skyroute.roadmap.sight_kernels` (shapely settles the few cases within rounding of
a touch), the free ones become a CSR adjacency, and scipy labels its connected
components. A city's graph is kept on disk (:mod:`skyroute.roadmap.visibility_cache`).

A query connects its start and goal to the corners they see (tangent, free), answers
"no path" at once when no corner seen from the start shares a component with one seen
from the goal (different free regions), and otherwise runs the compiled A* of
:mod:`skyroute.roadmap.corner_search`.

The build tests about n * n / 8 pairs of its n corners, so a world of more than
:data:`MAX_CORNERS` is refused (:func:`check_size`) before that part starts. Measured on
``skyroute synth-city`` (2 cores): 8,363 corners (``--blocks 30``) built in 5 s with a
peak of 0.8 GB, 14,885 (``--blocks 40``) in 21 s and 1.9 GB, and about 23,000
(``--blocks 50``) ran out of 4 GB; the FCND city has 3,347 (1.3 s).
"""

from __future__ import annotations

import time

import numpy as np
import shapely
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from skyroute.errors import OptionError, budget
from skyroute.result import STATUS_OF_CODE, PlanResult
from skyroute.roadmap import sight_kernels as sk
from skyroute.roadmap.corner_search import corner_astar
from skyroute.roadmap.visibility_cache import graph_key, load_graph, save_graph
from skyroute.world.geometry import boundary_corners, convex_corners
from skyroute.world.prepared_lock import LOCK
from skyroute.world.world import World

MAX_CORNERS = 10_000  # about 12 million pairs tested: 1 GB and 8 s (see above)
SAVE_AFTER = 0.1  # seconds: with cache=None, keep graphs that took longer to build
INSET = 1e-9  # a bend at a boundary corner, inside it: this times the boundary's size


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
                           world.boundary, world.frame, world.home, world.name, world.source)
        # tangents are tested at the corners themselves, paths bend at bend points
        self._at, self._prev, self._next = arrays["corners"], arrays["prev"], arrays["next"]
        self.corners = bend_points(world, self._at, self._prev, self._next)
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

    def edge_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Every free edge in both directions: corner ids ``i``, ``j`` and lengths."""
        rows = np.repeat(np.arange(len(self.corners)), np.diff(self._indptr))
        return rows, self._indices, self._weights

    def edge_segments(self) -> np.ndarray:
        """(E, 2, 2) plane segments of the graph's edges (for plots)."""
        rows, cols, _ = self.edge_arrays()
        keep = rows < cols
        return np.stack([self.corners[rows[keep]], self.corners[cols[keep]]], axis=1)

    def free(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Exact (shapely's) verdict for each segment a[k] -> b[k]: it meets no obstacle
        interior and lies strictly inside the boundary."""
        return _free(self.world, self._index, self._convex_boundary, a, b)

    def _seen(self, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Corners point p sees along a tangent: (ids, distances)."""
        ids = sk.tangent_ids(p[0], p[1], self._at, self._prev, self._next)
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
        if self.free(s[None], t[None])[0]:  # start == goal: one point, as every planner
            path = np.array([s, t]) if direct else s[None].copy()
            return PlanResult(STATUS_OF_CODE[0], path, direct, 0, 1, 1,
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


def check_size(world: World) -> None:
    """An OptionError naming the world (its file) when its visibility graph would have
    more than :data:`MAX_CORNERS` corners, so commands that build one on a city can
    refuse it before any other work."""
    _refuse(world, fewest_corners(world), at_least=True)
    _refuse(world, len(_corners(world, world.merged())[0]))


def fewest_corners(world: World) -> int:
    """A lower bound on the convex corners of the merged obstacles, without their union
    (which took 9 s on 35,000 boxes): each group of overlapping or touching obstacles
    merges into polygons with at least three. 0 with a boundary (corners outside it may
    be dropped)."""
    n = len(world.obstacles)
    if world.boundary is not None or n == 0:
        return 0
    tree = world.tree
    with LOCK:  # the obstacles are prepared, and tested through that form
        i, j = tree.query(world.obstacles, predicate="intersects")
    touching = csr_matrix((np.ones(len(i)), (i, j)), shape=(n, n))
    return 3 * connected_components(touching, directed=False)[0]


def refuse_corners(world: World, corners: int, *, limit: int, table: str, instead: str,
                   at_least: bool = False, param: str | None = None) -> None:
    """An OptionError naming the world (its file) when ``corners`` (``at_least``: a lower
    bound) are more than ``limit`` for ``table``, a build over every pair of them;
    ``instead`` says what to do, ``param`` the parameter that chose ``table``."""
    if corners > limit:
        many = f"at least {corners:,}" if at_least else f"{corners:,}"
        raise OptionError(f"{world.where}: {many} obstacle corners, over the limit of "
                          f"{limit:,} for {table} (built over every pair of them); "
                          f"{instead}, or plan at an altitude that keeps fewer obstacles",
                          param=param)


def _refuse(world: World, corners: int, *, at_least: bool = False) -> None:
    refuse_corners(world, corners, limit=MAX_CORNERS, table="the visibility graph",
                   instead="plan with prm or on a grid (theta, astar)", at_least=at_least,
                   param="algorithm")


def _corners(world: World, merged: World) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The convex corners of the merged obstacles (inside the boundary, when there is
    one) and the boundary's corners where a path may bend (those whose bend point is
    free), with their ring neighbours."""
    corners, prev, nxt = convex_corners(merged)
    if world.boundary is not None:
        keep = merged.inside(corners)  # corners outside the boundary: useless
        more = boundary_corners(world.boundary)
        bend = bend_points(world, *more)
        free = merged.is_free(bend) if len(bend) else np.empty(0, bool)
        corners, prev, nxt = (np.concatenate([a[keep], b[free]])
                              for a, b in zip((corners, prev, nxt), more, strict=True))
    return corners, prev, nxt


def bend_points(world: World, corners: np.ndarray, prev: np.ndarray,
                nxt: np.ndarray) -> np.ndarray:
    """Where a path bends at each corner: the corner itself, or, for a corner on the
    boundary (where a path may not go), the point :data:`INSET` times the boundary's
    size (its width, height or farthest coordinate) inside it along the bisector of its
    free angle."""
    out = np.array(corners, dtype=float).reshape(-1, 2)
    if world.boundary is None or not len(out):
        return out
    on = ~world.inside(out)
    if on.any():
        x0, y0, x1, y1 = world.boundary.bounds
        inset = INSET * max(x1 - x0, y1 - y0, abs(x0), abs(y0), abs(x1), abs(y1))
        c = out[on]
        a = prev[on] - c
        b = nxt[on] - c
        # the blocked side lies between the two edges (a convex angle): go the other way
        d = a / np.hypot(*a.T)[:, None] + b / np.hypot(*b.T)[:, None]
        out[on] = c - inset * d / np.hypot(*d.T)[:, None]
    return out


def _build(world: World) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The merged obstacles and the graph's arrays: corners with their ring neighbours,
    the CSR adjacency of free bitangent edges (both directions) and component labels;
    a world past :data:`MAX_CORNERS` is refused before the pairs are tested."""
    _refuse(world, fewest_corners(world), at_least=True)
    merged = world.merged()
    corners, prev, nxt = _corners(world, merged)
    _refuse(world, len(corners))
    corners, prev, nxt = (np.ascontiguousarray(x, dtype=float).reshape(-1, 2)
                          for x in (corners, prev, nxt))
    n = len(corners)
    index = sk.edge_index(merged.obstacles)
    i, j = sk.corner_pairs(corners, prev, nxt)
    bends = bend_points(world, corners, prev, nxt)
    same = np.all(bends[i] == bends[j], axis=1)  # two obstacles meeting at a corner
    ok = same.copy()
    ok[~same] = _free(merged, index, _convex(world.boundary), bends[i[~same]],
                      bends[j[~same]])
    i, j = i[ok], j[ok]
    rows, cols = np.r_[i, j], np.r_[j, i]
    order = np.lexsort((cols, rows))
    rows, cols = rows[order], cols[order]
    indptr = np.searchsorted(rows, np.arange(n + 1)).astype(np.int64)
    weights = np.hypot(*(bends[cols] - bends[rows]).T)
    adjacency = csr_matrix((np.ones(len(cols)), cols, indptr), shape=(n, n))
    labels = connected_components(adjacency, directed=False)[1] if n else np.empty(0)
    names = np.array(merged.names if len(merged.names) else [], dtype=str)
    return merged.obstacles, {"corners": corners, "prev": prev, "next": nxt,
                              "indptr": indptr, "indices": cols.astype(np.int64),
                              "weights": weights, "labels": labels.astype(np.int64),
                              "names": names}
