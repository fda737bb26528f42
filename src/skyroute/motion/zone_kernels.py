"""Compiled geometry for the step drone: its 36 moves against polygon zones and a
boundary, one numba call per expansion (plain arrays in, masks out).

The zone edges are read through their bucket grid (:mod:`skyroute.motion.edge_grid`,
``grid`` = its (meta, start, ids)): :func:`near`, :func:`sight` and :func:`inside` test
the edges of the buckets a query meets and answer what :func:`_near`, :func:`crosses`
over every edge and :func:`_inside` answer (the boundary's few edges are scanned whole).
On the FCND city (15,380 edges) a move test or a sight line meets a few dozen.

``clear``: a move is legal when it touches no zone edge (within ``eps``, so the test is
never more permissive than an exact one), ends outside every zone and ends strictly
inside the boundary (more than ``eps`` from its edges). ``sees``: the sight line to the
target properly crosses no zone edge; touching and edge cases count as seeing, which can
only lower A*'s bound (still admissible).
"""

from __future__ import annotations

import numpy as np
import shapely
from numba import njit

from skyroute.motion.edge_grid import SLACK, index, row_cols, rows
from skyroute.world.geometry import point_segment_dist2
from skyroute.world.world import World


def zone_arrays(world: World) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(zone edges (E, 4), edge -> zone id (E,), boundary edges (B, 4))."""
    edges, owner = [], []
    for k, poly in enumerate(world.obstacles):
        for ring in (poly.exterior, *poly.interiors):
            c = np.asarray(ring.coords)
            edges.append(np.c_[c[:-1], c[1:]])
            owner.append(np.full(len(c) - 1, k))
    e = np.concatenate(edges) if edges else np.empty((0, 4))
    o = np.concatenate(owner) if owner else np.empty(0, np.int64)
    if world.boundary is not None:
        c = np.asarray(shapely.Polygon(world.boundary).exterior.coords)
        b = np.c_[c[:-1], c[1:]]
    else:
        b = np.empty((0, 4))
    return np.ascontiguousarray(e), o.astype(np.int64), np.ascontiguousarray(b)


@njit(cache=True)
def _orient(ax, ay, bx, by, cx, cy):
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


@njit(cache=True)
def _touch(ax, ay, bx, by, cx, cy, dx, dy, eps):
    """Segments ab and cd intersect or come within eps of each other."""
    o1 = _orient(ax, ay, bx, by, cx, cy)
    o2 = _orient(ax, ay, bx, by, dx, dy)
    o3 = _orient(cx, cy, dx, dy, ax, ay)
    o4 = _orient(cx, cy, dx, dy, bx, by)
    if ((o1 > 0) != (o2 > 0)) and ((o3 > 0) != (o4 > 0)) and o1 != 0 and o2 != 0 \
            and o3 != 0 and o4 != 0:
        return True
    e2 = eps * eps
    return (point_segment_dist2(ax, ay, cx, cy, dx, dy) <= e2
            or point_segment_dist2(bx, by, cx, cy, dx, dy) <= e2
            or point_segment_dist2(cx, cy, ax, ay, bx, by) <= e2
            or point_segment_dist2(dx, dy, ax, ay, bx, by) <= e2)


@njit(cache=True)
def crosses(ax, ay, bx, by, cx, cy, dx, dy):
    """Proper crossing: interiors meet at one point, no collinear or endpoint cases."""
    o1 = _orient(ax, ay, bx, by, cx, cy)
    o2 = _orient(ax, ay, bx, by, dx, dy)
    o3 = _orient(cx, cy, dx, dy, ax, ay)
    o4 = _orient(cx, cy, dx, dy, bx, by)
    return o1 * o2 < 0 and o3 * o4 < 0


@njit(cache=True)
def _inside(px, py, edges, owner, nzones):
    """Zone id holding point p (even-odd rule per zone), or -1."""
    count = np.zeros(nzones, np.int64)
    for i in range(edges.shape[0]):
        ax, ay, bx, by = edges[i, 0], edges[i, 1], edges[i, 2], edges[i, 3]
        if (ay > py) != (by > py):
            x = ax + (py - ay) * (bx - ax) / (by - ay)
            if px < x:
                count[owner[i]] += 1
    for k in range(nzones):
        if count[k] % 2 == 1:
            return k
    return -1


@njit(cache=True)
def _near(px, py, edges, reach):
    """Indices of edges within ``reach`` of p: the only ones a move of that length meets."""
    out = np.empty(edges.shape[0], np.int64)
    k = 0
    r2 = reach * reach
    for i in range(edges.shape[0]):
        if point_segment_dist2(px, py, edges[i, 0], edges[i, 1], edges[i, 2], edges[i, 3]) <= r2:
            out[k] = i
            k += 1
    return out[:k]


@njit(cache=True)
def sight(qx, qy, vx, vy, edges, meta, start, ids):
    """No edge properly crosses segment qv (:func:`crosses`), as a test of every edge
    answers, testing only the edges of the buckets qv passes through, from q's end (a
    blocked sight line is mostly blocked near q: the search's q lies among buildings)."""
    nx = int(meta[3])
    pad = meta[2] * SLACK
    r0, r1 = rows(qy, vy, meta, pad)
    up = vy >= qy
    right = vx >= qx
    for rr in range(r1 - r0 + 1):
        r = r0 + rr if up else r1 - rr
        c0, c1 = row_cols(qx, qy, vx, vy, r, meta, pad)
        for cc in range(c1 - c0 + 1):
            b = r * nx + (c0 + cc if right else c1 - cc)
            for j in range(start[b], start[b + 1]):
                i = ids[j]
                if crosses(qx, qy, vx, vy, edges[i, 0], edges[i, 1], edges[i, 2],
                           edges[i, 3]):
                    return False
    return True


