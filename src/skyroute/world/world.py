"""A continuous world: polygon obstacles with heights, an optional boundary, a frame.

Geometry lives in a plane: east and north metres around ``home`` (frames "lonlat",
"ned", "enu"), or longitude and latitude read as a flat plane (frame "degrees", the ILP
rules). A World remembers the frame it was loaded in: its public queries read points in
that frame and planners return paths in it; :meth:`World.to_plane` and
:meth:`World.from_plane` are the one pair of conversions (see :mod:`skyroute.geo` for the
table of frames). Obstacles are shapely polygons with a floor and a ceiling;
``at(altitude)`` keeps those that count at an altitude. Queries are exact and vectorised
(shapely 2 and an STRtree): a point is free when it lies in no obstacle's interior and
strictly inside the boundary; a segment is free when it meets no interior of the
obstacles' union and lies strictly inside the boundary (touching an obstacle's edge or
corner is allowed; a face two touching obstacles share lies inside their union).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import shapely
from shapely import STRtree

from skyroute.errors import OptionError, QueryError, check_choice, real, renamed
from skyroute.geo import (
    FRAME_ALIASES,
    FRAMES,
    Home,
    enu_to_lonlat,
    heading_from_plane,
    heading_to_plane,
    lonlat_to_enu,
    metres_per_degree_north,
)
from skyroute.world.grid import Grid, raster_shape
from skyroute.world.interiors import entered, entered_one
from skyroute.world.nearest_free import nearest_free
from skyroute.world.points import (
    MAX_METRES,
    MAX_REACH,
    as_points,
    check_metres,
    check_places,
    plane_points,
)
from skyroute.world.prepared_lock import LOCK

AXES = {"lonlat": ("lon", "lat"), "degrees": ("lon", "lat"), "ned": ("north", "east"),
        "enu": ("x", "y")}


def _flat(geoms):
    """Geometries (one, or an object array) without their z: a GeoJSON zone may carry a
    height per vertex ([lon, lat, alt]), which the plane ignores (floors and ceilings
    say the heights), and a 3-D ring failed in the visibility graph's corner code
    (numpy's "array dimensions ... must match"). Anything not a geometry is left as it
    is, for the planners to refuse."""
    try:
        has_z = bool(np.any(shapely.has_z(geoms)))
    except TypeError:
        return geoms
    return shapely.force_2d(geoms) if has_z else geoms


def _check_finite(obstacles, names, boundary) -> None:
    """An OptionError naming the first obstacle (or the boundary) with a coordinate that
    is not finite. The loaders refuse one in a file; a World built in code reached the
    planners with it (the step drone's edge grid raised numpy's "cannot convert float NaN
    to integer"). Anything not a geometry is left for the planners to refuse."""
    for what, geoms in (("obstacle", obstacles), ("boundary", boundary)):
        if geoms is None:
            continue
        try:
            xy, index = shapely.get_coordinates(geoms, return_index=True)
        except (TypeError, shapely.errors.GEOSException):
            continue
        bad = np.flatnonzero(~np.isfinite(xy).all(axis=1))
        if len(bad):
            k = int(index[bad[0]])
            who = "the boundary" if what == "boundary" else f"obstacle {k} ({names[k]!r})"
            x, y = map(float, xy[bad[0]])
            raise OptionError(f"{who} has a vertex that is not finite ({x!r}, {y!r}): "
                              "every coordinate must be a finite number")


@dataclass(frozen=True, eq=False)
class World:
    """Polygon obstacles (with floors and ceilings), a boundary, a frame and a home.

    Obstacles and boundary are given in the plane (shapely x, y: east, north metres, or
    lon, lat in the "degrees" frame). ``frame`` says how callers give and get points:
    "enu" (the default: the plane itself), "ned" ("local" is an alias), "lonlat" (needs
    ``home``) or "degrees". ``name`` titles tables and pictures (a file's base name);
    ``source`` is the file as the caller named it (None for a world built in code), which
    errors about the whole world name. Neither takes part in equality (a World is equal
    only to itself) nor in the caches' keys.
    """

    obstacles: np.ndarray  # object array of shapely Polygons
    floors: np.ndarray
    ceilings: np.ndarray
    names: tuple[str, ...]
    boundary: shapely.Polygon | None = None
    frame: str = "enu"
    home: Home | None = None
    name: str = field(default="world", compare=False)
    source: str | None = field(default=None, compare=False)

    def __post_init__(self) -> None:
        obs = np.asarray(self.obstacles, dtype=object).ravel()
        frame = FRAME_ALIASES.get(self.frame, self.frame)
        if frame == "metres":
            warnings.warn("frame='metres' is deprecated; use 'enu' (the same plane)",
                          DeprecationWarning, stacklevel=3)
            frame = "enu"
        if frame not in FRAMES:
            raise OptionError(f"frame={self.frame!r} is not valid; choose one of "
                              + ", ".join(repr(f) for f in (*FRAMES, *FRAME_ALIASES)))
        if frame == "lonlat" and self.home is None:
            raise OptionError("frame='lonlat' needs a home (the origin of the metres plane)")
        object.__setattr__(self, "frame", frame)
        n = len(obs)
        floors = np.broadcast_to(np.asarray(self.floors, dtype=float), (n,)).copy()
        ceilings = np.broadcast_to(np.asarray(self.ceilings, dtype=float), (n,)).copy()
        names = tuple(self.names) if self.names else tuple(f"obstacle {i}" for i in range(n))
        if len(names) != n:
            raise OptionError(f"{len(names)} names for {n} obstacles")
        object.__setattr__(self, "obstacles", _flat(obs))
        if self.boundary is not None:
            object.__setattr__(self, "boundary", _flat(self.boundary))
        _check_finite(self.obstacles, names, self.boundary)
        object.__setattr__(self, "floors", floors)
        object.__setattr__(self, "ceilings", ceilings)
        object.__setattr__(self, "names", names)

    def __repr__(self) -> str:
        """A summary, not thousands of polygons."""
        home = "" if self.home is None else \
            f", home ({self.home.lon:.6f}, {self.home.lat:.6f})"
        boundary = "" if self.boundary is None else ", a boundary"
        return (f"<World {self.name!r}: {len(self.obstacles)} obstacles{boundary}, "
                f"frame {self.frame!r}{home}>")

    @property
    def where(self) -> str:
        """What an error about the whole world names: its file as given, else its name."""
        return self.name if self.source is None else self.source

    # -- frames ----------------------------------------------------------------------

    @property
    def plane(self) -> str:
        """The plane's units: "metres" (east, north) or "degrees" (lon, lat)."""
        return "degrees" if self.frame == "degrees" else "metres"

    @property
    def has_lonlat(self) -> bool:
        """True when plane points can be given as lon/lat (a home, or the degrees frame)."""
        return self.frame == "degrees" or self.home is not None

    def metres_in_plane(self, metres: float, *, near=None) -> float:
        """A distance of ``metres`` in the plane's units: itself in the metres frames; in
        "degrees", ``metres`` over the metres per degree of latitude
        (:func:`~skyroute.geo.metres_per_degree_north`) at the world's home, else at the
        centre of its extent, else at ``near`` (a plane point: a run's start).

        What a vehicle's distance defaults, documented in metres, are in this world's
        plane (a value the caller gives is plane units, as every distance of a World).
        The degrees plane is flat and isotropic in degrees, so one scale serves every
        direction; the north one is chosen because a degree of latitude is a degree
        everywhere (110.6 to 111.7 km, pole included), so the default is never longer
        on the ground than its metres: north it is as long, east cos(latitude) of it
        (a geometric mean of the two scales would grow without bound near a pole)."""
        metres = real("metres", metres)
        if self.frame != "degrees":
            return metres
        if self.home is not None:
            lat = self.home.lat
        elif self.boundary is not None or len(self.obstacles):
            lat = (self.bounds[1] + self.bounds[3]) / 2
        elif near is not None:
            lat = float(np.asarray(near, dtype=float).reshape(2)[1])
        else:
            raise OptionError(f"world {self.name!r} (frame 'degrees') has no home, extent "
                              "or point to measure a metre at")
        return metres / metres_per_degree_north(lat)

    def to_plane(self, points, what: str = "points") -> np.ndarray:
        """Points in the world's frame -> (N, 2) plane points; a malformed input is a
        QueryError naming ``what``."""
        p = as_points(points, what)
        if self.frame == "ned":
            return check_metres(p, what)[:, ::-1].copy()
        if self.frame == "enu":
            return check_metres(p, what)
        if self.frame in ("lonlat", "degrees"):
            check_places(p, what)
        if self.frame == "lonlat":
            return lonlat_to_enu(p[:, 0], p[:, 1], 0.0, self.home)[:, :2] if len(p) else p
        return p

    def from_plane(self, points) -> np.ndarray:
        """(N, 2) plane points -> points in the world's frame."""
        p = plane_points(points)
        if self.frame == "ned":
            return p[:, ::-1].copy()
        if self.frame == "lonlat":
            return self.plane_to_lonlat(p)
        return p.copy()

    def plane_to_lonlat(self, points) -> np.ndarray:
        """(N, 2) plane points -> (lon, lat) degrees."""
        return self._through_home(points, enu_to_lonlat)

    def plane_from_lonlat(self, lonlat) -> np.ndarray:
        """(N, 2) (lon, lat) degrees -> plane points."""
        return self._through_home(lonlat, lonlat_to_enu)

    def _through_home(self, points, convert) -> np.ndarray:
        p = plane_points(points)
        if self.frame == "degrees" or len(p) == 0:
            return p.copy()
        if self.home is None:
            raise OptionError(f"world {self.name!r} has no home, so no lon/lat")
        return convert(p[:, 0], p[:, 1], 0.0, self.home)[:, :2]

    def heading_to_plane(self, heading):
        """A heading in the world's frame (radians) -> plane radians from +x."""
        return heading_to_plane(heading, self.frame)

    def heading_from_plane(self, heading):
        """A plane heading (radians from +x, anticlockwise) -> the world's frame."""
        return heading_from_plane(heading, self.frame)

    def to_lonlat(self, points, what: str = "points") -> np.ndarray:
        """Points in the world's frame -> (N, 2) (lon, lat) degrees (unchanged, bit for
        bit, in the frames whose points are lon/lat)."""
        if self.frame in ("lonlat", "degrees"):
            return check_places(as_points(points, what), what)
        return self.plane_to_lonlat(self.to_plane(points, what))

    def in_frame(self, frame: str) -> World:
        """The same world read and written in another frame. Between the metres frames
        only the point interface changes; to or from "degrees" every vertex is carried
        exactly through lon/lat (edges stay straight in the new plane, which differs from
        the old by millimetres over hundreds of metres)."""
        frame = FRAME_ALIASES.get(frame, frame)
        check_choice("frame", frame, FRAMES)
        obstacles, boundary = self.obstacles, self.boundary
        if (frame == "degrees") != (self.frame == "degrees"):
            if self.home is None:
                raise OptionError(f"frame={frame!r}: world {self.name!r} has no home, so "
                                  "no lon/lat", param="frame")
            to_new = self.plane_to_lonlat if frame == "degrees" else \
                World([], [], [], (), None, "lonlat", self.home).plane_from_lonlat
            obstacles = shapely.transform(self.obstacles, to_new)
            boundary = None if boundary is None else shapely.transform(boundary, to_new)
        return World(obstacles, self.floors, self.ceilings, self.names, boundary, frame,
                     self.home, self.name, self.source)

    # -- views -----------------------------------------------------------------------

    def at(self, altitude: float | None) -> World:
        """The obstacles that count at ``altitude`` (floor <= altitude < ceiling); None: all."""
        if altitude is None:
            return self
        altitude = real("altitude", altitude)  # a NaN kept no obstacle: an empty world
        keep = (self.floors <= altitude) & (self.ceilings > altitude)
        return World(self.obstacles[keep], self.floors[keep], self.ceilings[keep],
                     tuple(np.asarray(self.names, dtype=object)[keep]), self.boundary,
                     self.frame, self.home, self.name, self.source)

    @cached_property
    def tree(self) -> STRtree:
        """Spatial index over the obstacles (which are prepared for fast predicates, under
        :data:`~skyroute.world.prepared_lock.LOCK`, as every test through them runs)."""
        with LOCK:
            shapely.prepare(self.obstacles)
            return STRtree(self.obstacles)

    def merged(self) -> World:
        """The same free space with overlapping or touching obstacles fused into one
        polygon each: fewer, larger obstacles, and no zero-width gap along a shared edge.
        Floors and ceilings are dropped (use :meth:`at` first)."""
        if len(self.obstacles) == 0:
            return self
        union = shapely.unary_union(self.obstacles)
        parts = np.array(list(getattr(union, "geoms", [union])), dtype=object)
        parts = parts[shapely.get_type_id(parts) == 3]  # polygons only
        n = len(parts)
        ip, io = self.tree.query(parts, predicate="intersects")
        names = []
        for i in range(n):
            members = np.sort(io[ip == i])
            first = self.names[members[0]] if len(members) else f"block {i}"
            names.append(first if len(members) <= 1 else f"{first} and {len(members) - 1} more")
        return World(parts, np.full(n, -np.inf), np.full(n, np.inf), tuple(names),
                     self.boundary, self.frame, self.home, self.name, self.source)

    @cached_property
    def _prepared_boundary(self):
        if self.boundary is None:
            return None
        b = shapely.Polygon(self.boundary)  # a copy of its own: prepared, held by LOCK
        shapely.prepare(b)
        return b

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) of the boundary, or of the obstacles without one."""
        if self.boundary is not None:
            return tuple(self.boundary.bounds)
        if len(self.obstacles) == 0:
            raise OptionError("a world with no obstacles and no boundary has no extent")
        b = shapely.total_bounds(self.obstacles)
        return tuple(float(v) for v in b)

    # -- exact queries ---------------------------------------------------------------

    def inside(self, points) -> np.ndarray:
        """True where a point lies strictly inside the boundary (always, without one)."""
        p = plane_points(points)
        if self.boundary is None:
            return np.ones(len(p), bool)
        pts = shapely.points(p)
        with LOCK:
            return shapely.contains_properly(self._prepared_boundary, pts)

    def blocking(self, points) -> np.ndarray:
        """Index of an obstacle whose interior holds each point, or -1. A point on the
        face two touching obstacles share lies inside their union, so it is blocked
        too (by the lowest-numbered of them); one on an outer edge is free."""
        p = plane_points(points)
        if len(self.obstacles) == 0:
            return np.full(len(p), -1, np.int64)
        return entered(self.obstacles, self.tree, shapely.points(p))

    def is_free(self, points) -> np.ndarray:
        """True where a point is in no interior of the obstacles' union (:meth:`blocking`)
        and strictly inside the boundary."""
        return (self.blocking(points) < 0) & self.inside(points)

    def segments_free(self, a, b) -> np.ndarray:
        """True for each segment a[i] -> b[i] that meets no interior of the obstacles'
        union and lies strictly inside the boundary. a, b: (N, 2). Touching an edge or a
        corner is allowed; running along (or through) a face two touching obstacles
        share is not (:mod:`skyroute.world.interiors`)."""
        a, b = _segment_ends(a, b)
        n = len(a)
        ok = np.ones(n, bool)
        if n == 0:
            return ok
        same = np.all(a == b, axis=1)
        coords = np.stack([a, b], axis=1)
        lines = shapely.linestrings(coords[~same])
        idx = np.flatnonzero(~same)
        if len(self.obstacles) and len(lines):
            ok[idx] = entered(self.obstacles, self.tree, lines) < 0
        if same.any():
            ok[same] = self.is_free(a[same])
        if self.boundary is not None and len(lines):
            with LOCK:
                ok[idx] &= shapely.contains_properly(self._prepared_boundary, lines)
        return ok

    def segments_clear(self, a, b) -> np.ndarray:
        """Stricter than :meth:`segments_free`: the segment may not even touch an obstacle
        (closed polygons), and lies strictly inside the boundary. The ILP rules' test."""
        a, b = _segment_ends(a, b)
        lines = shapely.linestrings(np.stack([a, b], axis=1))
        ok = np.ones(len(a), bool)
        if len(self.obstacles):
            il, _ = self.tree.query(lines, predicate="intersects")
            ok[il] = False
        if self.boundary is not None:
            with LOCK:
                ok &= shapely.contains_properly(self._prepared_boundary, lines)
        return ok

    def segment_free(self, a, b) -> bool:
        """:meth:`segments_free` for one segment (a leaner path: 70 us, not 120, here)."""
        a = np.asarray(a, dtype=float)
        b = np.asarray(b, dtype=float)
        if np.array_equal(a, b):
            return bool(self.is_free([a])[0])
        line = shapely.LineString([a, b])
        if self.boundary is not None:
            with LOCK:
                if not self._prepared_boundary.contains_properly(line):
                    return False
        return not len(self.obstacles) or entered_one(self.obstacles, self.tree, line) < 0

    def clearance(self, points) -> np.ndarray:
        """Distance from each point to the nearest obstacle (0 inside one); inf if none."""
        p = plane_points(points)
        if len(self.obstacles) == 0:
            return np.full(len(p), np.inf)
        pts = shapely.points(p)
        ip, io = self.tree.query_nearest(pts, all_matches=False)
        out = np.full(len(p), np.inf)
        out[ip] = shapely.distance(pts[ip], self.obstacles[io])
        return out

    def extent_with(self, points, margin: float = 0.0) -> tuple[float, float, float, float]:
        """The world's bounds grown to hold ``points`` (and ``margin`` around them) when
        there is no boundary: planners must be able to reach points beyond the obstacles."""
        if self.boundary is not None:
            return self.bounds
        p = plane_points(points)
        x0, y0, x1, y1 = self.bounds if len(self.obstacles) else (*p.min(0), *p.max(0))
        lo = np.minimum([x0, y0], p.min(0) - margin)
        hi = np.maximum([x1, y1], p.max(0) + margin)
        return float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])

    def check_point(self, point, what: str) -> np.ndarray:
        """One point in the world's frame -> its (2,) plane point when it is free, else a
        QueryError naming ``what`` that speaks in the world's frame and shows the point as
        given (not as it comes back from the plane: far from home a lon/lat does not)."""
        try:
            p = self.to_plane(point, what)
        except QueryError as exc:  # "not a place": say what it likely was
            hint = self._not_a_place_hint(point, what)
            if not hint:
                raise
            raise QueryError(f"{exc}{hint}", param=what) from None
        if len(p) != 1:
            raise QueryError(f"{what} must be one point (a, b), got {len(p)} points",
                             param=what)
        return self.check_plane_point(p[0], what, given=as_points(point, what)[0])

    def check_plane_point(self, p: np.ndarray, what: str, *, given=None) -> np.ndarray:
        """A (2,) plane point when it is free, else a QueryError in the world's frame
        (``given``: the point as the caller wrote it, shown instead of ``p`` converted)."""
        p = np.asarray(p, dtype=float).reshape(2)
        shown = self._fmt(p) if given is None else self._fmt_frame(given)
        self._check_reach(p, what, shown, given)
        if not self.inside([p])[0]:
            raise QueryError(f"{what} {shown} lies outside the map "
                             f"({self._extent_text()}){self._hint(given)}",
                             param=what)
        j = int(self.blocking([p])[0])
        if j >= 0:
            near = nearest_free(self, p, j, self._decimals)
            hint = "" if near is None else f"; nearest free point {self._fmt(near)}"
            raise QueryError(f"{what} {shown} lies inside obstacle {self.names[j]!r}{hint}",
                             param=what)
        return p

    def _check_reach(self, p: np.ndarray, what: str, shown: str, given) -> None:
        """Refuse a point of a lon/lat world with no boundary (frames "lonlat" and
        "degrees") that lies more than :data:`~skyroute.world.points.MAX_REACH` from the
        world's home, straight through the Earth: the reach a GeoJSON world's zones and a
        boundary box are held to. A start typed (lat, lon) lies thousands of km away, and
        without a boundary nothing else refuses it: it was planned through, "found".

        Measured from home, not from the obstacles' extent: home is the reference every
        other reach is measured from (a GeoJSON world's centre, a colliders city's
        lat0/lon0, which its --boundary is checked against), the metres plane is tangent
        there (its error grows with the distance from home), and a world with no obstacle
        below the altitude still has one. A "degrees" world built without a home is
        measured from the centre of its obstacles' box (none: not checked). Points in
        "ned" and "enu" are metres, held to ``MAX_METRES`` by :meth:`to_plane`."""
        if self.boundary is not None or self.frame not in ("lonlat", "degrees"):
            return
        lonlat = self.plane_to_lonlat([p])[0] if given is None else given
        far = self._reach(lonlat)
        if far is None or far <= MAX_REACH:
            return
        home = self._reach_home()
        raise QueryError(f"{what} {shown} lies {far / 1000:,.0f} km from the world's home "
                         f"(lon {home.lon:g}, lat {home.lat:g}), more than the "
                         f"{MAX_REACH / 1000:,.0f} km a world with no boundary reaches"
                         f"{self._hint(given)}", param=what)

    def _reach_home(self) -> Home | None:
        """Where :meth:`_check_reach` measures from: the home, else (a "degrees" world
        built without one) the centre of the obstacles' box, else None."""
        if self.home is not None or len(self.obstacles) == 0:
            return self.home
        x0, y0, x1, y1 = shapely.total_bounds(self.obstacles)
        return Home((x0 + x1) / 2, (y0 + y1) / 2, 0.0)

    def _reach(self, lonlat) -> float | None:
        """Metres from :meth:`_reach_home` to a (lon, lat), straight through the Earth (as
        GeoJSON worlds measure theirs); None when there is nothing to measure from."""
        home = self._reach_home()
        if home is None:
            return None
        lon, lat = np.asarray(lonlat, dtype=float)
        return float(np.linalg.norm(lonlat_to_enu([lon], [lat], 0.0, home)))

    def _hint(self, given) -> str:
        """What a point refused as outside the map (or past its reach) was likely meant
        as: its numbers swapped (:meth:`_swapped_hint`), else metres
        (:meth:`_metres_hint`); '' when neither lies inside."""
        return self._swapped_hint(given) or self._metres_hint(given)

    def _metres_hint(self, given, *, far: bool = False) -> str:
        """'; ... 'ned' frame' when a point of the "lonlat" frame lies past the reach from
        home as (lon, lat) (``far``: it is known to be no (lon, lat) at all) but, read as
        (north, east) metres from home as FCND writes points, would lie inside the map
        (with no boundary, within its reach); else ''. ``--start 0,0`` (home, in metres)
        was refused as 5,965 km away, naming no way on; a (lon, lat) near home but
        outside the map gets no such note."""
        if given is None or self.frame != "lonlat" or self.home is None:
            return ""
        reach = None if far else self._reach(given)
        if not far and (reach is None or reach <= MAX_REACH):
            return ""
        north, east = np.asarray(given, dtype=float)
        if not max(abs(north), abs(east)) <= MAX_METRES:
            return ""
        if self.boundary is None:
            if np.hypot(north, east) > MAX_REACH:
                return ""
        elif not self.inside([(east, north)])[0]:
            return ""
        return ("; points are (lon, lat) here: (north, east) metres from home are the "
                "'ned' frame")

    def _not_a_place_hint(self, point, what: str) -> str:
        """What a point of a lon/lat frame that is no place (|lat| > 90) was likely
        meant as: its numbers swapped, (lat, lon) (:meth:`_swapped_hint`), else (north,
        east) metres (:meth:`_metres_hint`); '' when neither lies in the map, or the
        point is not one pair of numbers. A FCND student's likely slips, typed (lat, lon)
        from the colliders' ``lat0, lon0`` line or (north, east) metres, are no place at
        the FCND city's latitude (lat -122.4, or east beyond 90 m), and got no hint,
        where the same slips near a higher latitude (Edinburgh) did."""
        if self.frame not in ("lonlat", "degrees"):
            return ""
        try:
            given = as_points(point, what)
        except QueryError:
            return ""
        if len(given) != 1:
            return ""
        return self._swapped_hint(given[0], reach_text=True) or \
            self._metres_hint(given[0], far=True)

    def _swapped_hint(self, given, *, reach_text: bool = False) -> str:
        """'; ... (lon, lat)' when a lon/lat point outside the map (or, with no boundary,
        past its reach) would lie inside it (within it) with its two numbers swapped,
        else ''. ``reach_text``: the point is no place at all, so the note says what
        "it" is (the map, or the reach of a world with no boundary)."""
        if given is None or self.frame not in ("lonlat", "degrees"):
            return ""
        q = np.asarray(given, dtype=float)[::-1]
        if abs(q[0]) > 180 or abs(q[1]) > 90:
            return ""
        if self.boundary is None:
            far = self._reach(q)
            if far is None or far > MAX_REACH:
                return ""
            within = f"one, within the {MAX_REACH / 1000:,.0f} km a world with no " \
                "boundary reaches" if reach_text else "within it"
            return f"; {self._fmt_frame(q)} is {within}: points are (lon, lat)"
        if not self.inside(self.to_plane(q))[0]:
            return ""
        inside = "one, inside the map" if reach_text else "inside"
        return f"; {self._fmt_frame(q)} is {inside}: points are (lon, lat)"

    def _fmt(self, p) -> str:
        """A plane point as the caller wrote it: 7 decimals of a degree (about 1 cm) or cm."""
        return self._fmt_frame(self.from_plane([p])[0])

    def _fmt_frame(self, q) -> str:
        """A point in the world's frame, as :meth:`_fmt` shows it."""
        a, b = q
        return f"({a:.{self._decimals}f}, {b:.{self._decimals}f})"

    @property
    def _decimals(self) -> int:
        """Decimals a point is shown with: 7 of a degree (about 1 cm), or 2 of a metre."""
        return 7 if self.frame in ("lonlat", "degrees") else 2

    def _extent_text(self) -> str:
        """'x in (a, b), y in (c, d)' for the map's extent, in the world's frame."""
        x0, y0, x1, y1 = self.bounds
        q = self.from_plane([[x0, y0], [x0, y1], [x1, y0], [x1, y1]])
        lo, hi = q.min(0), q.max(0)
        fmt = "{:.7f}" if self.frame in ("lonlat", "degrees") else "{:.6g}"
        a, b = AXES[self.frame]
        return (f"{a} in ({fmt.format(lo[0])}, {fmt.format(hi[0])}), "
                f"{b} in ({fmt.format(lo[1])}, {fmt.format(hi[1])})")

    # -- rasterising -----------------------------------------------------------------

    def rasterize(self, resolution: float, altitude: float | None = None, *,
                  safety: float | None = None,
                  bounds: tuple[float, float, float, float] | None = None,
                  clearance: float | None = None) -> Grid:
        """A Grid over the world's bounds: a cell is blocked when its centre lies within
        ``safety`` of an obstacle (0: in the closed obstacle) or is not that far inside
        the boundary. World point (x, y) maps to cell ((x - xmin) / r, (y - ymin) / r):
        grid rows grow with y (north).

        The distance is to the obstacle itself, not between cell centres as in
        :meth:`Grid.inflate`, which would leave a free centre up to half a cell from an
        obstacle's edge. Obstacles are buffered with 32-gon circles enlarged by
        1/cos(pi/32), so the test never under-blocks. ``bounds`` (xmin, ymin, xmax, ymax)
        overrides the world's extent. ``clearance`` is the old name of ``safety``."""
        if real("resolution", resolution) <= 0:
            raise OptionError(f"resolution={resolution!r} must be a positive number",
                              param="resolution")
        resolution = float(resolution)
        safety = renamed("safety", safety, "clearance", clearance)
        safety = 0.0 if safety is None else real("safety", safety)
        if safety < 0:
            raise OptionError(f"safety={safety!r} must be a number >= 0", param="safety")
        w = self.at(altitude)
        if bounds is None:
            xmin, ymin, xmax, ymax = self.bounds
        else:
            b = np.asarray(bounds, dtype=object).ravel()
            if len(b) != 4:
                raise OptionError(f"bounds={bounds!r} must be (xmin, ymin, xmax, ymax)",
                                  param="bounds")
            xmin, ymin, xmax, ymax = (real("bounds", v) for v in b)
        width, height = raster_shape(xmax - xmin, ymax - ymin, resolution)
        xs = xmin + (np.arange(width) + 0.5) * resolution
        ys = ymin + (np.arange(height) + 0.5) * resolution
        blocked = np.zeros((height, width), bool)
        grow = safety / np.cos(np.pi / 32) if safety > 0 else 0.0
        for poly in w.obstacles:
            if grow:
                poly = poly.buffer(grow, quad_segs=8)
            x0, y0, x1, y1 = poly.bounds
            c0, c1 = np.searchsorted(xs, x0, "left"), np.searchsorted(xs, x1, "right")
            r0, r1 = np.searchsorted(ys, y0, "left"), np.searchsorted(ys, y1, "right")
            if c1 <= c0 or r1 <= r0:
                continue
            gx, gy = np.meshgrid(xs[c0:c1], ys[r0:r1])
            with LOCK:  # an obstacle itself (no margin) may be prepared
                blocked[r0:r1, c0:c1] |= shapely.intersects_xy(poly, gx, gy)
        if w.boundary is not None:
            inner = shapely.Polygon(w.boundary)
            if safety > 0:
                inner = inner.buffer(-grow, quad_segs=8)
            gx, gy = np.meshgrid(xs, ys)
            blocked |= ~shapely.contains_xy(inner, gx, gy)
        return Grid(blocked, resolution, (xmin, ymin), name=self.name)


def _segment_ends(a, b) -> tuple[np.ndarray, np.ndarray]:
    """Two (N, 2) arrays of segment ends, or a QueryError naming ``a`` or ``b``."""
    a, b = plane_points(a, "a"), plane_points(b, "b")
    if len(a) != len(b):
        raise QueryError(f"a and b must hold as many points: {len(a)} and {len(b)}")
    return a, b
