"""One entry point that reads any supported map file into a Grid."""

from __future__ import annotations

from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING

from skyroute.errors import (
    GridNotWorldError,
    InputFormatError,
    OptionError,
    check_choice,
    real,
    renamed,
)
from skyroute.files import as_path, cannot_read
from skyroute.keywords import strict_keywords, unknown_keywords
from skyroute.world.grid import Grid

if TYPE_CHECKING:
    from skyroute.world.world import World

# Each reader is imported when its kind of file is read: a .map needs neither shapely
# (walls, worlds) nor pyproj (frames) nor numba's wall kernel.

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".gif", ".pgm", ".tif", ".tiff")


def bundled_maps() -> dict[str, Path]:
    """The MovingAI maps shipped inside the package, by name (see data/maps/CITATION.md)."""
    folder = Path(str(resources.files("skyroute") / "data" / "maps"))
    return {p.stem: p for p in sorted(folder.glob("*.map"))}


def resolve_map_path(path: str | Path) -> Path:
    """``path`` itself when it exists and is not a folder (a file, a pipe), else the
    bundled map of that name (a folder of the same name in the working folder does not
    hide it)."""
    p = as_path(path, "path")
    if not str(path):  # Path("") is ".", read as "a folder, not a map file"
        raise OptionError("path='' is empty: give a map file or a bundled map's name",
                          param="path")
    try:
        if p.exists() and not p.is_dir():
            return p
    except OSError as exc:  # e.g. a name longer than the file system allows
        raise cannot_read(p, exc) from None
    maps = bundled_maps()
    key = p.name[:-4] if p.name.endswith(".map") else p.name
    if str(path) == p.name and key in maps:
        return maps[key]
    if p.is_dir():
        raise InputFormatError(p, "a folder, not a map file")
    raise InputFormatError(p, "no such file (bundled maps: " + ", ".join(maps) + ")")


@strict_keywords
def load_map(path: str | Path, *, resolution: float | None = None, safety: float | None = None,
             cell_size: float | None = None, clearance: float | None = None, **misspelt) -> Grid:
    """Read a map into a :class:`Grid`, chosen by the file's suffix.

    - ``.map``: a MovingAI map (1 m cells; ``resolution`` rescales it);
    - ``.csv``: wall segments ``x1,y1,x2,y2`` in metres, rasterised at ``resolution``;
    - ``.png``, ``.jpg``, ...: an image, dark pixels blocked;
    - ``.npy``: a 2-D array, non-zero blocked.

    A bare name such as ``"den312d"`` that is not a file names a bundled map.
    ``resolution`` is the cell size in metres (default 1). ``safety`` (metres) blocks
    cells near obstacles (exact to the walls for ``.csv``; a Euclidean distance
    transform, :meth:`Grid.inflate`, for the others). ``cell_size`` and ``clearance``
    are the old names of ``resolution`` and ``safety`` (deprecated).

    >>> grid = load_map("den312d")
    >>> grid.width, grid.height
    (65, 81)
    """
    if misspelt:
        raise unknown_keywords(load_map, misspelt)
    resolution = renamed("resolution", resolution, "cell_size", cell_size)
    resolution = 1.0 if resolution is None else real("resolution", resolution)
    safety = renamed("safety", safety, "clearance", clearance)
    safety = 0.0 if safety is None else real("safety", safety)
    p = resolve_map_path(path)
    suffix = p.suffix.lower()
    if suffix == ".csv":
        from skyroute.world.segments import load_segments

        return load_segments(p, resolution=resolution, safety=safety)
    if suffix == ".map":
        from skyroute.world.movingai import read_map

        grid = read_map(p)
        if resolution != 1.0:
            grid = Grid(grid.blocked, resolution, grid.origin, name=grid.name)
    elif suffix in IMAGE_SUFFIXES:
        from skyroute.world.image import read_image

        grid = read_image(p, resolution=resolution)
    elif suffix == ".npy":
        from skyroute.world.image import read_npy

        grid = read_npy(p, resolution=resolution)
    elif suffix in (".geojson", ".json"):  # load_world's GeoJSON
        from skyroute.errors import WorldNotGridError

        raise WorldNotGridError(p, f"GeoJSON zones ({suffix}), a world, not a grid map "
                                "(.map, .csv walls, .npy, an image)")
    else:
        raise InputFormatError(p, f"unknown map type {suffix!r}; valid: .map, .csv, .npy, "
                               + ", ".join(IMAGE_SUFFIXES))
    return grid.inflate(safety)


MIN_ALTITUDE = 0.0  # metres above the ground: below it no building counts
ALTITUDE = f"a finite number >= {MIN_ALTITUDE:g}"  # what an altitude must be
MAX_SAFETY_DEGREES = 180.0  # a safety margin in the degrees frame; in metres, MAX_METRES


