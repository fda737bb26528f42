"""Compiled geometry for the step drone: its 36 moves against polygon zones and a
boundary, one numba call per expansion (plain arrays in, masks out).

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


@njit(cache=True, inline="always")
def _touches_any(px, py, qx, qy, idx, edges, eps):
    """Segment pq touches one of the edges ``edges[idx]``."""
    for j in range(idx.shape[0]):
        i = idx[j]
        if _touch(px, py, qx, qy, edges[i, 0], edges[i, 1], edges[i, 2], edges[i, 3], eps):
            return True
    return False


@njit(cache=True)
def expand(px, py, deltas, tx, ty, edges, owner, nzones, bedges, eps, want_sees=True):
    """(clear (36,), sees (36,)) for the moves p + deltas[k] from a free point p (sees
    all False unless ``want_sees``).

    Only edges within one move of p are tested for the moves; with none near, no move can
    enter a zone (it would cross an edge), so the point-in-zone test is skipped too.
    """
    n = deltas.shape[0]
    reach = 0.0
    for k in range(n):
        reach = max(reach, np.hypot(deltas[k, 0], deltas[k, 1]))
    near = _near(px, py, edges, reach + 2 * eps)
    bnear = _near(px, py, bedges, reach + 2 * eps)
    clear = np.zeros(n, np.bool_)
    sees = np.zeros(n, np.bool_)
    bowner = np.zeros(bedges.shape[0], np.int64)  # the boundary is one ring
    for k in range(n):
        qx, qy = px + deltas[k, 0], py + deltas[k, 1]
        ok = not _touches_any(px, py, qx, qy, bnear, bedges, eps)
        if ok and bnear.shape[0] and _inside(qx, qy, bedges, bowner, 1) < 0:
            ok = False
        ok = ok and not _touches_any(px, py, qx, qy, near, edges, eps)
        if ok and near.shape[0] and _inside(qx, qy, edges, owner, nzones) >= 0:
            ok = False
        clear[k] = ok
        if ok and want_sees:
            s = True
            for i in range(edges.shape[0]):
                if crosses(qx, qy, tx, ty, edges[i, 0], edges[i, 1], edges[i, 2],
                            edges[i, 3]):
                    s = False
                    break
            sees[k] = s
    return clear, sees
