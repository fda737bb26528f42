"""FCND city maps: ``colliders.csv`` boxes around a home point (a 2.5D world in metres).

Line 1 is ``lat0 <deg>, lon0 <deg>``; line 2 the header
``posX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ``; then one box per row: centre north,
east and height above ground, and half extents along north, east and up (metres). The
course's first file (Udacity's FCND-Motion-Planning, 2018, still in many students' forks)
gives the home on two lines, ``lat0,lon0`` over ``37.792480,-122.397450``, the header on
line 3 and boxes from line 4; it is read as well. Each
box grows by ``safety`` on every side and at its top; it counts at an altitude below
its top + safety. A box may reach :data:`MAX_CITY_REACH` (50 km) from home, where the
tangent plane the World plans in is still within a metre or so of the ground.

A file is refused before it is read past :data:`MAX_BYTES`, and after its lines are
split, before any is parsed, past :data:`MAX_BOXES` boxes: the FCND city has 3,845 boxes
(132 kB) and ``skyroute synth-city --blocks 100`` 34,921 (1.7 MB), which PRM and the
grid planners take in seconds; 140,000 boxes took them about a minute (docs/cli.md).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import shapely

from skyroute.errors import GridNotWorldError, InputFormatError
from skyroute.files import read_text, strip_bom
from skyroute.geo import Home
from skyroute.world.points import MAX_METRES
from skyroute.world.world import World

HEADER = "posX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ"
# How far (metres, horizontally) a box may reach from home. The World's plane is PROJ's
# tangent plane at home: a (lon, lat) goes to it at R sin(s/R) for a ground distance s, a
# plane point back at R atan(d/R), so a path planned in the plane and returned in lon/lat
# lies d**3 / (2 R**2) from where the plane had it, and the plane's distances fall
# d**3 / (3 R**2) short of the ground's (what a local frame such as PX4's keeps). At
# 50 km that is 1.5 m and 1.0 m (WGS84, measured through geo.py), under a third of the
# 5 m margin FCND plans with; at 100 km 12.4 m and 8.2 m, more than it. The FCND city
# reaches 0.73 km from home and ``synth-city``'s largest 4.2 km; a box thousands of km
# away is a position in another frame (UTM northings, another home).
MAX_CITY_REACH = 50_000.0
MAX_BOXES = 50_000  # 13 times the FCND city's
MAX_BYTES = 10_000_000  # 200 bytes a box line (FCND's are 35); a file is read whole
# any float Python reads (a sign, an exponent) and any case: float() and the range
# check below judge the numbers; "lat0 +37.79" and "LAT0 ..." were refused as malformed
_HOME = re.compile(r"^\s*lat0\s+([^\s,]+)\s*,\s*lon0\s+([^\s,]+)\s*$", re.IGNORECASE)


def read_colliders(path: str | Path, *, safety: float = 0.0, frame: str = "lonlat",
                   text: str | None = None) -> World:
    """Read a colliders file into a World in ``frame`` ("lonlat", "ned" or "enu"; the
    plane is east/north metres around home at (lon0, lat0)). ``text``: the file's content,
    already in hand (an upload); ``path`` then only names it in errors."""
    source, path = str(path), Path(path)
    if text is None:  # Excel starts a saved CSV with a byte-order mark
        text = read_text(path, max_bytes=MAX_BYTES,
                         kind=f"a colliders file (at most {MAX_BOXES:,} boxes)")
    lines = strip_bom(text).splitlines()
    # the header's index: 2 in the first FCND layout, whose home takes two lines
    head = 2 if lines and "".join(lines[0].split()).lower() == "lat0,lon0" else 1
    boxes = sum(1 for line in lines[head + 1:] if line.strip())
    if boxes > MAX_BOXES:
        raise InputFormatError(path, f"{boxes:,} boxes, over the limit of {MAX_BOXES:,} in a "
                               "colliders file")
    if head == 2:
        lat0, lon0 = _home_values(path, lines[1] if len(lines) > 1 else None)
    else:
        lat0, lon0 = _home(path, lines[0] if lines else None)
    if not (-90 <= lat0 <= 90 and -180 <= lon0 <= 180):
        raise InputFormatError(path, f"home lat0 {lat0}, lon0 {lon0} is not a place",
                               line=head)
    if len(lines) <= head or "".join(lines[head].split()).lower() != HEADER.lower():
        raise InputFormatError(path, f"expected the header {HEADER!r}", line=head + 1)
    rows, numbers = [], []
    for n, line in enumerate(lines[head + 1:], start=head + 2):
        if not line.strip():
            continue
        parts = line.split(",")
        try:
            if len(parts) != 6:
                raise ValueError
            vals = [float(v) for v in parts]
        except ValueError:
            raise InputFormatError(path, f"expected 6 numbers ({HEADER}), got {line[:60]!r}",
                                   line=n) from None
        if not all(np.isfinite(vals)) or min(vals[3:]) <= 0:
            raise InputFormatError(path, "values must be finite and half sizes > 0", line=n)
        if max(abs(vals[i]) + vals[i + 3] for i in range(3)) > MAX_METRES:
            raise InputFormatError(path, f"the box reaches more than {MAX_METRES:.0e} m from "
                                   "home", line=n)
        reach = math.hypot(abs(vals[0]) + vals[3], abs(vals[1]) + vals[4])
        if reach > MAX_CITY_REACH:
            km = f"{MAX_CITY_REACH / 1000:g} km"
            raise InputFormatError(path, f"the box reaches {reach / 1000:,.1f} km from home, "
                                   f"over the {km} limit: posX, posY are metres north and "
                                   "east of lat0, lon0, not UTM or another origin (beyond "
                                   f"{km} the tangent plane at home is over a metre off)",
                                   line=n)
        rows.append(vals)
        numbers.append(n)
    if not rows:
        raise InputFormatError(path, "no boxes after the header", line=head + 2)
    b = np.array(rows)
    north, east, up, hn, he, hu = b.T
    s = float(safety)
    boxes = shapely.box(east - he - s, north - hn - s, east + he + s, north + hn + s)
    # each box named by its own line: after a blank line, counting boxes named the next
    names = tuple(f"box at line {n}" for n in numbers)
    return World(boxes, up - hu - s, up + hu + s, names, None, frame,
                 Home(lon0, lat0, 0.0), name=path.name, source=source)


def _home(path: Path, line: str | None) -> tuple[float, float]:
    """(lat0, lon0) from line 1, ``lat0 <deg>, lon0 <deg>`` (None: an empty file)."""
    m = _HOME.match(line) if line is not None else None
    try:
        if m is None:
            raise ValueError
        return float(m.group(1)), float(m.group(2))
    except ValueError:
        if line is not None and _walls_line(line):
            raise GridNotWorldError(path, "wall segments x1,y1,x2,y2 (a grid map), not a "
                                    "colliders.csv city (line 1 'lat0 ..., lon0 ...')",
                                    line=1) from None
        got = "an empty file" if line is None else repr(line[:60])
        raise InputFormatError(path, f"expected 'lat0 <deg>, lon0 <deg>', got {got}",
                               line=1) from None


def _home_values(path: Path, line: str | None) -> tuple[float, float]:
    """(lat0, lon0) from line 2 of the first FCND layout, ``<lat>,<lon>`` under a line 1
    of ``lat0,lon0`` (None: the file ends after line 1)."""
    parts = line.split(",") if line is not None else []
    try:
        if len(parts) != 2:
            raise ValueError
        return float(parts[0]), float(parts[1])
    except ValueError:
        got = "the end of the file" if line is None else repr(line[:60])
        raise InputFormatError(path, f"expected '<lat0>,<lon0>' under line 1's 'lat0,lon0', "
                               f"got {got}", line=2) from None


def _walls_line(line: str) -> bool:
    """Whether line 1 is that of a walls file (:mod:`skyroute.world.segments`): a
    comment, the header ``x1,y1,x2,y2`` or a wall of 4 numbers."""
    cells = [c.strip() for c in line.split(",")]
    if line.lstrip().startswith("#") or cells[0].lower() in ("x1", "x0", "x"):
        return True
    if len(cells) != 4:
        return False
    try:
        [float(c) for c in cells]
    except ValueError:
        return False
    return True
