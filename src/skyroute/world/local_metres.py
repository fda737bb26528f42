"""A "degrees" world seen in metres: its (lon, lat) plane scaled by the metres per degree
of longitude and of latitude at the world's home.

Why: a vehicle whose options are distances (the potential field's step, sensor range
and tolerance) takes them in metres in every frame, so that the same value means the
same thing on a world in "degrees" as on the same world in "lonlat". The map is affine
(a shift and a scale per axis), so edges stay straight: a segment is free in one plane
exactly when its image is free in the other (up to rounding), and a path planned in
metres is a path of the "degrees" world. It is exact at home and off by the change of
the scale across the world (about 3e-4 over 1 km at 56 N), which the "degrees" frame's
flat plane itself ignores.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np
import shapely

from skyroute.caches import register
from skyroute.errors import OptionError
from skyroute.geo import Home, metres_per_degree
from skyroute.world.world import World


@dataclass(frozen=True, eq=False)
class LocalMetres:
    """``world`` in metres (frame "enu": east, north of ``origin``), ``origin`` (lon, lat)
    and ``scale`` (metres per degree of lon and of lat there)."""

    world: World
    origin: np.ndarray
    scale: np.ndarray

    def to_metres(self, points) -> np.ndarray:
        """(N, 2) plane points of the "degrees" world -> metres."""
        return (np.asarray(points, dtype=float).reshape(-1, 2) - self.origin) * self.scale

    def from_metres(self, points) -> np.ndarray:
        """(N, 2) metres -> plane points of the "degrees" world."""
        return np.asarray(points, dtype=float).reshape(-1, 2) / self.scale + self.origin

    def heading_to_metres(self, heading: float) -> float:
        """A plane heading of the "degrees" world (radians anticlockwise from +lon, on the
        flat lon/lat plane) -> the same direction's heading in metres."""
        return math.atan2(self.scale[1] * math.sin(heading),
                          self.scale[0] * math.cos(heading))


_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
register(_CACHE.clear)


def local_metres(world: World, *, near=None) -> LocalMetres:
    """``world`` (frame "degrees") in metres around its home; a world built without one
    is scaled at the centre of its bounds, or, with no obstacles and no boundary, at
    ``near`` (a plane point: the start). Cached per world (not for ``near``)."""
    if world.frame != "degrees":
        raise OptionError(f"world {world.name!r} is in frame {world.frame!r}, whose plane "
                          "is already metres", param="world")
    if world in _CACHE:
        return _CACHE[world]
    cache = True
    if world.home is not None:
        origin = np.array([world.home.lon, world.home.lat])
    elif world.boundary is not None or len(world.obstacles):
        x0, y0, x1, y1 = world.bounds
        origin = np.array([(x0 + x1) / 2, (y0 + y1) / 2])
    else:
        origin, cache = np.asarray(near, dtype=float).reshape(2), False
    scale = metres_per_degree(Home(*origin))
    if not (np.isfinite(scale).all() and scale.min() > 1e3):
        raise OptionError(f"world {world.name!r} lies at latitude {origin[1]:g}: at a pole "
                          "(within half a degree) a degree of longitude is shorter than "
                          "1 km, and distances in metres have no steady size in the "
                          "degrees frame; load it in frame 'lonlat'", param="world")

    def move(p):
        return (p - origin) * scale

    boundary = None if world.boundary is None else shapely.transform(world.boundary, move)
    out = LocalMetres(World(shapely.transform(world.obstacles, move), world.floors,
                            world.ceilings, world.names, boundary, "enu", None,
                            world.name, world.source), origin, scale)
    if cache:
        _CACHE[world] = out
    return out
