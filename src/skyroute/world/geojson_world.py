"""No-fly zones and a confinement area as GeoJSON polygons in longitude/latitude.

Every feature must be a Polygon or MultiPolygon (an obstacle), except the boundary: a
feature whose properties carry ``"boundary": true`` or whose name mentions
"confinement". A boundary may also come from another GeoJSON file or a bbox string
``MINLON,MINLAT,MAXLON,MAXLAT``. Frames: "degrees" keeps (lon, lat) as a flat plane
(the ILP rules); "lonlat" (the default), "ned" and "enu" project to east/north metres
around a home at the centre of the boundary (or of the zones), see :mod:`skyroute.geo`.

A file is refused before it is read past :data:`MAX_BYTES` (as a colliders file is), and
a world whose lon/lat box (zones and boundary) reaches more than :data:`MAX_REACH` metres
from that home is refused naming the feature farthest from the others: one feature
written (lat, lon) by mistake lies thousands of kilometres away, where it would silently
guard nothing (and the tangent plane at home is off by 0.1 % at 500 km, 0.4 % at 1,000).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import shapely

from skyroute.errors import InputFormatError, OptionError, QueryError, check_choice
from skyroute.files import lone_surrogate, read_text, strip_bom
from skyroute.geo import FRAME_ALIASES, FRAMES, Home, lonlat_to_enu
from skyroute.world.points import MAX_REACH, check_places
from skyroute.world.world import World

MAX_BYTES = 10_000_000  # as a colliders file's; the ILP zones are 11 kB; read whole
SWAPPED = "are its coordinates (lat, lon)? GeoJSON and boundary boxes are (lon, lat)"


def _features(path: Path | str, text: str | None = None) -> list[dict]:
    if text is None:  # a byte-order mark (Windows editors) is read past
        text = read_text(path, max_bytes=MAX_BYTES, kind="a GeoJSON file")
    try:
        doc = json.loads(strip_bom(text))
    except json.JSONDecodeError as exc:
        raise InputFormatError(path, f"not JSON: {exc.msg}", line=exc.lineno) from None
    if not isinstance(doc, dict) or doc.get("type") != "FeatureCollection" or \
            not isinstance(doc.get("features"), list):
        kind = doc.get("type") if isinstance(doc, dict) else None
        if kind == "FeatureCollection":
            got = "its 'features' is not a list of features"
        elif kind == "Feature":
            got = ("got one Feature (wrap it: {\"type\": \"FeatureCollection\", "
                   "\"features\": [...]})")
        elif isinstance(kind, str) and kind:
            got = f"got a bare {kind} (make it the geometry of a Feature in one)"
        elif isinstance(doc, dict):
            got = "got a JSON object with no GeoJSON 'type'"
        else:
            got = "got a JSON " + {list: "array", str: "string", bool: "boolean",
                                   type(None): "null"}.get(type(doc), "number")
        raise InputFormatError(path, f"expected a GeoJSON FeatureCollection; {got}")
    return doc["features"]


def _polygon(path: Path, i: int, feature: dict) -> tuple[shapely.Geometry, str]:
    if not isinstance(feature, dict):
        raise InputFormatError(path, f"feature {i} is {type(feature).__name__} "
                               f"{json.dumps(feature)[:40]}, not a GeoJSON Feature object")
    name = str(_properties(feature).get("name", f"feature {i}"))
    if (at := lone_surrogate(name)) is not None:  # the escape "\\ud800": no character
        raise InputFormatError(path, f"feature {i}: its name holds U+{ord(name[at]):04X}, "
                               "half of a UTF-16 surrogate pair and no character")
    geom = feature.get("geometry")
    kind = geom.get("type") if isinstance(geom, dict) else None
    if kind not in ("Polygon", "MultiPolygon"):
        what = "has no geometry" if geom is None else f"is a {kind}" if kind else \
            "has a geometry with no type"
        raise InputFormatError(path, f"feature {i} ({name!r}) {what}; only Polygon and "
                               "MultiPolygon features are zones")
    try:  # NaN, Infinity (Python's json reads them) and 1e999 are no JSON numbers
        text = json.dumps(geom, allow_nan=False)
    except ValueError:
        raise InputFormatError(path, f"feature {i} ({name!r}): coordinates must be finite "
                               "numbers, found NaN or Infinity (or one too large, "
                               "such as 1e999)") from None
    try:
        shape = shapely.from_geojson(text)
    except shapely.errors.GEOSException as exc:
        raise InputFormatError(path, f"feature {i} ({name!r}): bad coordinates: {exc}") from None
    if shape.is_empty:
        raise InputFormatError(path, f"feature {i} ({name!r}) has no coordinates")
    if not shape.is_valid:
        raise InputFormatError(path, f"feature {i} ({name!r}) is not a valid polygon: "
                               f"{shapely.is_valid_reason(shape)}")
    try:
        check_places(shapely.get_coordinates(shape), "a vertex")
    except QueryError as exc:
        raise InputFormatError(path, f"feature {i} ({name!r}): {exc}") from None
    return shape, name


def _properties(feature: dict) -> dict:
    """A feature's properties; none (null, or not an object) read as {}."""
    props = feature.get("properties")
    return props if isinstance(props, dict) else {}


