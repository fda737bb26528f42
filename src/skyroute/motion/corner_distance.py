"""The obstacle-avoiding 2D distance to a target, as a lower bound a search can afford.

A shortest path among polygons bends only at convex corners, on segments tangent to the
obstacles at both ends (:func:`skyroute.roadmap.visibility.convex_corners`). Per world
(kept weakly): the corners and the lengths of the bitangent segments between them that
are free (:meth:`World.segments_free`, exact). Per target, compiled: which corners the
target sees (no obstacle edge properly crossed: a superset of true sight, so the table
can only be lower) and a dense Dijkstra from it, giving D(c) for every corner. A point q
is then at least max(|q - t|, min over corners c that q sees of |q - c| + D(c)) from the
target (:func:`skyroute.motion.move_search.distance`), and exactly that without a
boundary or with a convex one (a non-convex boundary's corners are not in the table,
which can only raise the value above the true one; keep boundaries convex).

The table is dense, N x N, and its build holds a few arrays of N x N / 2 pairs: a world
of more than :data:`MAX_CORNERS` is refused before it starts (5,300 corners,
``skyroute synth-city --blocks 24``, peaked at 1.9 GB; 8,363 ran out of 4 GB). Its free
test is shapely's, about a minute per 1,000 corners squared (3,675 corners: 187 s).
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np
from numba import njit

from skyroute.motion.move_search import _sight
from skyroute.motion.zone_kernels import zone_arrays
from skyroute.world.world import World

MAX_CORNERS = 5_000  # the FCND city has 3,347
_TABLES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


@dataclass(frozen=True, eq=False)
class CornerGraph:
    """Convex corners (N, 2), bitangent free segment lengths (N, N) (inf: none), and the
    obstacle edges (E, 4) the sight tests use."""

    corners: np.ndarray
    adjacency: np.ndarray
    edges: np.ndarray

    def to(self, target) -> np.ndarray:
        """(N,) shortest distance from each corner to ``target`` (inf: unreachable)."""
        t = np.asarray(target, dtype=float).reshape(2)
        return target_distances(float(t[0]), float(t[1]), self.corners, self.adjacency,
                                self.edges)


def corner_graph(world: World) -> CornerGraph:
    """The corner graph of ``world`` (built once per world)."""
    g = _TABLES.get(world)
    if g is None:
        g = _TABLES[world] = _build(world)
    return g


def _build(world: World) -> CornerGraph:
    from skyroute.roadmap.visibility import fewest_corners, refuse_corners
    from skyroute.world.geometry import convex_corners

    def refuse(n: int, at_least: bool = False) -> None:
        refuse_corners(world, n, limit=MAX_CORNERS, table="Hybrid A*'s corner distances",
                       instead="plan with the waypoints planner or another vehicle (lattice, "
                       "field)",
                       at_least=at_least)

    refuse(fewest_corners(world), at_least=True)
    merged = world.merged()
    edges = np.ascontiguousarray(zone_arrays(merged)[0], dtype=float)
    corners, prev, nxt = convex_corners(merged)
    n = len(corners)
    refuse(n)
    adj = np.full((n, n), np.inf)
    if n > 1:
        i, j = np.triu_indices(n, 1)
        d = corners[j] - corners[i]

        def tangent(at, other_dir):
            a, b = prev[at] - corners[at], nxt[at] - corners[at]
            s1 = other_dir[:, 0] * a[:, 1] - other_dir[:, 1] * a[:, 0]
            s2 = other_dir[:, 0] * b[:, 1] - other_dir[:, 1] * b[:, 0]
            return s1 * s2 >= 0

        keep = tangent(i, d) & tangent(j, -d)
        i, j = i[keep], j[keep]
        ok = world.segments_free(corners[i], corners[j])
        i, j = i[ok], j[ok]
        w = np.hypot(*(corners[j] - corners[i]).T)
        adj[i, j] = w
        adj[j, i] = w
    return CornerGraph(np.ascontiguousarray(corners, dtype=float), adj, edges)


@njit(cache=True)
def target_distances(tx, ty, corners, adj, edges):
    """Dense Dijkstra from the target over the corners (O(N^2), no heap)."""
    n = corners.shape[0]
    dist = np.full(n, np.inf)
    done = np.zeros(n, np.bool_)
    for c in range(n):
        if _sight(tx, ty, corners[c, 0], corners[c, 1], edges):
            dist[c] = math.hypot(tx - corners[c, 0], ty - corners[c, 1])
    for _ in range(n):
        u = -1
        best = np.inf
        for c in range(n):
            if not done[c] and dist[c] < best:
                best = dist[c]
                u = c
        if u < 0:
            break
        done[u] = True
        for v in range(n):
            alt = best + adj[u, v]
            if alt < dist[v]:
                dist[v] = alt
    return dist


@njit(cache=True)
def lower_bound(qx, qy, tx, ty, sees, corners, cdist, edges, scratch, tests):
    """A lower bound on the obstacle-avoiding distance from q to target t: |q - t| when q
    sees t, else the least |q - c| + D(c) over corners c that q sees, found by testing
    sight to the cheapest candidates first. After ``tests`` blocked candidates it stops
    and returns the next candidate's value: every corner q sees costs at least that, so
    the bound stays a bound, and the loop stays short among many corners. ``scratch``:
    (N,) float workspace."""
    d = math.hypot(qx - tx, qy - ty)
    n = corners.shape[0]
    if sees or n == 0:
        return d
    for c in range(n):
        scratch[c] = math.hypot(qx - corners[c, 0], qy - corners[c, 1]) + cdist[c]
    for k in range(tests + 1):
        c = np.argmin(scratch[:n])
        v = scratch[c]
        if not v < np.inf:
            return d
        if k == tests or _sight(qx, qy, corners[c, 0], corners[c, 1], edges):
            return max(d, v)
        scratch[c] = np.inf
    return d
