"""Which geometries enter polygon obstacles: meet the interior of their union.

Testing each obstacle alone is not enough where obstacles touch or overlap: a segment
along the face two touching boxes share (or crossing it at a shared corner) meets
neither box's interior, it only touches each, yet it runs through the building the two
make; a point on that face lies in neither interior either. City maps (FCND colliders,
``skyroute synth-city``) are full of touching and overlapping boxes.

A point lies in the union's interior but in no obstacle's interior only when it lies on
the boundaries of two or more obstacles that, closed, cover a neighbourhood of it; every
one of them meets a geometry through that point, and they meet each other there. So the
exact test is, per geometry: each obstacle's interior (the prepared per-obstacle test,
as before); then, for a geometry that only touches two or more obstacles some of which
meet each other, the interior of the union of those few (shapely's union). No union of
the whole map is built, and a geometry that touches no obstacle, or one, costs nothing
more.
"""

from __future__ import annotations

import numpy as np
import shapely

from skyroute.world.prepared_lock import LOCK

_NONE = np.iinfo(np.int64).max


def entered(polygons: np.ndarray, tree: shapely.STRtree, geoms) -> np.ndarray:
    """For each geometry of ``geoms`` (an array; points, lines, rings), the index of an
    obstacle of ``polygons`` (indexed by ``tree``) it enters, or -1 where it meets no
    interior of their union (touching edges and corners is allowed). The index is the
    lowest of the obstacles whose interior it meets, else the lowest of the touching
    obstacles whose union's interior it meets (for error messages). The obstacles are
    tested through their prepared forms, holding :data:`~skyroute.world.prepared_lock.LOCK`."""
    with LOCK:
        return _entered(polygons, tree, geoms)


def _entered(polygons: np.ndarray, tree: shapely.STRtree, geoms) -> np.ndarray:
    geoms = np.asarray(geoms, dtype=object).ravel()
    out = np.full(len(geoms), -1, np.int64)
    if len(polygons) == 0 or len(geoms) == 0:
        return out
    ig, io = tree.query(geoms, predicate="intersects")
    if len(ig) == 0:
        return out
    inside = ~shapely.touches(polygons[io], geoms[ig])
    first = np.full(len(geoms), _NONE, np.int64)
    np.minimum.at(first, ig[inside], io[inside])
    hit = first < _NONE
    out[hit] = first[hit]
    only_touch = ~hit & (np.bincount(ig, minlength=len(geoms)) >= 2)
    if only_touch.any():
        keep = only_touch[ig]
        ig, io = ig[keep], io[keep]
        order = np.argsort(ig, kind="stable")
        ig, io = ig[order], io[order]
        starts = np.flatnonzero(np.r_[True, ig[1:] != ig[:-1]])
        for g, members in zip(ig[starts], np.split(io, starts[1:]), strict=True):
            out[g] = _joined(polygons, np.sort(members), geoms[g])
    return out


def entered_one(polygons: np.ndarray, tree: shapely.STRtree, geom, *,
                lowest: bool = False) -> int:
    """:func:`entered` for one geometry (a leaner path for one segment at a time): the
    index of an obstacle it enters (with ``lowest``, the lowest, as :func:`entered`
    names it; without, the first found, which saves a sort), or -1."""
    if len(polygons) == 0:
        return -1
    with LOCK:
        return _entered_one(polygons, tree, geom, lowest)


def _entered_one(polygons: np.ndarray, tree: shapely.STRtree, geom, lowest: bool) -> int:
    hits = tree.query(geom, predicate="intersects")
    if lowest:
        hits = np.sort(hits)
    for j in hits:
        if not polygons[j].touches(geom):
            return int(j)
    return _joined(polygons, np.sort(hits), geom) if len(hits) >= 2 else -1


def _joined(polygons: np.ndarray, members: np.ndarray, geom) -> int:
    """The lowest of ``members`` (sorted obstacles that ``geom`` touches, none of whose
    interiors it meets) that meet another member, when ``geom`` meets the interior of
    those obstacles' union; else -1."""
    i, j = np.triu_indices(len(members), 1)
    meet = shapely.intersects(polygons[members[i]], polygons[members[j]])
    if not meet.any():
        return -1
    joined = np.unique(np.r_[members[i][meet], members[j][meet]])
    union = shapely.union_all(polygons[joined])
    return -1 if shapely.touches(union, geom) else int(joined[0])