def _is_boundary(feature: dict) -> bool:
    props = _properties(feature)
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
    zones, names, labels, found, found_label = [], [], [], None, None
    for i, feature in enumerate(_features(path, text)):
        shape, name = _polygon(path, i, feature)
        label = f"feature {i} ({name!r})"
        if _is_boundary(feature):
            if found is not None:
                raise InputFormatError(path, f"two boundaries: {found_label} and {label} (a "
                                       "feature with \"boundary\": true or \"confinement\" "
                                       "in its name); keep one")
            if shape.geom_type != "Polygon":
                raise InputFormatError(path, f"{label} is the boundary, so it must be one "
                                       f"Polygon, not a {shape.geom_type}")
            found, found_label = shape, label
        else:
            zones.append(shape)
            names.append(name)
            labels.append(label)
    if boundary is not None:
        found = boundary if isinstance(boundary, shapely.Polygon) else parse_boundary(boundary)
        found_label = "the boundary" if isinstance(boundary, shapely.Polygon) else \
            f"boundary={str(boundary)!r}"
    if not zones and found is None:
        raise InputFormatError(path, "no zones and no boundary")
    shapes = zones + ([found] if found is not None else [])
    allb = shapely.total_bounds(np.array(shapes, dtype=object))
    home = Home((allb[0] + allb[2]) / 2, (allb[1] + allb[3]) / 2, 0.0)
    _check_reach(path, shapes, labels + ([found_label] if found is not None else []), home)
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


def _check_reach(path: Path | str, shapes: list, labels: list[str], home: Home) -> None:
    """Refuse a world whose lon/lat box (zones and boundary) reaches more than
    :data:`MAX_REACH` metres (straight through the Earth) from its centre ``home``, saying
    what is likely wrong: a shape across the antimeridian, or one far from the others,
    (lat, lon) written for (lon, lat)."""
    shapes = np.array(shapes, dtype=object)
    box = shapely.bounds(shapes)  # (n, 4): lon0, lat0, lon1, lat1
    lon0, lat0 = box[:, :2].min(axis=0)
    lon1, lat1 = box[:, 2:].max(axis=0)
    corners = lonlat_to_enu(np.array([lon0, lon1, lon0, lon1]),
                            np.array([lat0, lat0, lat1, lat1]), 0.0, home)
    reach = np.linalg.norm(corners, axis=1).max()
    if reach <= MAX_REACH:
        return
    limit = f"a world reaches at most {MAX_REACH / 1000:,.0f} km from its centre"
    if lon1 - lon0 > 180:
        wide = np.flatnonzero(box[:, 2] - box[:, 0] > 180)
        who = f"{labels[wide[0]]} spans" if len(wide) else "the zones span"
        raise InputFormatError(path, f"{who} lon {lon0:g} to {lon1:g}, across the "
                               f"antimeridian; {limit}")
    centres = shapely.get_coordinates(shapely.centroid(shapes))
    mid = Home(*np.median(centres, axis=0), 0.0)
    far = int(np.argmax(np.linalg.norm(lonlat_to_enu(*centres.T, 0.0, mid), axis=1)))
    rest = np.delete(centres, far, axis=0)
    km = 0.0 if len(rest) == 0 else np.linalg.norm(
        lonlat_to_enu(*centres[far], 0.0, Home(*np.median(rest, axis=0), 0.0))) / 1000
    if km * 1000 <= MAX_REACH:
        raise InputFormatError(path, f"the world reaches {reach / 1000:,.0f} km from its "
                               f"centre; {limit}")
    raise InputFormatError(path, f"{labels[far]} lies {km:,.0f} km from the rest of the world "
                           f"({limit}): {SWAPPED}")


def _to_metres(shape: shapely.Geometry, home: Home) -> shapely.Geometry:
    def project(coords: np.ndarray) -> np.ndarray:
        return lonlat_to_enu(coords[:, 0], coords[:, 1], 0.0, home)[:, :2]

    return shapely.transform(shape, project)
