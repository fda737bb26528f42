"""Plane geometry shared across layers: convex corners of obstacle unions (visibility
graphs, the step drone's heuristic) and the compiled point-segment distance (rasterising
walls, the step drone's move test)."""

from __future__ import annotations

import numpy as np
import shapely
from numba import njit


@njit(cache=True)
def point_segment_dist2(px, py, ax, ay, bx, by):
    """Squared distance from point p to segment ab (compiled)."""
    dx, dy = bx - ax, by - ay
    L2 = dx * dx + dy * dy
    t = 0.0
    if L2 > 0.0:
        t = ((px - ax) * dx + (py - ay) * dy) / L2
        t = min(1.0, max(0.0, t))
    qx, qy = ax + t * dx - px, ay + t * dy - py
    return qx * qx + qy * qy



def convex_corners(world) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(corners, previous, next): the convex corners of the union of the obstacles, with
    their neighbours along the ring (obstacle interior on the left)."""
    if len(world.obstacles) == 0:
        e = np.empty((0, 2))
        return e, e, e
    merged = shapely.orient_polygons(shapely.unary_union(world.obstacles))
    # exterior counter-clockwise, holes clockwise: the obstacle is on the left
    return ring_corners([np.asarray(ring.coords)[:-1]
                         for poly in getattr(merged, "geoms", [merged])
                         if poly.geom_type == "Polygon"
                         for ring in (poly.exterior, *poly.interiors)])


def boundary_corners(boundary) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(corners, previous, next) where a path kept inside ``boundary`` may have to bend:
    the reflex corners of its exterior and the convex corners of its holes, that is the
    convex corners of the region outside it (on the left along the rings)."""
    b = shapely.orient_polygons(shapely.Polygon(boundary))
    # reversed, the exterior runs clockwise and the holes counter-clockwise
    return ring_corners([np.asarray(ring.coords)[-2::-1]
                         for ring in (b.exterior, *b.interiors)])


def ring_corners(rings) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(corners, previous, next): the convex corners of rings ((K, 2) arrays, not closed)
    that have the blocked side on their left, with their ring neighbours."""
    corners, prevs, nexts = [np.empty((0, 2))], [np.empty((0, 2))], [np.empty((0, 2))]
    for c in rings:
        prev, nxt = np.roll(c, 1, axis=0), np.roll(c, -1, axis=0)
        u, v = c - prev, nxt - c
        cross = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
        scale = np.hypot(*u.T) * np.hypot(*v.T)
        keep = cross > 1e-12 * scale  # convex, not collinear
        corners.append(c[keep])
        prevs.append(prev[keep])
        nexts.append(nxt[keep])
    return np.concatenate(corners), np.concatenate(prevs), np.concatenate(nexts)
