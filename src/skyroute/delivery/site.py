"""A delivery site: shops and their menus, no-fly zones, the confinement area, home, and
what3words places, read from a data source (ILP 2021 layout, SPEC.md 4.5).

The ILP files carry no confinement area or home; they are the rules' constants
(SPEC.md 4.2-4.3) unless the set has ``website/area.json``::

    {"home": "nests.takes.print", "confinement": [min_lon, min_lat, max_lon, max_lat]}

which is how a synthetic set in another town names its own.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

import numpy as np
import shapely

from skyroute.delivery.source import DirSource, HttpSource
from skyroute.errors import InputFormatError, QueryError
from skyroute.world.geojson_world import read_geojson_world
from skyroute.world.points import check_places
from skyroute.world.world import World

ILP_HOME = "nests.takes.print"  # Appleton Tower
ILP_CONFINEMENT = (-3.192473, 55.942617, -3.184319, 55.946233)


@dataclass(frozen=True)
class Shop:
    name: str
    words: str
    lonlat: tuple[float, float]


@dataclass
class Site:
    """Everything about the place that does not change from day to day."""

    source: DirSource | HttpSource
    shops: tuple[Shop, ...]
    menu: dict[str, tuple[int, int]]  # item -> (pence, shop index)
    world: World  # degrees frame: zones, confinement as the boundary
    home: tuple[float, float]
    home_words: str
    confinement: tuple[float, float, float, float]
    _places: dict[str, tuple[float, float]] = field(default_factory=dict, repr=False)

    def locate(self, words: str) -> tuple[float, float]:
        """(lon, lat) of a what3words address, from ``words/<w1>/<w2>/<w3>/details.json``."""
        if words not in self._places:
            self._places[words] = _read_words(self.source, words)
        return self._places[words]


def _json(source, path: str):
    text = source.text(path)
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputFormatError(source.where(path), f"not JSON: {exc.msg}",
                               line=exc.lineno) from None


def _read_words(source, words: str) -> tuple[float, float]:
    parts = str(words).split(".")
    if len(parts) != 3 or not all(p.isalpha() for p in parts):
        raise InputFormatError(source.where("words"), f"{words!r} is not a what3words "
                               "address (three words joined by dots)")
    path = f"words/{parts[0]}/{parts[1]}/{parts[2]}/details.json"
    doc = _json(source, path)
    try:
        c = doc["coordinates"]
        return float(c["lng"]), float(c["lat"])
    except (KeyError, TypeError, ValueError):
        raise InputFormatError(source.where(path), "no coordinates {lng, lat}") from None


def _read_menus(source) -> tuple[tuple[tuple[str, str], ...], dict[str, tuple[int, int]]]:
    path = "menus/menus.json"
    doc = _json(source, path)
    where = source.where(path)
    if not isinstance(doc, list) or not doc:
        raise InputFormatError(where, "expected a list of shops")
    shops, menu = [], {}
    for k, shop in enumerate(doc):
        try:
            name, loc, items = shop["name"], shop["location"], shop["menu"]
            if not (isinstance(name, str) and isinstance(loc, str)):
                raise ValueError("name and location must be strings")
            loc = loc.strip()  # as the order CSVs' deliverTo is read
            for it in items:
                item, pence = it["item"], it["pence"]
                if not isinstance(item, str):
                    raise ValueError(f"item {item!r}: an item's name must be a string")
                # spaces round a name read past, as in orderDetails.csv: a menu's 'Ham
                # roll ' was never 'Ham roll', and its orders were invalid ('unknown item')
                item = item.strip()
                if not item:
                    raise ValueError(f"item {it['item']!r}: an item's name is empty")
                # bool is an int to Python: true would be 1p; 2**63 and more overflow SQL
                if isinstance(pence, bool) or not isinstance(pence, int) \
                        or not 0 <= pence < 2**63:
                    raise ValueError(f"item {item!r}: pence must be a whole number >= 0 "
                                     "(below 2**63)")
                if item in menu:  # twice on this shop's menu, or on an earlier one's
                    raise ValueError(f"item {item!r} is twice on its menu" if menu[item][1]
                                     == k else f"item {item!r} is also on shop "
                                     f"{shops[menu[item][1]][0]!r}'s menu")
                menu[item] = (pence, k)
        except (KeyError, TypeError) as exc:
            raise InputFormatError(where, f"shop {k}: missing or malformed {exc}") from None
        except ValueError as exc:
            raise InputFormatError(where, f"shop {k} ({shop.get('name')!r}): {exc}") from None
        shops.append((name, loc))
    return tuple(shops), menu


def load_site(source: DirSource | HttpSource) -> Site:
    """Read menus, zones, the area and every shop's place; errors name the file."""
    names, menu = _read_menus(source)
    home_words, box = ILP_HOME, ILP_CONFINEMENT
    try:
        area = _json(source, "area.json")
    except InputFormatError as exc:
        if "no such file" not in str(exc):
            raise
        area = None
    if area is not None:
        try:
            home_words = str(area["home"])
            box = tuple(float(v) for v in area["confinement"])
            if len(box) != 4 or not (box[0] < box[2] and box[1] < box[3]) \
                    or not all(map(math.isfinite, box)):
                raise ValueError
        except (KeyError, TypeError, ValueError):
            raise InputFormatError(source.where("area.json"), "expected {\"home\": WORDS, "
                                   "\"confinement\": [min_lon, min_lat, max_lon, max_lat]}"
                                   ) from None
        _check_area(source, home_words, box)
    zones = "buildings/no-fly-zones.geojson"
    world = read_geojson_world(source.where(zones), boundary=shapely.box(*box),
                               frame="degrees", text=source.text(zones))
    site = Site(source, (), menu, world, (0.0, 0.0), home_words, box)
    site.shops = tuple(Shop(n, w, site.locate(w)) for n, w in names)
    site.home = site.locate(home_words)
    for label, words, p in [("home", home_words, site.home)] + \
            [(f"shop {s.name!r}", s.words, s.lonlat) for s in site.shops]:
        check_place(site, label, words, p)
    return site


def _check_area(source, home_words: str, box: tuple[float, ...]) -> None:
    """``area.json``'s confinement on its own: on the Earth, small enough for a world, and
    around home. A box too big, or written (lat, lon), was named as a fault of the zones
    file (the world is read from it with the box as its boundary)."""
    where = source.where("area.json")
    try:
        check_places(np.array([box[:2], box[2:]]), "a corner of the confinement")
    except QueryError as exc:
        raise InputFormatError(where, str(exc)) from None
    read_geojson_world(where, boundary=shapely.box(*box), frame="degrees",
                       text='{"type": "FeatureCollection", "features": []}')
    x, y = _read_words(source, home_words)
    if not (box[0] < x < box[2] and box[1] < y < box[3]):
        raise InputFormatError(where, f"home {home_words!r} at ({x}, {y}) is not inside the "
                               f"confinement {list(box)} (min_lon, min_lat, max_lon, "
                               "max_lat)")


def check_place(site: Site, label: str, words: str, p: tuple[float, float]) -> None:
    """A place the drone must reach lies strictly inside the area and outside every zone."""
    if not (site.world.is_free([p])[0] and site.world.blocking([p])[0] < 0):
        raise InputFormatError(site.source.where(f"words/{words.replace('.', '/')}/"
                                                 "details.json"),
                               f"{label} at ({p[0]}, {p[1]}) is outside the confinement area "
                               "or inside a no-fly zone")
