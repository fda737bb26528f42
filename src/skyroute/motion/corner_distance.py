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

The table is dense, N x N: a world of more than :data:`MAX_CORNERS` is refused before
it starts (5,300 corners, ``skyroute synth-city --blocks 24``, peaked at 1.9 GB when the
table tested its own pairs). Its free segments are the world's visibility graph
(:func:`skyroute.roadmap.world_plan.visibility_graph`: the compiled sight test, kept
with the world and on disk, shared with ``plan-world``): the FCND city at 5 m altitude
and 5 m safety, 1,128 corners, took 68 s through shapely's test pair by pair and takes
0.4 s so (docs/benchmarks.md section 6).
"""

from __future__ import annotations

import functools
import math
import weakref
from dataclasses import dataclass

import numpy as np
from numba import njit

from skyroute.motion import edge_grid
from skyroute.motion.zone_kernels import sight, zone_arrays
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

    @functools.cached_property
    def grid(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The edges' bucket grid (:mod:`skyroute.motion.edge_grid`), built on first use."""
        return edge_grid.build(self.edges)

    def to(self, target) -> np.ndarray:
        """(N,) shortest distance from each corner to ``target`` (inf: unreachable)."""
        t = np.asarray(target, dtype=float).reshape(2)
        return target_distances(float(t[0]), float(t[1]), self.corners, self.adjacency,
                                self.edges, *self.grid)


def corner_graph(world: World) -> CornerGraph:
    """The corner graph of ``world`` (built once per world)."""
    g = _TABLES.get(world)
    if g is None:
        g = _TABLES[world] = _build(world)
    return g


def _build(world: World) -> CornerGraph:
    from skyroute.roadmap.visibility import fewest_corners, refuse_corners
    from skyroute.roadmap.world_plan import visibility_graph
    from skyroute.world.geometry import convex_corners

    def refuse(n: int, at_least: bool = False) -> None:
        refuse_corners(world, n, limit=MAX_CORNERS, table="Hybrid A*'s corner distances",
                       instead="plan with the waypoints planner or another vehicle (lattice, "
                       "field)",
                       at_least=at_least)

    refuse(fewest_corners(world), at_least=True)
    merged = world.merged()
    refuse(len(convex_corners(merged)[0]))
    # The visibility graph's nodes are these convex corners (those outside a boundary
    # dropped: no path inside a convex boundary bends there) and its edges the free
    # bitangent segments between them, both ways: exactly this table's entries.
    graph = visibility_graph(world)
    n = len(graph.corners)
    adj = np.full((n, n), np.inf)
    i, j, w = graph.edge_arrays()
    adj[i, j] = w
    edges = np.ascontiguousarray(zone_arrays(merged)[0], dtype=float)
    return CornerGraph(np.ascontiguousarray(graph.corners, dtype=float), adj, edges)


@njit(cache=True)
def target_distances(tx, ty, corners, adj, edges, meta, start, ids):
    """Dense Dijkstra from the target over the corners (O(N^2), no heap); which corners
    the target sees through the edges' bucket grid (meta, start, ids)."""
    n = corners.shape[0]
    dist = np.full(n, np.inf)
    done = np.zeros(n, np.bool_)
    for c in range(n):
        if sight(tx, ty, corners[c, 0], corners[c, 1], edges, meta, start, ids):
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
def approximate(qx, qy, cols, cdist, out):
    """``out[c] = sqrt(dx**2 + dy**2) + D(c)`` for every corner c, (dx, dy) = q - c: a
    first pass over the corners (``cols``: (2, N) rows of x and y, C order, which LLVM
    vectorises) that glibc's ``hypot`` made most of a search's time. It is within a few
    ulps of the exact value (:func:`exact`), so a corner whose approximation exceeds
    :func:`beyond` of an exact value v has an exact value above v."""
    for c in range(cols.shape[1]):
        dx = qx - cols[0, c]
        dy = qy - cols[1, c]
        out[c] = math.sqrt(dx * dx + dy * dy) + cdist[c]


@njit(cache=True)
def beyond(v):
    """The approximation (:func:`approximate`) above which a corner's exact value exceeds
    ``v``, and the exact value of every corner whose approximation is ``v`` or less (an
    approximation and its exact value differ by a few ulps, far below 1e-12 of it; the
    1e-150 covers squares that underflow); inf when ``v`` is."""
    return v * (1.0 + 1e-12) + 1e-150


@njit(cache=True)
def exact(qx, qy, cols, cdist, c):
    """Corner c's value ``hypot(q - c) + D(c)``: what the bounds return."""
    return math.hypot(qx - cols[0, c], qy - cols[1, c]) + cdist[c]


@njit(cache=True)
def lower_bound(qx, qy, tx, ty, sees, cols, cdist, edges, meta, start, ids, scratch, picks,
                tests):
    """A lower bound on the obstacle-avoiding distance from q to target t: |q - t| when q
    sees t, else the least |q - c| + D(c) over corners c that q sees, found by testing
    sight to the cheapest candidates first (ties: the lower corner index first). After
    ``tests`` blocked candidates it stops and returns the next candidate's value: every
    corner q sees costs at least that, so the bound stays a bound, and the loop stays
    short among many corners. The sight tests read the edges through their bucket grid
    (meta, start, ids: :attr:`CornerGraph.grid`). ``cols``: the corners as (2, N) rows of
    x and y. ``scratch`` (N,) float and ``picks`` (N,) int64: workspace.

    The candidates are found from the corners' approximations (:func:`approximate`): only
    those within :func:`beyond` of the (tests + 1)-th smallest get the exact value. They
    hold every corner the exact order could try, so the answer is the one a scan of every
    corner's exact value gives.
    """
    d = math.hypot(qx - tx, qy - ty)
    n = cols.shape[1]
    if sees or n == 0:
        return d
    approximate(qx, qy, cols, cdist, scratch)
    top = np.full(tests + 1, np.inf)  # the smallest approximations, ascending
    for c in range(n):
        v = scratch[c]
        if v < top[tests]:
            k = tests
            while k > 0 and top[k - 1] > v:
                top[k] = top[k - 1]
                k -= 1
            top[k] = v
    cut = beyond(top[tests])  # inf when fewer values are finite
    m = 0
    for c in range(n):
        if scratch[c] <= cut:
            picks[m] = c
            scratch[m] = exact(qx, qy, cols, cdist, c)
            m += 1
    for k in range(tests + 1):
        j = np.argmin(scratch[:m])
        v = scratch[j]
        if not v < np.inf:
            return d
        c = picks[j]
        if k == tests or sight(qx, qy, cols[0, c], cols[1, c], edges, meta, start, ids):
            return max(d, v)
        scratch[j] = np.inf
    return d
