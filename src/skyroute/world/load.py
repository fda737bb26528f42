"""One entry point that reads any supported map file into a Grid."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

import numpy as np

from skyroute.errors import InputFormatError, OptionError, check_choice
from skyroute.world.grid import Grid
from skyroute.world.image import read_image, read_npy
from skyroute.world.movingai import read_map
from skyroute.world.segments import rasterize_segments, read_segments
from skyroute.world.world import World

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".gif", ".pgm", ".tif", ".tiff")


def bundled_maps() -> dict[str, Path]:
    """The MovingAI maps shipped inside the package, by name (see data/maps/CITATION.md)."""
    folder = Path(str(resources.files("skyroute") / "data" / "maps"))
    return {p.stem: p for p in sorted(folder.glob("*.map"))}


def resolve_map_path(path: str | Path) -> Path:
    """``path`` itself when it exists, else the bundled map of that name."""
    p = Path(path)
    if p.exists():
        return p
    maps = bundled_maps()
    key = p.name[:-4] if p.name.endswith(".map") else p.name
    if str(path) == p.name and key in maps:
        return maps[key]
    raise InputFormatError(p, "no such file (bundled maps: " + ", ".join(maps) + ")")


def load_map(path: str | Path, *, cell_size: float = 1.0, clearance: float = 0.0) -> Grid:
    """Read a map into a :class:`Grid`, chosen by the file's suffix.

    - ``.map``: a MovingAI map (1 m cells; ``cell_size`` rescales it);
    - ``.csv``: wall segments ``x1,y1,x2,y2`` in metres, rasterised at ``cell_size``;
    - ``.png``, ``.jpg``, ...: an image, dark pixels blocked;
    - ``.npy``: a 2-D array, non-zero blocked.

    A bare name such as ``"den312d"`` that is not a file names a bundled map.
    ``clearance`` (metres) blocks cells near obstacles (exact to the walls for ``.csv``;
    a Euclidean distance transform, :meth:`Grid.inflate`, for the others).

    >>> grid = load_map("den312d")
    >>> grid.width, grid.height
    (65, 81)
    """
    p = resolve_map_path(path)
    suffix = p.suffix.lower()
    if suffix == ".csv":
        return rasterize_segments(read_segments(p), resolution=cell_size, clearance=clearance,
                                  name=p.name)
    if suffix == ".map":
        grid = read_map(p)
        if cell_size != 1.0:
            grid = Grid(grid.blocked, cell_size, grid.origin, name=grid.name)
    elif suffix in IMAGE_SUFFIXES:
        grid = read_image(p, cell_size=cell_size)
    elif suffix == ".npy":
        grid = read_npy(p, cell_size=cell_size)
    else:
        raise InputFormatError(p, f"unknown map type {suffix!r}; valid: .map, .csv, .npy, "
                               + ", ".join(IMAGE_SUFFIXES))
    return grid.inflate(clearance)


def load_world(path: str | Path, *, altitude: float | None = None, safety: float = 0.0,
               boundary: str | Path | None = None, frame: str = "lonlat") -> World:
    """Read a continuous world: a ``colliders.csv`` city or a GeoJSON file of zones.

    ``frame``: "lonlat" and "local" give geometry in metres around home (they differ
    only in how a CLI reads starts and goals); "degrees" keeps (lon, lat) as a plane,
    which is how the ILP rules measure. ``altitude`` keeps the obstacles that count
    there; ``safety`` grows every obstacle (metres, or degrees in the degrees frame).
    """
    from skyroute.world.colliders import read_colliders
    from skyroute.world.geojson_world import parse_boundary, read_geojson_world

    check_choice("frame", frame, ("lonlat", "local", "degrees"))
    if not (np.isfinite(safety) and safety >= 0):
        raise OptionError(f"safety={safety!r} must be a number >= 0")
    p = Path(path)
    if not p.exists():
        raise InputFormatError(p, "no such file")
    if p.suffix.lower() == ".csv":
        if frame == "degrees":
            raise OptionError("a colliders.csv city is in metres; use frame 'lonlat' or 'local'")
        world = read_colliders(p, safety=safety)
        if boundary is not None:
            world = _with_boundary(world, parse_boundary(boundary))
    elif p.suffix.lower() in (".geojson", ".json"):
        world = read_geojson_world(p, boundary=boundary, safety=safety,
                                   frame="degrees" if frame == "degrees" else "metres")
    else:
        raise InputFormatError(p, f"unknown world type {p.suffix!r}; valid: .csv (colliders), "
                               ".geojson")
    return world.at(altitude)


def _with_boundary(world: World, lonlat_box) -> World:
    """Attach a lon/lat boundary to a metres world (projected around its home)."""
    import shapely

    from skyroute.geo import lonlat_to_enu

    def project(coords):
        return lonlat_to_enu(coords[:, 0], coords[:, 1], 0.0, world.home)[:, :2]

    return World(world.obstacles, world.floors, world.ceilings, world.names,
                 shapely.transform(lonlat_box, project), world.frame, world.home, world.name)