@strict_keywords
def load_world(path: str | Path, *, altitude: float | None = None, safety: float = 0.0,
               boundary: str | Path | None = None, frame: str = "lonlat",
               text: str | None = None, **misspelt) -> World:
    """Read a continuous world: a ``colliders.csv`` city or a GeoJSON file of zones.

    ``frame`` is how points are given to and returned by everything that takes this
    world (:func:`skyroute.plan`, the motion models, the writers): "lonlat" (the default
    for both kinds of file: (lon, lat) in, geometry in metres around home), "ned"
    ((north, east) metres from home, FCND; "local" is an alias), "enu" ((east, north)
    metres) or "degrees" ((lon, lat) on a flat plane, the ILP rules; GeoJSON only). A
    colliders file's home is its ``lat0, lon0``; a GeoJSON file's the centre of its
    zones and boundary. ``altitude`` (metres above the ground, >= 0) keeps the obstacles
    that count there; ``safety`` grows every obstacle (metres, or degrees in the degrees
    frame). ``text``: the file's content, already in hand (an upload); ``path`` then only
    names it and its suffix tells the format.
    """
    if misspelt:
        raise unknown_keywords(load_world, misspelt)
    from skyroute.geo import FRAME_ALIASES, FRAMES
    from skyroute.world.colliders import read_colliders
    from skyroute.world.geojson_world import parse_boundary, read_geojson_world
    from skyroute.world.points import MAX_METRES

    check_choice("frame", frame, (*FRAMES, *FRAME_ALIASES))
    frame = FRAME_ALIASES.get(frame, frame)
    if real("safety", safety) < 0:
        raise OptionError(f"safety={safety!r} must be a number >= 0", param="safety")
    safety = float(safety)
    # metres above the ground, as bench.world.check_altitude has it: -5 kept no building
    # of a city (all stand on the ground) and planned straight through them
    if altitude is not None:
        altitude = real("altitude", altitude, low=MIN_ALTITUDE, need=ALTITUDE)
    most = MAX_SAFETY_DEGREES if frame == "degrees" else MAX_METRES
    if safety > most:
        raise OptionError(f"safety={safety!r} must be at most {most:g} "
                          f"({'degrees' if frame == 'degrees' else 'metres'})", param="safety")
    p = Path(path)
    if not str(path):  # Path("") is ".", a folder: "unknown world type ''"
        raise OptionError("path='' is empty: give a colliders.csv city or a GeoJSON file",
                          param="path")
    if text is None and not p.exists():
        key = p.name[:-4] if p.name.endswith(".map") else p.name
        if str(path) == p.name and key in bundled_maps():
            raise GridNotWorldError(p, "no such file, but the name of a bundled grid map, "
                                    "not a world")
        raise InputFormatError(p, "no such file")
    if p.suffix.lower() in (".map", ".npy", *IMAGE_SUFFIXES):
        raise GridNotWorldError(p, f"a grid map ({p.suffix}), not a world (a colliders.csv "
                                "city or GeoJSON zones)")
    if p.suffix.lower() == ".csv":
        if frame == "degrees":
            raise OptionError("frame='degrees': a colliders.csv city is in metres; use "
                              "'lonlat', 'ned' or 'enu'", param="frame")
        world = read_colliders(p, safety=safety, frame=frame, text=text)
        if boundary is not None:
            world = _with_boundary(world, _near_home(boundary, parse_boundary(boundary),
                                                     world.home))
    elif p.suffix.lower() in (".geojson", ".json"):
        world = read_geojson_world(p, boundary=boundary, safety=safety, frame=frame,
                                   text=text)
    else:
        raise InputFormatError(p, f"unknown world type {p.suffix!r}; valid: .csv (colliders), "
                               ".geojson")
    return world.at(altitude)


def _near_home(given, lonlat_box, home):
    """``lonlat_box`` when it lies within the GeoJSON worlds' reach of a city's home, else
    an OptionError: beyond it a (lat, lon) box is projected into a distorted far-off area
    that no start or goal near home lies in."""
    import numpy as np

    from skyroute.geo import lonlat_to_enu
    from skyroute.world.geojson_world import MAX_REACH, SWAPPED

    xy = np.asarray(lonlat_box.exterior.coords)
    km = np.linalg.norm(lonlat_to_enu(xy[:, 0], xy[:, 1], 0.0, home), axis=1).max() / 1000
    if km * 1000 > MAX_REACH:
        raise OptionError(f"boundary={str(given)!r} reaches {km:,.0f} km from the city's home "
                          f"(lon {home.lon:g}, lat {home.lat:g}), more than "
                          f"{MAX_REACH / 1000:,.0f} km: {SWAPPED}", param="boundary")
    return lonlat_box


def _with_boundary(world: World, lonlat_box) -> World:
    """Attach a lon/lat boundary to a metres world (projected around its home)."""
    import shapely

    from skyroute.world.world import World

    return World(world.obstacles, world.floors, world.ceilings, world.names,
                 shapely.transform(lonlat_box, world.plane_from_lonlat), world.frame,
                 world.home, world.name, world.source)
