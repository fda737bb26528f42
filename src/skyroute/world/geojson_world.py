"""No-fly zones and a confinement area as GeoJSON polygons in longitude/latitude.

Every feature must be a Polygon or MultiPolygon (an obstacle), except the boundary: a
feature whose properties carry ``"boundary": true`` or whose name mentions
"confinement". A boundary may also come from another GeoJSON file or a bbox string
``MINLON,MINLAT,MAXLON,MAXLAT``. Frames: "degrees" keeps (lon, lat) as a flat plane
(the ILP rules); "lonlat" (the default), "ned" and "enu" project to east/north metres
around a home at the centre of the boundary (or of the zones), see :mod:`skyroute.geo`.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import shapely

from skyroute.errors import InputFormatError, OptionError, QueryError, check_choice
from skyroute.geo import FRAME_ALIASES, FRAMES, Home, lonlat_to_enu
from skyroute.world.points import check_places
from skyroute.world.world import World


def _features(path: Path | str, text: str | None = None) -> list[dict]:
    try:
        doc = json.loads(Path(path).read_text() if text is None else text)
    except (OSError, UnicodeDecodeError) as exc:
        raise InputFormatError(path, f"cannot read: {exc}") from None
    except json.JSONDecodeError as exc:
        raise InputFormatError(path, f"not JSON: {exc.msg}", line=exc.lineno) from None
    if not isinstance(doc, dict) or doc.get("type") != "FeatureCollection" or \
            not isinstance(doc.get("features"), list):
        raise InputFormatError(path, "expected a GeoJSON FeatureCollection")
    return doc["features"]


def _polygon(path: Path, i: int, feature: dict) -> tuple[shapely.Geometry, str]:
    props = feature.get("properties") or {}
    name = str(props.get("name", f"feature {i}"))
    geom = feature.get("geometry") or {}
    kind = geom.get("type")
    if kind not in ("Polygon", "MultiPolygon"):
        raise InputFormatError(path, f"feature {i} ({name!r}) is a {kind}; only Polygon and "
                               "MultiPolygon features are zones")
    try:
        shape = shapely.from_geojson(json.dumps(geom))
    except shapely.errors.GEOSException as exc:
        raise InputFormatError(path, f"feature {i} ({name!r}): bad coordinates: {exc}") from None
    if not shape.is_valid:
        raise InputFormatError(path, f"feature {i} ({name!r}) is not a valid polygon: "
                               f"{shapely.is_valid_reason(shape)}")
    try:
        check_places(shapely.get_coordinates(shape), "a vertex")
    except QueryError as exc:
        raise InputFormatError(path, f"feature {i} ({name!r}): {exc}") from None
    return shape, name


def _is_boundary(feature: dict) -> bool:
    props = feature.get("properties") or {}
    return props.get("boundary") is True or "confinement" in str(props.get("name", "")).lower()


def parse_boundary(value: str | Path) -> shapely.Polygon:
    """A boundary from a bbox string ``MINLON,MINLAT,MAXLON,MAXLAT`` or a GeoJSON file."""
    text = str(value)
    parts = text.split(",")
    if len(parts) == 4 and not Path(text).exists():
        try:
            x0, y0, x1, y1 = (float(p) for p in parts)
        except ValueError:
            raise OptionError(f"boundary={text!r}: expected MINLON,MINLAT,MAXLON,MAXLAT or "
                              "a GeoJSON file", param="boundary") from None
        if not (x0 < x1 and y0 < y1):
            raise OptionError(f"boundary={text!r}: min must be below max", param="boundary")
        try:
            check_places(np.array([[x0, y0], [x1, y1]]), "a corner")
        except QueryError as exc:
            raise OptionError(f"boundary={text!r}: {exc}", param="boundary") from None
        return shapely.box(x0, y0, x1, y1)
    path = Path(text)
    if not path.exists():
        raise InputFormatError(path, "no such boundary file (or give MINLON,MINLAT,MAXLON,MAXLAT)")
    shapes = [_polygon(path, i, f)[0] for i, f in enumerate(_features(path))]
    if len(shapes) != 1 or shapes[0].geom_type != "Polygon":
        raise InputFormatError(path, f"a boundary file must hold one Polygon, found {len(shapes)}")
    return shapes[0]


def read_geojson_world(path: str | Path, *, boundary: str | Path | shapely.Polygon | None = None,
                       safety: float = 0.0, frame: str = "lonlat",
                       text: str | None = None) -> World:
    """Read zones (and a boundary) from a FeatureCollection in lon/lat.

    ``safety`` grows every zone by that distance in the frame's units (mitred corners,
    so polygons stay polygons; a point at the corner keeps at least that distance).
    ``text``: the document itself, already fetched; ``path`` then only names it (a URL).
    """
    source = str(path)
    if text is None:
        path = Path(path)
    zones, names, found = [], [], None
    for i, feature in enumerate(_features(path, text)):
        shape, name = _polygon(path, i, feature)
        if _is_boundary(feature):
            found = shape
        else:
            zones.append(shape)
            names.append(name)
    if boundary is not None:
        found = boundary if isinstance(boundary, shapely.Polygon) else parse_boundary(boundary)
    if not zones and found is None:
        raise InputFormatError(path, "no zones and no boundary")
    allb = shapely.total_bounds(np.array(zones + ([found] if found is not None else []),
                                         dtype=object))
    home = Home((allb[0] + allb[2]) / 2, (allb[1] + allb[3]) / 2, 0.0)
    check_choice("frame", frame, (*FRAMES, *FRAME_ALIASES))
    if frame != "degrees":
        zones = [_to_metres(z, home) for z in zones]
        found = _to_metres(found, home) if found is not None else None
    polys, pnames = [], []
    for z, name in zip(zones, names, strict=True):
        if safety:
            z = z.buffer(safety, join_style="mitre", mitre_limit=2.0)
        for part in getattr(z, "geoms", [z]):
            polys.append(part)
            pnames.append(name)
    n = len(polys)
    return World(np.array(polys, dtype=object), np.full(n, -np.inf), np.full(n, np.inf),
                 tuple(pnames), found, frame, home, name=source.rstrip("/").rsplit("/")[-1],
                 source=source)


def _to_metres(shape: shapely.Geometry, home: Home) -> shapely.Geometry:
    def project(coords: np.ndarray) -> np.ndarray:
        return lonlat_to_enu(coords[:, 0], coords[:, 1], 0.0, home)[:, :2]

    return shapely.transform(shape, project)
