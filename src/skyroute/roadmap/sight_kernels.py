"""Compiled sight tests for the visibility graph: does a segment meet the interior of a
polygon obstacle? Plain arrays in, one code per segment out.

The obstacles are the merged world's polygons, as edges (rings and holes, grouped per
polygon) bucketed on a uniform grid (:func:`edge_index`). A segment walks the grid cells
it passes (column by column, grown by ``eps``) and meets each edge there once:

- both segments' orientation tests have certain signs (beyond a floating-point error
  bound, as in Shewchuk's fast orient2d) and say they cross properly: BLOCKED at once;
- a certain sign says they are apart: nothing;
- otherwise they touch where an orientation is exactly zero (a shared vertex, or exact
  arithmetic on an expansion says so); the kernel notes where along the segment the
  contact lies (and the stretches it runs along an edge). The pieces between contacts
  lie wholly inside or wholly outside each touched polygon, so the midpoint of each
  piece not along an edge is tested (even-odd rule).

Anything the floating-point test cannot settle (a near-zero orientation that is not an
exact zero, a midpoint within ``eps`` of an edge, more contacts than the scratch holds)
is UNSURE, and the caller asks shapely (:meth:`World.segments_free`), so the verdicts
are exactly shapely's: free means the segment meets no obstacle interior; touching
edges and corners is allowed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely
from numba import njit

from skyroute.world.edge_buckets import bucket_edges
from skyroute.world.geometry import point_segment_dist2

FREE, BLOCKED, UNSURE = 0, 1, 2
ERR = 1e-14  # relative error bound of a computed orientation (Shewchuk's is 3.3e-16)
MAX_CONTACTS = 64


@dataclass(frozen=True, eq=False)
class EdgeIndex:
    """Obstacle edges (E, 4) with their polygon (``owner``; polygon k's edges are
    ``edges[first[k]:first[k + 1]]``), bucketed on a uniform grid: the edges of cell
    (ix, iy) are ``items[start[b]:start[b + 1]]``, b = iy * nx + ix."""

    edges: np.ndarray
    owner: np.ndarray
    first: np.ndarray
    start: np.ndarray
    items: np.ndarray
    x0: float
    y0: float
    cell: float
    nx: int
    ny: int
    eps: float

    def args(self) -> tuple:
        """The arrays and numbers the kernels take, in order."""
        return (self.edges, self.owner, self.first, self.start, self.items, self.x0,
                self.y0, self.cell, self.nx, self.ny, self.eps)


def edge_index(polygons: np.ndarray) -> EdgeIndex:
    """The bucketed edges of disjoint ``polygons`` (a merged world's obstacles)."""
    rings, poly = shapely.get_rings(np.asarray(polygons, dtype=object), return_index=True)
    xy, ring = shapely.get_coordinates(rings, return_index=True)
    same = ring[:-1] == ring[1:]  # consecutive vertices of one (closed) ring
    edges = np.ascontiguousarray(np.c_[xy[:-1][same], xy[1:][same]], dtype=np.float64)
    owner = poly[ring[:-1][same]].astype(np.int64)
    first = np.searchsorted(owner, np.arange(len(polygons) + 1)).astype(np.int64)
    if len(edges) == 0:
        return EdgeIndex(edges.reshape(0, 4), owner, first, np.zeros(2, np.int64),
                         np.zeros(0, np.int64), 0.0, 0.0, 1.0, 1, 1, 1e-9)
    lo = np.minimum(edges[:, :2], edges[:, 2:]).min(0)
    hi = np.maximum(edges[:, :2], edges[:, 2:]).max(0)
    extent = float(max((hi - lo).max(), 1e-300))
    eps = 1e-9 * max(extent, np.abs(np.r_[lo, hi]).max())
    cell = max(extent / max(1.0, math.sqrt(len(edges) / 2.0)), 16 * eps)
    start, items, x0, y0, nx, ny = bucket_edges(edges, cell, eps)
    return EdgeIndex(edges, owner, first, start, items, x0, y0, float(cell), nx, ny, eps)


@njit(cache=True)
def _two_sum(a, b):
    """a + b as x + y exactly (Knuth)."""
    x = a + b
    bv = x - a
    av = x - bv
    return x, (a - av) + (b - bv)


@njit(cache=True)
def _two_product(a, b):
    """a * b as x + y exactly (Dekker's split, no FMA needed)."""
    x = a * b
    c = 134217729.0 * a  # 2**27 + 1
    ahi = c - (c - a)
    alo = a - ahi
    c = 134217729.0 * b
    bhi = c - (c - b)
    blo = b - bhi
    return x, alo * blo - (((x - ahi * bhi) - alo * bhi) - ahi * blo)


@njit(cache=True)
def _exact_sign(ax, ay, bx, by, cx, cy):
    """The exact sign of orient(a, b, c): its six products summed as an expansion
    (Shewchuk's Grow-Expansion); the sign is that of the largest component."""
    e = np.zeros(12)
    n = 0
    for k in range(6):
        if k == 0:
            x, y = _two_product(bx, cy)
        elif k == 1:
            x, y = _two_product(-bx, ay)
        elif k == 2:
            x, y = _two_product(-ax, cy)
        elif k == 3:
            x, y = _two_product(-by, cx)
        elif k == 4:
            x, y = _two_product(ax, by)
        else:
            x, y = _two_product(ay, cx)
        for v in (y, x):
            q = v
            for i in range(n):
                q, h = _two_sum(q, e[i])
                e[i] = h
            e[n] = q
            n += 1
    for i in range(n - 1, -1, -1):
        if e[i] != 0.0:
            return 1 if e[i] > 0 else -1
    return 0


@njit(cache=True)
def _sign(ax, ay, bx, by, cx, cy):
    """Sign of orient(a, b, c): 1 left, -1 right, 0 exactly collinear (exact arithmetic
    says so), 2 too close to call: not collinear, but within rounding of it, where
    shapely's answer is the reference (its predicates are not exact there)."""
    left = (bx - ax) * (cy - ay)
    right = (by - ay) * (cx - ax)
    d = left - right
    if abs(d) > ERR * (abs(left) + abs(right)):
        return 1 if d > 0 else -1
    if (cx == ax and cy == ay) or (cx == bx and cy == by):
        return 0
    if _exact_sign(ax, ay, bx, by, cx, cy) == 0:
        return 0
    return 2


@njit(cache=True)
def _param(px, py, qx, qy, ax, ay):
    """Where point a (on line pq) lies along pq: 0 at p, 1 at q."""
    dx, dy = qx - px, qy - py
    if abs(dx) >= abs(dy):
        return (ax - px) / dx
    return (ay - py) / dy


@njit(cache=True)
def _inside(mx, my, edges, lo, hi, eps):
    """1 when m is inside the polygon whose edges are edges[lo:hi] (even-odd), 0 when
    outside, 2 when within eps of an edge."""
    inside = False
    e2 = eps * eps
    for e in range(lo, hi):
        ax, ay, bx, by = edges[e, 0], edges[e, 1], edges[e, 2], edges[e, 3]
        if point_segment_dist2(mx, my, ax, ay, bx, by) <= e2:
            return 2
        if (ay > my) != (by > my) and mx < ax + (my - ay) * (bx - ax) / (by - ay):
            inside = not inside
    return 1 if inside else 0


@njit(cache=True)
def segment_code(px, py, qx, qy, edges, owner, first, start, items, x0, y0, cell, nx, ny,
                 eps, stamp, ts, spans, touched, verts):
    """FREE, BLOCKED or UNSURE for segment pq, whose ends lie in no obstacle's interior
    (corners, checked points: a segment wholly inside one would pass). Scratch (see
    :func:`scratch`): ``stamp`` (E + 1,) int64, its last entry counting calls; ``ts``
    (MAX_CONTACTS,) and ``spans`` (MAX_CONTACTS, 2) float; ``touched`` (MAX_CONTACTS,)
    int64; ``verts`` (MAX_CONTACTS, 2) float: the edge vertices on pq, since two distinct
    ones closer than eps can give the same parameter along pq and hide the sliver
    between them (boxes overlapping by 4e-17 of a metre: their union's interior)."""
    if px == qx and py == qy:
        return UNSURE
    tick = stamp[-1] + 1
    stamp[-1] = tick
    nt = 0
    ns = 0
    nk = 0
    nv = 0
    unsure = False
    xlo, xhi = min(px, qx), max(px, qx)
    ylo, yhi = min(py, qy), max(py, qy)
    cl = max(0, int((xlo - eps - x0) // cell))
    ch = min(nx - 1, int((xhi + eps - x0) // cell))
    for cc in range(ch - cl + 1):
        c = cl + cc if qx >= px else ch - cc  # from p: a blocking edge near p ends early
        if qx != px:
            xa = min(max(x0 + c * cell, xlo), xhi)
            xb = min(max(x0 + (c + 1) * cell, xlo), xhi)
            ya = py + (xa - px) * (qy - py) / (qx - px)
            yb = py + (xb - px) * (qy - py) / (qx - px)
            ra, rb = min(ya, yb), max(ya, yb)
        else:
            ra, rb = ylo, yhi
        rl = max(0, int((ra - eps - y0) // cell))
        rh = min(ny - 1, int((rb + eps - y0) // cell))
        for rr in range(rh - rl + 1):
            r = rl + rr if qy >= py else rh - rr
            b = r * nx + c
            for m in range(start[b], start[b + 1]):
                e = items[m]
                if stamp[e] == tick:
                    continue
                stamp[e] = tick
                ax, ay, bx, by = edges[e, 0], edges[e, 1], edges[e, 2], edges[e, 3]
                o1 = _sign(px, py, qx, qy, ax, ay)
                o2 = _sign(px, py, qx, qy, bx, by)
                if o1 != 2 and o2 != 2 and o1 * o2 > 0:
                    continue
                o3 = _sign(ax, ay, bx, by, px, py)
                o4 = _sign(ax, ay, bx, by, qx, qy)
                if o3 != 2 and o4 != 2 and o3 * o4 > 0:
                    continue
                if o1 == 2 or o2 == 2 or o3 == 2 or o4 == 2:
                    unsure = True  # unless an edge further on blocks it for certain
                    continue
                if o1 * o2 < 0 and o3 * o4 < 0:
                    return BLOCKED
                if nt + 4 > ts.shape[0] or ns >= spans.shape[0] or nk >= touched.shape[0]:
                    unsure = True
                    continue
                before = nt
                for v in range(2):  # the edge's ends on pq's line
                    if (o1 if v == 0 else o2) != 0:
                        continue
                    vx, vy = (ax, ay) if v == 0 else (bx, by)
                    near = False
                    for j in range(nv):
                        d2 = (verts[j, 0] - vx) ** 2 + (verts[j, 1] - vy) ** 2
                        near = near or 0.0 < d2 <= eps * eps
                    unsure = unsure or near
                    if nv < verts.shape[0]:
                        verts[nv, 0] = vx
                        verts[nv, 1] = vy
                        nv += 1
                    else:
                        unsure = True
                if o1 == 0 and o2 == 0:  # along the edge's line
                    ta = _param(px, py, qx, qy, ax, ay)
                    tb = _param(px, py, qx, qy, bx, by)
                    lo, hi = max(min(ta, tb), 0.0), min(max(ta, tb), 1.0)
                    if lo <= hi:
                        ts[nt] = lo
                        ts[nt + 1] = hi
                        nt += 2
                        if lo < hi:
                            spans[ns, 0] = lo
                            spans[ns, 1] = hi
                            ns += 1
                else:
                    if o1 == 0:
                        t = _param(px, py, qx, qy, ax, ay)
                        if 0.0 <= t <= 1.0:
                            ts[nt] = t
                            nt += 1
                    if o2 == 0:
                        t = _param(px, py, qx, qy, bx, by)
                        if 0.0 <= t <= 1.0:
                            ts[nt] = t
                            nt += 1
                    if o1 * o2 < 0:  # the edge crosses pq's line at p or q
                        if o3 == 0:
                            ts[nt] = 0.0
                            nt += 1
                        elif o4 == 0:
                            ts[nt] = 1.0
                            nt += 1
                if nt > before:
                    k = owner[e]
                    seen = False
                    for j in range(nk):
                        seen = seen or touched[j] == k
                    if not seen:
                        touched[nk] = k
                        nk += 1
    if nt == 0:
        return UNSURE if unsure else FREE
    # the pieces between contacts: along an edge, or wholly in or out of each polygon
    # (a midpoint well inside a polygon blocks for certain, even when unsure)
    ts[nt] = 0.0
    ts[nt + 1] = 1.0
    nt += 2
    for i in range(1, nt):  # insertion sort: a handful of values
        v = ts[i]
        j = i - 1
        while j >= 0 and ts[j] > v:
            ts[j + 1] = ts[j]
            j -= 1
        ts[j + 1] = v
    for i in range(nt - 1):
        a, b = ts[i], ts[i + 1]
        if not a < b:
            continue
        along = False
        for j in range(ns):
            along = along or (spans[j, 0] <= a and b <= spans[j, 1])
        if along:
            continue
        tm = 0.5 * (a + b)
        mx, my = px + tm * (qx - px), py + tm * (qy - py)
        for j in range(nk):
            k = touched[j]
            inside = _inside(mx, my, edges, first[k], first[k + 1], eps)
            if inside == 1:
                return BLOCKED
            unsure = unsure or inside == 2
    return UNSURE if unsure else FREE


def scratch(index: EdgeIndex) -> tuple:
    """Fresh scratch arrays for :func:`segment_code` (stamp, ts, spans, touched, verts)."""
    return (np.zeros(len(index.edges) + 1, np.int64), np.empty(MAX_CONTACTS),
            np.empty((MAX_CONTACTS, 2)), np.empty(MAX_CONTACTS, np.int64),
            np.empty((MAX_CONTACTS, 2)))


@njit(cache=True)
def _tangent(dx, dy, ax, ay, bx, by):
    """The line through a corner along (dx, dy) leaves both ring neighbours (at a and b
    from the corner) on one side, or runs along one of them (within rounding: keeping
    an edge too many never makes a path wrong, dropping one may make it longer)."""
    s1 = dx * ay - dy * ax
    s2 = dx * by - dy * bx
    if s1 * s2 >= 0.0:
        return True
    d = math.hypot(dx, dy)
    return abs(s1) <= 1e-12 * d * math.hypot(ax, ay) or \
        abs(s2) <= 1e-12 * d * math.hypot(bx, by)


@njit(cache=True)
def corner_pairs(corners, prev, nxt):
    """(i, j) with i < j for every bitangent pair of corners: the segment is tangent to
    the obstacle at both ends (only such edges can lie on a shortest path)."""
    n = corners.shape[0]
    out_i = np.empty(16, np.int64)
    out_j = np.empty(16, np.int64)
    m = 0
    for i in range(n):
        cx, cy = corners[i, 0], corners[i, 1]
        pax, pay = prev[i, 0] - cx, prev[i, 1] - cy
        pbx, pby = nxt[i, 0] - cx, nxt[i, 1] - cy
        for j in range(i + 1, n):
            dx, dy = corners[j, 0] - cx, corners[j, 1] - cy
            if not _tangent(dx, dy, pax, pay, pbx, pby):
                continue
            if not _tangent(-dx, -dy, prev[j, 0] - corners[j, 0], prev[j, 1] - corners[j, 1],
                            nxt[j, 0] - corners[j, 0], nxt[j, 1] - corners[j, 1]):
                continue
            if m == out_i.shape[0]:
                out_i = np.concatenate((out_i, np.empty(m, np.int64)))
                out_j = np.concatenate((out_j, np.empty(m, np.int64)))
            out_i[m] = i
            out_j[m] = j
            m += 1
    return out_i[:m], out_j[:m]


@njit(cache=True)
def tangent_ids(px, py, corners, prev, nxt):
    """Corners v where the line p -> v leaves both of v's ring neighbours on one side."""
    n = corners.shape[0]
    out = np.empty(n, np.int64)
    m = 0
    for v in range(n):
        cx, cy = corners[v, 0], corners[v, 1]
        if _tangent(cx - px, cy - py, prev[v, 0] - cx, prev[v, 1] - cy, nxt[v, 0] - cx,
                    nxt[v, 1] - cy):
            out[m] = v
            m += 1
    return out[:m]


@njit(cache=True)
def segment_codes(a, b, edges, owner, first, start, items, x0, y0, cell, nx, ny, eps,
                  stamp, ts, spans, touched, verts):
    """:func:`segment_code` for each segment a[k] -> b[k] ((K, 2) arrays)."""
    out = np.empty(a.shape[0], np.int64)
    for k in range(a.shape[0]):
        out[k] = segment_code(a[k, 0], a[k, 1], b[k, 0], b[k, 1], edges, owner, first,
                              start, items, x0, y0, cell, nx, ny, eps, stamp, ts, spans,
                              touched, verts)
    return out
