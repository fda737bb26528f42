"""The free point nearest to a point inside an obstacle, as an error suggests it.

A start or goal inside an obstacle is refused with a free point to use instead. That
point must be free in the world, not only outside the obstacle named: boxes of a
colliders city overlap (the FCND city is built of touching 10 m boxes, and ``safety``
grows them into each other), so the edge of one box is often inside its neighbour, and a
gap between boxes inside a block is free but closed in. And it must be free as printed,
since the caller types it back: a point 1 mm outside an edge, shown to the cm, can round
back inside. And it must be off the edge, not on it: a point on an edge is free, but a
turning vehicle cannot leave it (Hybrid A*'s pieces keep clear of every edge).
"""

from __future__ import annotations

import numpy as np
import shapely

from skyroute.world.prepared_lock import LOCK

# Candidates are stepped out from the block's edge in these many directions (and straight
# away from the point), up to STEPS steps of a tenth of the printed resolution.
DIRECTIONS = 16
STEPS = 50


def nearest_free(world, p: np.ndarray, j: int, decimals: int) -> np.ndarray | None:
    """A free plane point of ``world`` nearest the plane point ``p`` (inside obstacle
    ``j``) outside the block of obstacles joined to ``j`` (holes filled: a point closed in
    by the block is no way out), still free when its coordinates in the world's frame are
    rounded to ``decimals`` (as the error prints them); None when there is none."""
    pt = shapely.Point(p)
    block = _block(world, j)
    free = shapely.boundary(block)
    if world.boundary is not None:
        free = shapely.difference(world.boundary, block)
    if free.is_empty:
        return None
    q = np.array(shapely.shortest_line(pt, free).coords[-1])
    return _stepped_out(world, block, p, q, decimals)


def _block(world, j: int):
    """The union of obstacle ``j`` and every obstacle joined to it through others that
    touch or overlap, its holes filled."""
    members = {j}
    frontier = np.array([j])
    while len(frontier):
        with LOCK:  # the obstacles are prepared, and tested through that form
            _, found = world.tree.query(world.obstacles[frontier], predicate="intersects")
        new = set(found.tolist()) - members
        members |= new
        frontier = np.array(sorted(new), dtype=np.int64)
    union = shapely.union_all(world.obstacles[sorted(members)])
    parts = shapely.get_parts(union)
    return shapely.union_all(shapely.polygons(shapely.get_exterior_ring(parts)))


def _stepped_out(world, block, p: np.ndarray, q: np.ndarray,
                 decimals: int) -> np.ndarray | None:
    """Of the points stepped out from ``q`` (on the block's edge) whose rounded form is
    free and off every obstacle (on no edge), the one nearest ``p``, as typed back from
    its rounded form."""
    step = 10.0 ** -decimals / 10 if world.frame == "degrees" else 1e-3
    away = (q - p) / (np.hypot(*(q - p)) or 1.0)
    angles = np.linspace(0, 2 * np.pi, DIRECTIONS, endpoint=False)
    dirs = np.vstack([away, np.column_stack([np.cos(angles), np.sin(angles)])])
    k = np.arange(1, STEPS + 1)[:, None, None] * step
    cand = (q + k * dirs[None]).reshape(-1, 2)
    back = world.to_plane(np.round(world.from_plane(cand), decimals) + 0.0)  # no -0.00
    # off the block's edge, not on it: a point on an edge is free, but no turning
    # vehicle can leave it (Hybrid A*'s pieces keep clear of every edge: no_path)
    pts = shapely.points(back)
    ok = np.flatnonzero(world.is_free(back) & shapely.disjoint(pts, block)
                        & ~world_touches(world, pts))
    if len(ok) == 0:
        return None
    return back[ok[np.argmin(np.hypot(*(back[ok] - p).T))]]


def world_touches(world, pts) -> np.ndarray:
    """True for each point on an obstacle's edge (free, but on it)."""
    out = np.zeros(len(pts), bool)
    if len(world.obstacles):
        ip, _ = world.tree.query(pts, predicate="intersects")
        out[ip] = True
    return out
