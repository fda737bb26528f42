"""Exact, compiled collision tests of circular arcs and straight pieces against a world.

A piece starts at a pose (x, y, heading) and travels a signed length ``u`` (negative:
in reverse) with turn ``k`` = +1 (left, anticlockwise), 0 (straight) or -1 (right) on a
circle of radius ``r``. It is free when its exact distance to every obstacle edge and
boundary edge exceeds ``eps`` (1e-9 of the world's extent) and its start is free: a
continuous curve that meets no edge cannot change sides, so it stays outside every
obstacle and strictly inside the boundary. There is no sampling and no polyline: the
distance between an arc and a segment is found in closed form (its minimum lies at an
end of either, on the radius through an edge end, on the radius perpendicular to the
edge, or is zero where the edge's line meets the arc). The test is stricter than
:meth:`World.segments_free` only by ``eps``: a piece that grazes an edge within 1e-9 of
the extent is called blocked, never the other way round.

Edges come from :func:`skyroute.motion.zone_kernels.zone_arrays` on the merged world
(touching obstacles fused, so there is no gap along a shared edge) and are bucketed in a
uniform grid (CSR arrays): a piece is cut into chunks no longer than a bucket (and no
more than a quarter turn), and each chunk is tested against the edges of the buckets its
box (chord grown by the sagitta) overlaps. A stamp per edge skips repeats in one chunk.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np
import shapely
from numba import njit

from skyroute.motion.zone_kernels import crosses, zone_arrays
from skyroute.world.edge_buckets import bucket_edges
from skyroute.world.geometry import point_segment_dist2
from skyroute.world.world import World

TWO_PI = 2 * math.pi
SUB = 4  # clearance sub-cells per bucket side
_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


@dataclass(frozen=True, eq=False)
class EdgeIndex:
    """Obstacle and boundary edges (E, 4) bucketed on a uniform grid (CSR: the edges of
    bucket (ix, iy) are ``items[start[b]:start[b + 1]]``, b = iy * nx + ix)."""

    edges: np.ndarray
    start: np.ndarray
    items: np.ndarray
    x0: float
    y0: float
    cell: float
    nx: int
    ny: int
    eps: float
    clear: np.ndarray

    def args(self) -> tuple:
        """The arrays and numbers the kernels take, in order."""
        return (self.edges, self.start, self.items, self.x0, self.y0, self.cell, self.nx,
                self.ny, self.eps, self.clear)


def world_edges(world: World) -> np.ndarray:
    """(E, 4) edges of the merged obstacles and of the boundary (rings and holes)."""
    edges, _, bedges = zone_arrays(world.merged())
    parts = [edges, bedges]
    if world.boundary is not None:
        for ring in shapely.Polygon(world.boundary).interiors:
            c = np.asarray(ring.coords)
            parts.append(np.c_[c[:-1], c[1:]])
    return np.ascontiguousarray(np.concatenate(parts), dtype=np.float64)


def edge_index(world: World, cell: float) -> EdgeIndex:
    """The bucketed edges of ``world`` (kept per world and bucket size)."""
    per = _CACHE.setdefault(world, {})
    if cell not in per:
        per[cell] = _build(world_edges(world), float(cell))
    return per[cell]


def _build(edges: np.ndarray, cell: float) -> EdgeIndex:
    if len(edges) == 0:
        return EdgeIndex(edges.reshape(0, 4), np.zeros(2, np.int64), np.zeros(0, np.int64),
                         0.0, 0.0, cell, 1, 1, 1e-9, np.zeros((1, 1)))
    eps = 1e-9 * max(1.0, float(np.ptp(edges[:, [0, 2]])), float(np.ptp(edges[:, [1, 3]])))
    start, items, x0, y0, nx, ny = bucket_edges(edges, cell, eps)
    clear = _clearance(edges, start, items, float(x0), float(y0), cell, nx, ny)
    return EdgeIndex(edges, start, items, float(x0), float(y0), cell, nx, ny, eps, clear)


@njit(cache=True)
def _clearance(edges, start, items, x0, y0, cell, nx, ny):
    """(SUB ny, SUB nx) distance from each sub-cell centre to the nearest edge, capped at
    two buckets (edges further away are in no bucket within two of the centre's)."""
    res = cell / SUB
    out = np.empty((SUB * ny, SUB * nx))
    cap = 2 * cell
    for r in range(SUB * ny):
        cy = y0 + (r + 0.5) * res
        by = r // SUB
        for c in range(SUB * nx):
            cx = x0 + (c + 0.5) * res
            bx = c // SUB
            best = cap * cap
            for iy in range(max(0, by - 2), min(ny, by + 3)):
                for ix in range(max(0, bx - 2), min(nx, bx + 3)):
                    b = iy * nx + ix
                    for m in range(start[b], start[b + 1]):
                        i = items[m]
                        best = min(best, point_segment_dist2(cx, cy, edges[i, 0], edges[i, 1],
                                                             edges[i, 2], edges[i, 3]))
            out[r, c] = math.sqrt(best)
    return out


@njit(cache=True)
def advance(x, y, th, k, u, r):
    """The pose after travelling signed length ``u`` with turn ``k`` on radius ``r``."""
    if k == 0:
        return x + u * math.cos(th), y + u * math.sin(th), th
    dth = k * u / r
    kr = k * r
    return (x + kr * (math.sin(th + dth) - math.sin(th)),
            y - kr * (math.cos(th + dth) - math.cos(th)), th + dth)


@njit(cache=True)
def _in_sweep(ang, a0, sweep):
    """Angle ``ang`` lies on the arc that starts at angle ``a0`` and turns ``sweep``."""
    if sweep >= 0:
        d = (ang - a0) % TWO_PI
        return d <= sweep
    d = (a0 - ang) % TWO_PI
    return d <= -sweep


@njit(cache=True)
def arc_segment_distance(cx, cy, r, a0, sweep, ax, ay, bx, by):
    """Exact distance between the arc (centre, radius, start angle, signed sweep of at
    most a half turn) and the segment ab."""
    e0x, e0y = cx + r * math.cos(a0), cy + r * math.sin(a0)
    e1x, e1y = cx + r * math.cos(a0 + sweep), cy + r * math.sin(a0 + sweep)
    best = math.sqrt(min(point_segment_dist2(e0x, e0y, ax, ay, bx, by),
                         point_segment_dist2(e1x, e1y, ax, ay, bx, by)))
    for j in range(2):
        px, py = (ax, ay) if j == 0 else (bx, by)
        dx, dy = px - cx, py - cy
        d = math.sqrt(dx * dx + dy * dy)
        if d > 0 and _in_sweep(math.atan2(dy, dx), a0, sweep):
            best = min(best, abs(d - r))
    ux, uy = bx - ax, by - ay
    L2 = ux * ux + uy * uy
    if L2 == 0.0:
        return best
    t = ((cx - ax) * ux + (cy - ay) * uy) / L2
    fx, fy = ax + t * ux - cx, ay + t * uy - cy
    d = math.sqrt(fx * fx + fy * fy)
    if 0.0 <= t <= 1.0 and d > 0 and _in_sweep(math.atan2(fy, fx), a0, sweep):
        best = min(best, abs(d - r))
    if d <= r:
        h = math.sqrt(r * r - d * d) / math.sqrt(L2)
        for tt in (t - h, t + h):
            if 0.0 <= tt <= 1.0:
                ix, iy = ax + tt * ux - cx, ay + tt * uy - cy
                if _in_sweep(math.atan2(iy, ix), a0, sweep):
                    return 0.0
    return best


@njit(cache=True)
def segment_distance(px, py, qx, qy, ax, ay, bx, by):
    """Exact distance between segments pq and ab."""
    if crosses(px, py, qx, qy, ax, ay, bx, by):
        return 0.0
    return math.sqrt(min(point_segment_dist2(px, py, ax, ay, bx, by),
                         point_segment_dist2(qx, qy, ax, ay, bx, by),
                         point_segment_dist2(ax, ay, px, py, qx, qy),
                         point_segment_dist2(bx, by, px, py, qx, qy)))


@njit(cache=True)
def piece_free(x, y, th, k, u, r, edges, start, items, x0, y0, cell, nx, ny, eps, clear,
               stamp, tick):
    """True when the piece from pose (x, y, th) (signed length ``u``, turn ``k``, radius
    ``r``) stays more than ``eps`` from every edge. ``stamp`` (E,) int64 and ``tick``
    (1,) int64 are scratch: stamp[i] == tick[0] marks edge i as tested in this chunk."""
    if edges.shape[0] == 0 or u == 0.0:
        return True
    length = abs(u)
    lc = cell if k == 0 else min(cell, 0.5 * math.pi * r)
    n = max(1, math.ceil(length / lc))
    du = u / n
    cx = cy = a0 = sweep = sag = 0.0
    res = cell / SUB
    slack = 0.7072 * res + abs(du) + eps  # half a sub-cell's diagonal, the chunk, eps
    gx1, gy1 = x0 + nx * cell, y0 + ny * cell
    j = -1
    while j < n - 1:
        j += 1
        px, py, pth = advance(x, y, th, k, du * j, r)
        # outside the buckets' grid (whose edges lie a bucket inside it), the next m
        # chunks stay within m |du| of here: skip those that cannot reach the grid, so a
        # piece far longer than the world (a radius of kilometres round a city block)
        # costs its chunks near the edges, not length / bucket of them
        out = math.hypot(max(x0 - px, px - gx1, 0.0), max(y0 - py, py - gy1, 0.0))
        if out > abs(du):
            j += int(min(out / abs(du), n)) - 1
            continue
        # a chunk lies within |du| of its start: far enough from every edge, it is free
        ci = math.floor((px - x0) / res)
        cj = math.floor((py - y0) / res)
        if 0 <= ci < clear.shape[1] and 0 <= cj < clear.shape[0] and clear[cj, ci] > slack:
            continue
        qx, qy, _ = advance(x, y, th, k, du * (j + 1), r)
        if k != 0:
            cx = px - k * r * math.sin(pth)
            cy = py + k * r * math.cos(pth)
            a0 = math.atan2(py - cy, px - cx)
            sweep = k * du / r
            sag = r * (1.0 - math.cos(0.5 * sweep))
        grow = sag + eps
        ix0 = max(0, math.floor((min(px, qx) - grow - x0) / cell))
        ix1 = min(nx - 1, math.floor((max(px, qx) + grow - x0) / cell))
        iy0 = max(0, math.floor((min(py, qy) - grow - y0) / cell))
        iy1 = min(ny - 1, math.floor((max(py, qy) + grow - y0) / cell))
        if ix0 > ix1 or iy0 > iy1:
            continue
        tick[0] += 1
        t = tick[0]
        for iy in range(iy0, iy1 + 1):
            for ix in range(ix0, ix1 + 1):
                b = iy * nx + ix
                for m in range(start[b], start[b + 1]):
                    i = items[m]
                    if stamp[i] == t:
                        continue
                    stamp[i] = t
                    if k == 0:
                        d = segment_distance(px, py, qx, qy, edges[i, 0], edges[i, 1],
                                             edges[i, 2], edges[i, 3])
                    else:
                        d = arc_segment_distance(cx, cy, r, a0, sweep, edges[i, 0],
                                                 edges[i, 1], edges[i, 2], edges[i, 3])
                    if d <= eps:
                        return False
    return True


@njit(cache=True)
def chain_free(x, y, th, turns, lengths, r, edges, start, items, x0, y0, cell, nx, ny, eps,
               clear, stamp, tick):
    """:func:`piece_free` for consecutive pieces (turns (P,) int64, signed lengths (P,))
    from pose (x, y, th)."""
    for p in range(turns.shape[0]):
        if not piece_free(x, y, th, turns[p], lengths[p], r, edges, start, items, x0, y0,
                          cell, nx, ny, eps, clear, stamp, tick):
            return False
        x, y, th = advance(x, y, th, turns[p], lengths[p], r)
    return True


@njit(cache=True)
def chain_reaches(x, y, th, turns, lengths, r, gx, gy, gth, tol):
    """True when the pieces from pose (x, y, th) end within ``tol`` of (gx, gy) and
    within 1e-9 rad of heading gth: closed forms lose digits on tiny or degenerate
    queries, and a path must not jump (callers pass 1e-12 of the world's extent; a
    well-posed Dubins path ends within about 1e-14 of it)."""
    for p in range(turns.shape[0]):
        x, y, th = advance(x, y, th, turns[p], lengths[p], r)
    dh = (th - gth + math.pi) % TWO_PI - math.pi
    return math.hypot(x - gx, y - gy) <= tol and abs(dh) <= 1e-9
