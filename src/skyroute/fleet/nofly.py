"""No-fly zones in a fleet scenario: cruise routes around them, checks for the rest.

A scenario's ``no_fly_zones`` are polygons of (north, east) metres. The cruise from the
climb-out pose to the approach gate is the shortest Dubins path when it stays clear of
every zone, else a Hybrid A* path (:func:`skyroute.motion.hybrid.plan`, same turning
radius, exact arcs and straights) around them. The straight parts a flight cannot bend
(the climb along the take-off runway, the final approach, a loiter circle) are checked
and an error names the airport and the zone when one crosses a zone.

Plane convention (as :mod:`skyroute.motion`): x east, y north, headings anticlockwise
from +x.
"""

from __future__ import annotations

import functools

import numpy as np
import shapely

from skyroute.errors import QueryError
from skyroute.motion import hybrid
from skyroute.motion.dubins import DubinsPath
from skyroute.motion.pieces import KINDS, chain
from skyroute.world.world import World


@functools.lru_cache(maxsize=8)
def _world(zones: tuple[tuple[str, tuple[tuple[float, float], ...]], ...]) -> World:
    polys = np.array([shapely.Polygon([(e, n) for n, e in pts]) for _, pts in zones],
                     dtype=object)
    k = len(polys)
    return World(polys, np.full(k, -np.inf), np.full(k, np.inf), tuple(n for n, _ in zones))


def zone_world(scenario) -> World | None:
    """The scenario's zones as a World in the (east, north) plane, or None."""
    if not scenario.no_fly_zones:
        return None
    return _world(tuple((z.name, tuple(map(tuple, z.points))) for z in scenario.no_fly_zones))


def crossed(scenario, geometry) -> str | None:
    """The name of the first zone whose interior ``geometry`` (in the (east, north)
    plane) meets, or None."""
    for z in scenario.no_fly_zones:
        poly = shapely.Polygon([(e, n) for n, e in z.points])
        if geometry.intersects(poly) and not geometry.touches(poly):
            return z.name
    return None


def check_line(scenario, p0, p1, what: str) -> None:
    """Raise a QueryError naming ``what`` and the zone when the straight from ``p0`` to
    ``p1`` ((north, east) metres) enters a zone."""
    if not scenario.no_fly_zones:
        return
    line = shapely.LineString([(p0[1], p0[0]), (p1[1], p1[0])])
    name = crossed(scenario, line)
    if name is not None:
        raise QueryError(f"{what} crosses no-fly zone {name!r}", param="no_fly_zones")


def circle_clear(scenario, centre, radius: float) -> bool:
    """True when the circle (centre (north, east), ``radius``) enters no zone."""
    ring = shapely.Point(centre[1], centre[0]).buffer(radius, quad_segs=64).exterior
    return crossed(scenario, ring) is None


def cruise(scenario, start, goal, radius: float, path: DubinsPath, *,
           what: str = "flight") -> list[tuple[str, float]]:
    """(letter, length) pieces of the cruise from plane pose ``start`` to ``goal``: the
    Dubins ``path`` when it is clear of the zones, else a Hybrid A* path."""
    world = zone_world(scenario)
    words = list(zip(path.word, path.segments, strict=True))
    if world is None:
        return words
    pieces = chain(start, [KINDS[c] for c in path.word], path.segments, radius)
    if hybrid.path_free(world, pieces):
        return words
    res = hybrid.plan(world, start, goal, radius)
    if not res.found:
        raise QueryError(f"{what}: no cruise around the no-fly zones from the climb-out "
                         f"({start[1]:.0f} N, {start[0]:.0f} E) to the approach gate "
                         f"({goal[1]:.0f} N, {goal[0]:.0f} E): {res.status.value}",
                         param="no_fly_zones")
    return [(p.kind, p.length) for p in res.segments]