@njit(cache=True)
def near(px, py, reach, edges, meta, start, ids):
    """Indices of the edges within ``reach`` of p, ascending (what a scan of every edge
    for point_segment_dist2 <= reach**2 gives), from the buckets of p's box."""
    x0, y0, cell, nx, ny = meta[0], meta[1], meta[2], int(meta[3]), int(meta[4])
    pad = reach + cell * SLACK
    c0 = max(index(px - pad, x0, cell, nx), 0)
    c1 = min(index(px + pad, x0, cell, nx), nx - 1)
    r0 = max(index(py - pad, y0, cell, ny), 0)
    r1 = min(index(py + pad, y0, cell, ny), ny - 1)
    k = 0
    for r in range(r0, r1 + 1):
        k += start[r * nx + c1 + 1] - start[r * nx + c0] if c0 <= c1 else 0
    out = np.empty(k, np.int64)
    k = 0
    r2 = reach * reach
    for r in range(r0, r1 + 1):
        if c0 > c1:
            break
        for j in range(start[r * nx + c0], start[r * nx + c1 + 1]):
            i = ids[j]
            if point_segment_dist2(px, py, edges[i, 0], edges[i, 1], edges[i, 2],
                                   edges[i, 3]) <= r2:
                out[k] = i
                k += 1
    return np.unique(out[:k])


@njit(cache=True)
def inside(px, py, edges, owner, nzones, meta, start, ids):
    """Zone id holding p (even-odd rule per zone), or -1, as
    :func:`_inside` answers: the edges crossing the ray from p to +x are
    those of p's row right of p, each counted in the one bucket its crossing lies in."""
    x0, y0, cell, nx, ny = meta[0], meta[1], meta[2], int(meta[3]), int(meta[4])
    count = np.zeros(nzones, np.int64)
    r = index(py, y0, cell, ny)
    if r < 0 or r >= ny:
        return -1
    c0 = max(index(px, x0, cell, nx), 0)
    for c in range(c0, nx):
        b = r * nx + c
        for j in range(start[b], start[b + 1]):
            i = ids[j]
            ax, ay, bx, by = edges[i, 0], edges[i, 1], edges[i, 2], edges[i, 3]
            if (ay > py) != (by > py):
                x = ax + (py - ay) * (bx - ax) / (by - ay)
                if px < x and min(max(index(x, x0, cell, nx), 0), nx - 1) == c:
                    count[owner[i]] += 1
    for k in range(nzones):
        if count[k] % 2 == 1:
            return k
    return -1


@njit(cache=True, inline="always")
def _touches_any(px, py, qx, qy, idx, edges, eps):
    """Segment pq touches one of the edges ``edges[idx]``."""
    for j in range(idx.shape[0]):
        i = idx[j]
        if _touch(px, py, qx, qy, edges[i, 0], edges[i, 1], edges[i, 2], edges[i, 3], eps):
            return True
    return False


@njit(cache=True)
def expand(px, py, deltas, tx, ty, edges, owner, nzones, bedges, meta, start, ids, eps,
           want_sees=True):
    """(clear (36,), sees (36,)) for the moves p + deltas[k] from a free point p (sees
    all False unless ``want_sees``); (meta, start, ids) the edges' bucket grid.

    Only edges within one move of p are tested for the moves; with none near, no move can
    enter a zone (it would cross an edge), so the point-in-zone test is skipped too.
    """
    n = deltas.shape[0]
    reach = 0.0
    for k in range(n):
        reach = max(reach, np.hypot(deltas[k, 0], deltas[k, 1]))
    near_ = near(px, py, reach + 2 * eps, edges, meta, start, ids)
    bnear = _near(px, py, bedges, reach + 2 * eps)
    clear = np.zeros(n, np.bool_)
    sees = np.zeros(n, np.bool_)
    bowner = np.zeros(bedges.shape[0], np.int64)  # the boundary is one ring
    for k in range(n):
        qx, qy = px + deltas[k, 0], py + deltas[k, 1]
        ok = not _touches_any(px, py, qx, qy, bnear, bedges, eps)
        if ok and bnear.shape[0] and _inside(qx, qy, bedges, bowner, 1) < 0:
            ok = False
        ok = ok and not _touches_any(px, py, qx, qy, near_, edges, eps)
        if ok and near_.shape[0] and inside(qx, qy, edges, owner, nzones, meta, start,
                                            ids) >= 0:
            ok = False
        clear[k] = ok
        if ok and want_sees:
            sees[k] = sight(qx, qy, tx, ty, edges, meta, start, ids)
    return clear, sees
