"""No-fly zones in a fleet scenario: cruise routes around them, checks for the rest.

A scenario's ``no_fly_zones`` are polygons of (north, east) metres. The cruise from the
climb-out pose to the approach gate is the shortest Dubins path when it stays clear of
every zone, else a Hybrid A* path (:func:`skyroute.motion.hybrid.plan`, same turning
radius, exact arcs and straights) around them. The straight parts a flight cannot bend
(the climb along the take-off runway, the final approach, a loiter circle) are checked
and an error names the airport and the zone when one crosses a zone. Airports that zones
close a ring round, so that no cruise can join them to the others, are refused before a
run (:func:`check_joined`), not when that pair is first flown.

Plane convention (as :mod:`skyroute.motion`): x east, y north, headings anticlockwise
from +x.
"""

from __future__ import annotations

import functools

import numpy as np
import shapely

from skyroute.errors import InputFormatError, QueryError
from skyroute.motion import hybrid
from skyroute.motion.dubins import DubinsPath
from skyroute.motion.pieces import KINDS, chain
from skyroute.result import Status
from skyroute.world.interiors import entered_one
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


@functools.lru_cache(maxsize=8)
def _indexed(zones: tuple[tuple[str, tuple[tuple[float, float], ...]], ...]):
    """(names, polygons in the (east, north) plane, their STRtree, which prepares
    them): those of :func:`_world`'s World, held per set of zones, as a check before a
    run tests every airport at every level."""
    world = _world(zones)
    return list(world.names), world.obstacles, world.tree


_LAST: tuple = (None, None)  # (a scenario's list of zones, its index)


def _zone_index(scenario):
    """:func:`_indexed` of the scenario's zones; the last list's is kept by identity, as
    the cache's key (every corner) took a millisecond to build for 1000 zones, each
    check."""
    global _LAST
    zones = scenario.no_fly_zones
    last, index = _LAST  # one read: another thread may replace it
    if last is not zones:
        index = _indexed(tuple((z.name, tuple(map(tuple, z.points))) for z in zones))
        _LAST = (zones, index)  # holding the list keeps its id from being reused
    return index


def crossed(scenario, geometry) -> str | None:
    """The name of the first zone whose interior ``geometry`` (in the (east, north)
    plane) meets, or None. Zones that touch count as one: a line along the edge two
    zones share runs inside them (:func:`~skyroute.world.interiors.entered_one`)."""
    if not scenario.no_fly_zones:
        return None
    names, polys, tree = _zone_index(scenario)
    k = entered_one(polys, tree, geometry, lowest=True)
    return None if k < 0 else names[k]


def check_line(scenario, p0, p1, what: str) -> None:
    """Raise a QueryError naming ``what`` and the zone when the straight from ``p0`` to
    ``p1`` ((north, east) metres) enters a zone."""
    if not scenario.no_fly_zones:
        return
    line = shapely.LineString([(p0[1], p0[0]), (p1[1], p1[0])])
    name = crossed(scenario, line)
    if name is not None:
        raise QueryError(f"{what} crosses no-fly zone {name!r}", param="no_fly_zones")


def circle_crossed(scenario, centre, radius: float) -> str | None:
    """The name of the first zone the circle (centre (north, east), ``radius``) enters,
    or None."""
    if not scenario.no_fly_zones:
        return None
    n, e = centre
    if not len(_zone_index(scenario)[2].query(shapely.box(e - radius, n - radius,
                                                           e + radius, n + radius))):
        return None  # no zone near: the ring is not built
    return crossed(scenario, shapely.Point(e, n).buffer(radius, quad_segs=64).exterior)


