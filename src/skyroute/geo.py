"""Geodetic coordinates and local frames around a home point, and heading conventions.

Local frames are the ellipsoid's tangent plane at home (WGS84), computed exactly by PROJ's
``cart`` + ``topocentric`` pipeline: ENU = (east, north, up) and NED = (north, east, down)
in metres. This is the "local" frame of PX4, ROS and ArduPilot; unlike a map projection
(UTM, as the FCND course used) it has no scale distortion at home and round-trips to the
millimetre and better within tens of kilometres.

Frames (one meaning everywhere: Python, CLI, files; see docs/architecture.md):

====================  ================  ==========================  =====================
frame                 a point is        plane (geometry)            heading (radians)
====================  ================  ==========================  =====================
``lonlat``            (lon, lat) deg    east, north metres at home  clockwise from north
``ned`` (``local``)   (north, east) m   east, north metres at home  clockwise from north
``enu``               (east, north) m   east, north metres          anticlockwise from +x
``degrees``           (lon, lat) deg    lon, lat as a flat plane    anticlockwise from +x
====================  ================  ==========================  =====================

Planners work in the plane, where headings are radians anticlockwise from +x (as
:mod:`skyroute.motion.dubins` and shapely). :func:`heading_to_plane` and
:func:`heading_from_plane` are the one place headings change convention. The CLI reads
and prints headings in degrees, with the same direction as its frame. File formats keep
their own: FCND waypoints ``[north, east, alt, heading]`` carry a NED heading (radians,
clockwise from north), ILP flight paths an ILP angle (degrees anticlockwise from east;
-999 means hover). Angles in the "degrees" frame are measured on the (lon, lat) plane as
if it were flat, which is what the ILP rules define.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np


@dataclass(frozen=True)
class Home:
    """The origin of a local frame: longitude and latitude in degrees, altitude in metres."""

    lon: float
    lat: float
    alt: float = 0.0

    def __post_init__(self) -> None:
        for name in ("lon", "lat", "alt"):
            object.__setattr__(self, name, float(getattr(self, name)))


@lru_cache(maxsize=32)
def _transformer(home: Home):
    from pyproj import Transformer

    pipeline = ("+proj=pipeline +step +proj=cart +ellps=WGS84 "
                f"+step +proj=topocentric +ellps=WGS84 +lon_0={home.lon:.12f} "
                f"+lat_0={home.lat:.12f} +h_0={home.alt:.6f}")
    return Transformer.from_pipeline(pipeline)


def lonlat_to_enu(lon, lat, alt, home: Home) -> np.ndarray:
    """(N, 3) east, north, up in metres for arrays of lon, lat (degrees) and alt (m)."""
    lon, lat, alt = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (lon, lat, alt)))
    e, n, u = _transformer(home).transform(lon.ravel(), lat.ravel(), alt.ravel())
    return np.column_stack([e, n, u])


def enu_to_lonlat(east, north, up, home: Home) -> np.ndarray:
    """(N, 3) lon, lat (degrees), alt (m) for arrays of east, north, up in metres."""
    e, n, u = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (east, north, up)))
    lon, lat, alt = _transformer(home).transform(e.ravel(), n.ravel(), u.ravel(),
                                                  direction="INVERSE")
    return np.column_stack([lon, lat, alt])


def lonlat_to_ned(lon, lat, alt, home: Home) -> np.ndarray:
    """(N, 3) north, east, down in metres."""
    enu = lonlat_to_enu(lon, lat, alt, home)
    return np.column_stack([enu[:, 1], enu[:, 0], -enu[:, 2]])


def ned_to_lonlat(north, east, down, home: Home) -> np.ndarray:
    """(N, 3) lon, lat (degrees), alt (m) for NED metres."""
    return enu_to_lonlat(east, north, -np.asarray(down, dtype=float), home)


def metres_per_degree_north(lat: float) -> float:
    """Metres per degree of latitude at latitude ``lat`` (degrees) on the WGS84 ellipsoid:
    110,574 m at the equator, 111,694 m at the poles (pyproj's geodesic along the
    meridian over a thousandth of a degree, one-sided at a pole). The scale that turns a
    distance in metres into the "degrees" frame's plane units (see
    :meth:`skyroute.world.world.World.metres_in_plane`)."""
    from pyproj import Geod

    lat = float(lat)
    a, b = max(lat - 5e-4, -90.0), min(lat + 5e-4, 90.0)
    return float(Geod(ellps="WGS84").inv(0.0, a, 0.0, b)[2] / (b - a))


def ned_heading_to_ilp(heading) -> np.ndarray:
    """NED heading (radians, 0 north, clockwise) -> ILP angle (degrees, 0 east, anticlockwise)."""
    return np.mod(90.0 - np.degrees(heading), 360.0)


def ilp_to_ned_heading(angle) -> np.ndarray:
    """ILP angle (degrees, 0 east, anticlockwise) -> NED heading in radians in [0, 2 pi)."""
    return np.mod(np.radians(90.0 - np.asarray(angle, dtype=float)), 2 * math.pi)


FRAMES = ("lonlat", "ned", "enu", "degrees")
FRAME_ALIASES = {"local": "ned"}
COMPASS_FRAMES = ("lonlat", "ned")  # headings clockwise from north


def heading_to_plane(heading, frame: str):
    """A heading in ``frame``'s convention (radians) -> the plane's (radians
    anticlockwise from +x, in [0, 2 pi))."""
    h = np.asarray(heading, dtype=float)
    out = (math.pi / 2 - h) if frame in COMPASS_FRAMES else h
    return np.mod(out, 2 * math.pi)


def heading_from_plane(heading, frame: str):
    """The plane's heading (radians anticlockwise from +x) -> ``frame``'s convention,
    in [0, 2 pi)."""
    return heading_to_plane(heading, frame)  # the map x -> pi/2 - x is its own inverse


def heading_of(dx, dy) -> np.ndarray:
    """NED heading (radians) of a move of (dx east, dy north)."""
    return np.mod(np.arctan2(dx, dy), 2 * math.pi)