def circle_clear(scenario, centre, radius: float) -> bool:
    """True when the circle (centre (north, east), ``radius``) enters no zone."""
    return circle_crossed(scenario, centre, radius) is None


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
    pair = (f"from the climb-out ({start[1]:.0f} N, {start[0]:.0f} E) to the approach "
            f"gate ({goal[1]:.0f} N, {goal[0]:.0f} E)")
    if res.status is Status.BUDGET_EXHAUSTED:  # not a proof that no cruise exists
        raise QueryError(f"{what}: the search for a cruise with a {radius:g} m turning "
                         f"radius round the no-fly zones {pair} ran out of its budget "
                         f"({res.extra['budget']:,} expansions): it found none, nor "
                         "showed that none exists", param="no_fly_zones")
    if not res.found:  # joined in the plane (check_joined), yet too narrow to turn in
        raise QueryError(f"{what}: no cruise with a {radius:g} m turning radius gets round "
                         f"the no-fly zones {pair}", param="no_fly_zones")
    return [(p.kind, p.length) for p in res.segments]


def cut_off(scenario) -> tuple[list[str], list[str], list[str]] | None:
    """None when no ring of no-fly zones parts the airports, else (the airports inside
    the first such ring, those outside it, the ring's zones as the message names them).

    A cheap necessary condition for every cruise, in place of one Hybrid A* search per
    pair of airports: both ends in one connected part of the plane outside the zones.
    The zones are grown by the clearance the planner keeps from every edge (1e-9 of
    their extent, :func:`skyroute.motion.hybrid.path_free`), so zones that touch, or
    leave a gap no path fits through, close a ring as one zone would. The plane outside
    the grown zones is joined unless their union has a hole holding some airports and
    not others. (An airport's runway is clear of every zone and its climb-out and final
    approach are checked by :func:`check_line`, so the airport stands for both ends of
    its cruises.) A gap too narrow to turn in is not caught here: the planner finds no
    cruise through it when the pair is first flown.

    The ring's zones are those that border the hole (their grown polygons reach its
    boundary), not every zone joined to them: a chain of zones running out from the ring
    closes nothing and is not named.
    """
    zones = scenario.no_fly_zones
    if not zones:
        return None
    polys = [shapely.Polygon([(e, n) for n, e in z.points]) for z in zones]
    x0, y0, x1, y1 = shapely.total_bounds(polys)
    grow = 1e-9 * max(1.0, x1 - x0, y1 - y0)
    grown = shapely.buffer(polys, grow)
    ports = shapely.points([(a.east, a.north) for a in scenario.airports])
    ids = [a.id for a in scenario.airports]
    names = [z.name for z in zones]
    for part in shapely.get_parts(shapely.union_all(grown)):
        for ring in part.interiors:
            inside = shapely.contains(shapely.Polygon(ring), ports)
            if inside.any() and not inside.all():
                # the union's nodes where two zones cross are rounded, so a zone that
                # borders the hole can miss its ring by ~1e-13 m: a tolerance of half
                # the growth, far above that and far below any zone's width
                border = shapely.dwithin(grown, ring, grow / 2)
                ring_zones = [repr(n) if names.count(n) == 1 else f"no_fly_zones[{k}]"
                              for k, (n, b) in enumerate(zip(names, border, strict=True))
                              if b]
                return ([i for i, x in zip(ids, inside, strict=True) if x],
                        [i for i, x in zip(ids, inside, strict=True) if not x], ring_zones)
    return None


def check_joined(scenario, where: object = "scenario") -> None:
    """An InputFormatError naming ``where`` (the file), two airports and the zones when
    no-fly zones close a ring round some airports and not others (:func:`cut_off`): no
    cruise could join them, and a run would fail when that pair is first flown."""
    found = cut_off(scenario)
    if found is None:
        return
    inside, outside, ring = found
    zones = f"zones {', '.join(ring)} close" if len(ring) > 1 else f"zone {ring[0]} closes"
    more = len(inside) - 1
    others = f" and {more} other airport{'s' if more > 1 else ''}" if more else ""
    raise InputFormatError(where, f"no_fly_zones: no cruise can join airports {inside[0]} "
                           f"and {outside[0]}: {zones} a ring round {inside[0]}{others} "
                           "(zones that touch leave no gap)")
