"""A synthetic lunch-delivery data set in the ILP layout, in another town with its own
buildings, shops, menus, customers' places and orders (the course data has no licence).

Everything comes from one seed, so the same command writes byte-identical files: the set
shipped in ``examples/lunch`` is checked against a fresh one by the tests.
"""

from __future__ import annotations

import datetime as dt
import json
import math
from pathlib import Path

import numpy as np
import shapely
from shapely import affinity

from skyroute.errors import OptionError, check_seed, whole
from skyroute.files import write_atomic
from skyroute.motion.step_drone import STEP

# A 0.0082 x 0.0036 degree box (the ILP area's size) near Leith Links, Edinburgh.
ORIGIN = (-3.1700, 55.9690)
SIZE = (0.0082, 0.0036)
TOWN = "Leith (synthetic)"
WORDS = (
    "amber", "apple", "arch", "badge", "basin", "beacon", "birch", "blade", "bloom", "boat",
    "brick", "brook", "cabin", "candle", "canal", "cedar", "chalk", "cliff", "clover",
    "coast", "comet", "coral", "crane", "crown", "daisy", "delta", "dune", "eagle", "ember",
    "fable", "fern", "field", "flint", "forge", "frost", "garnet", "glade", "globe", "grain",
    "harbor", "hazel", "heron", "hollow", "island", "ivory", "jade", "kettle", "lagoon",
    "lantern", "lemon", "linen", "maple", "marble", "meadow", "mint", "moss", "nectar", "oak",
    "opal", "orchard", "otter", "pebble", "pine", "plume", "quartz", "quill", "raven", "reed",
    "ridge", "river", "robin", "saffron", "sail", "shell", "silver", "slate", "spruce",
    "stone", "thistle", "tide", "timber", "topaz", "tulip", "velvet", "willow", "wren",
)
SHOPS = (("Harbour Bagels", ("bagel", "Smoked salmon", "Cream cheese", "Pastrami",
                             "Falafel", "Egg and cress", "Ham and brie")),
         ("Links Noodles", ("noodle box", "Teriyaki chicken", "Tofu", "Beef chilli",
                            "Prawn", "Vegetable", "Katsu")),
         ("Shore Bakery", ("pie", "Steak", "Cheese and onion", "Chicken and leek",
                           "Mushroom", "Lamb", "Vegan lentil")),
         ("Kirkgate Deli", ("sandwich", "Tuna melt", "Club", "Caprese", "Reuben",
                            "Chicken pesto", "BLT")),
         ("Dock Smoothies", ("smoothie", "Mango", "Berry", "Green", "Peanut banana",
                             "Tropical", "Oat and date")))
SIZES = (("Small", 0), ("Regular", 45), ("Large", 90))


# Random building placement gives up after this many draws and lays the six buildings
# out in a 3 x 2 grid of cells instead: the box is barely big enough for six random
# buildings kept apart, so most seeds paint themselves into a corner (seed 0 fits its
# sixth after about 100,000 draws, seed 1 after 26,000; the bound keeps both as they were).
ZONE_DRAWS = 120_000
ZONE_BATCH = 4_000  # draws made and screened at once (see _zones)
# Places give up after this many draws in a row without finding a free point.
PLACE_DRAWS = 20_000


def _outline(cx: float, cy: float, a: float, b: float, el: bool) -> list[tuple]:
    """The corners of a block (or of an L, the block less its top-right quarter)."""
    if el:
        return [(cx - a, cy - b), (cx + a, cy - b), (cx + a, cy), (cx, cy), (cx, cy + b),
                (cx - a, cy + b)]
    return [(cx - a, cy - b), (cx + a, cy - b), (cx + a, cy + b), (cx - a, cy + b)]


def _may_fit(cx, cy, a, b, el, angle, inner: tuple[float, ...]) -> bool:
    """False when the rotated building surely sticks out of ``inner`` (its bounds): a cheap
    test (plain floats: it runs on every draw) that skips the shapely work for most draws
    without changing any decision."""
    ox, oy = (cx - a / 6, cy - b / 6) if el else (cx, cy)  # the centroid
    t = math.radians(angle)
    c, s = math.cos(t), math.sin(t)
    slack = 1e-6  # the coordinates are rounded to 6 decimals afterwards
    for x, y in _outline(cx, cy, a, b, el):
        qx, qy = ox + c * (x - ox) - s * (y - oy), oy + s * (x - ox) + c * (y - oy)
        if not (inner[0] - slack <= qx <= inner[2] + slack
                and inner[1] - slack <= qy <= inner[3] + slack):
            return False
    return True


def _building(cx, cy, a, b, el, angle) -> shapely.Polygon:
    z = shapely.box(cx - a, cy - b, cx + a, cy + b)
    if el:  # an L: cut a corner out
        z = z.difference(shapely.box(cx, cy, cx + a, cy + b))
    z = affinity.rotate(z, angle, origin="centroid")
    return shapely.Polygon(np.round(np.asarray(z.exterior.coords), 6))


def _zones(rng, box: shapely.Polygon) -> list[shapely.Polygon]:
    """Buildings in the middle of the box: rotated blocks and L shapes, kept apart.

    Drawn at random until six fit; after ``ZONE_DRAWS`` draws, one building in each cell
    of a 3 x 2 grid instead (which always fits). The draws are made ``ZONE_BATCH`` at a
    time (the same numbers, in the same order, as one draw after another) and most are
    set aside by :func:`_surely_not`, without shapely; the others are decided as before.
    """
    x0, y0, x1, y1 = box.bounds
    w, h = x1 - x0, y1 - y0
    inner = box.buffer(-4 * STEP)
    bounds = inner.bounds
    zones: list[shapely.Polygon] = []
    # each draw: cx, cy, a, b in the box's shares below, an L when < 0.5, an angle
    low = np.array([0.25, 0.2, 0.04, 0.08, 0.0, -35.0])
    high = np.array([0.75, 0.8, 0.1, 0.22, 1.0, 35.0])
    for first in range(0, ZONE_DRAWS, ZONE_BATCH):
        n = min(ZONE_BATCH, ZONE_DRAWS - first)
        state = rng.bit_generator.state
        u = rng.random((n, 6))  # as rng.uniform(low, high) and rng.random() draw them
        v = low + (high - low) * u
        v[:, 4] = u[:, 4]
        cx, cy = x0 + w * v[:, 0], y0 + h * v[:, 1]
        a, b = w * v[:, 2], h * v[:, 3]
        el, angle = v[:, 4] < 0.5, v[:, 5]
        skip = _surely_not(cx, cy, a, b, el, angle, bounds, zones)
        for i in np.flatnonzero(~skip):
            args = (float(cx[i]), float(cy[i]), float(a[i]), float(b[i]), bool(el[i]),
                    float(angle[i]))
            if not _may_fit(*args, bounds):
                continue
            z = _building(*args)
            if z.is_valid and all(z.distance(o) > 3 * STEP for o in zones) and \
                    inner.contains(z):
                zones.append(z)
                if len(zones) == 6:
                    rng.bit_generator.state = state  # the draws up to this one, no more
                    rng.random((i + 1) * 6)
                    return zones
                skip[i + 1:] |= _surely_not(cx[i + 1:], cy[i + 1:], a[i + 1:], b[i + 1:],
                                            el[i + 1:], angle[i + 1:], bounds, zones[-1:])
    return _zones_in_cells(rng, inner)


def _surely_not(cx, cy, a, b, el, angle, bounds, zones) -> np.ndarray:
    """For arrays of draws: True where the building surely does not fit, so the loop of
    :func:`_zones` need not look (never where it would be kept): a corner more than
    ``_may_fit``'s slack (and a margin for numpy's sine beside math's) outside
    ``bounds``, or one within 3 steps less 2e-6 of a zone placed (the building's own
    corners are these, moved by less than 1e-6 by the rounding to 6 decimals)."""
    ox = np.where(el, cx - a / 6, cx)  # the centroid
    oy = np.where(el, cy - b / 6, cy)
    # the outline's corners (a block's four, its first one repeated for the L's six)
    px = np.stack([cx - a, cx + a, cx + a, np.where(el, cx, cx - a), np.where(el, cx, cx - a),
                   cx - a], axis=1)
    py = np.stack([cy - b, cy - b, np.where(el, cy, cy + b), np.where(el, cy, cy + b),
                   cy + b, np.where(el, cy + b, cy - b)], axis=1)
    t = np.radians(angle)[:, None]
    c, s = np.cos(t), np.sin(t)
    qx = ox[:, None] + c * (px - ox[:, None]) - s * (py - oy[:, None])
    qy = oy[:, None] + s * (px - ox[:, None]) + c * (py - oy[:, None])
    slack = 1e-6 + 1e-9
    out = ((qx < bounds[0] - slack) | (qx > bounds[2] + slack) | (qy < bounds[1] - slack)
           | (qy > bounds[3] + slack)).any(axis=1)
    look = np.flatnonzero(~out)
    if zones and len(look):
        placed = shapely.union_all(zones)
        shapely.prepare(placed)
        near = shapely.dwithin(placed, shapely.points(qx[look], qy[look]), 3 * STEP - 2e-6)
        out[look] = near.any(axis=1)
    return out


def _zones_in_cells(rng, inner: shapely.Polygon) -> list[shapely.Polygon]:
    """Six buildings, one in each cell of a 3 x 2 grid over ``inner``: each is drawn like
    the random ones, then shrunk to fit its cell less 1.5 steps all round, so any two
    are more than 3 steps apart by construction."""
    x0, y0, x1, y1 = inner.bounds
    cw, ch = (x1 - x0) / 3, (y1 - y0) / 2
    margin = 1.5 * STEP + 2e-6  # half the gap, plus room for rounding to 6 decimals
    zones = []
    for j in range(2):
        for i in range(3):
            cx, cy = x0 + (i + 0.5) * cw, y0 + (j + 0.5) * ch
            a, b = cw * rng.uniform(0.3, 0.5), ch * rng.uniform(0.3, 0.5)
            el = bool(rng.random() < 0.5)
            angle = rng.uniform(-35, 35)
            z = affinity.rotate(_building(cx, cy, a, b, el, 0.0), angle, origin="centroid")
            bx0, by0, bx1, by1 = z.bounds
            k = min(1.0, (cw / 2 - margin) / max(cx - bx0, bx1 - cx),
                    (ch / 2 - margin) / max(cy - by0, by1 - cy))
            z = affinity.scale(z, k, k, origin=(cx, cy))
            z = shapely.Polygon(np.round(np.asarray(z.exterior.coords), 6))
            zones.append(z if z.is_valid else _building(cx, cy, a * k, b * k, False, 0.0))
    return zones


def _places(rng, box, zones, n: int, taken: list) -> list[tuple[float, float]]:
    """Free points at least 2 steps from zones and edges, 3 steps from each other.

    Raises OptionError (naming --customers, the only count a caller chooses) after
    ``PLACE_DRAWS`` draws in a row that find no free point.
    """
    x0, y0, x1, y1 = box.bounds
    inner = box.buffer(-2 * STEP)
    out: list[tuple[float, float]] = []
    misses = 0
    while len(out) < n:
        p = (round(float(rng.uniform(x0, x1)), 6), round(float(rng.uniform(y0, y1)), 6))
        pt = shapely.Point(p)
        if inner.contains(pt) and all(z.distance(pt) > 2 * STEP for z in zones) and \
                all(math.dist(p, q) > 3 * STEP for q in taken + out):
            out.append(p)
            misses = 0
        else:
            misses += 1
            if misses >= PLACE_DRAWS:
                raise OptionError(
                    f"customers: no room for another place in the area after "
                    f"{len(taken) + len(out)} places; use fewer --customers", param="customers")
    return out


def _details(words: str, p: tuple[float, float]) -> str:
    d = 0.000015
    return json.dumps({"country": "GB", "square": {
        "southwest": {"lng": round(p[0] - d, 6), "lat": round(p[1] - d, 6)},
        "northeast": {"lng": round(p[0] + d, 6), "lat": round(p[1] + d, 6)}},
        "nearestPlace": TOWN, "coordinates": {"lng": p[0], "lat": p[1]}, "words": words,
        "language": "en", "map": ""}, indent=2) + "\n"


def synth(out: Path, *, days: int = 7, orders_per_day: int = 12, seed: int = 1,
          start: dt.date = dt.date(2024, 1, 1), customers: int = 7) -> dict:
    """Write the data set to ``out``; return a summary of what was written."""
    # integers, numpy's too (a numpy days= broke timedelta), each named alone
    days, customers = whole("days", days, low=1), whole("customers", customers, low=1)
    orders_per_day = whole("orders_per_day", orders_per_day, low=0)
    seed = check_seed(seed)
    try:
        start + dt.timedelta(days=days - 1)
    except OverflowError:
        raise OptionError(f"start={start.isoformat()} plus days={days} goes past "
                          f"{dt.date.max.isoformat()}, the last date there is",
                          param=("start", "days")) from None
    box = shapely.box(ORIGIN[0], ORIGIN[1], ORIGIN[0] + SIZE[0], ORIGIN[1] + SIZE[1])
    # No more points 3 steps apart fit in the area than disks of 1.5 steps' radius packed
    # as densely as disks go (pi / sqrt(12)) into it, grown by 1.5 steps all round.
    side = 3 * STEP
    most = int((SIZE[0] - 4 * STEP + side) * (SIZE[1] - 4 * STEP + side)
               / (math.sqrt(3) / 2 * side * side)) - 1 - len(SHOPS) - 2
    if customers > most:
        raise OptionError(f"customers={customers}: the area holds at most {most} "
                          f"customers' places", param="customers")
    rng = np.random.default_rng(seed)
    zones = _zones(rng, box)
    home = _places(rng, box, zones, 1, [])
    shops = _places(rng, box, zones, len(SHOPS), home)
    custs = _places(rng, box, zones, customers, home + shops)
    lands = _places(rng, box, zones, 2, home + shops + custs)
    pts = home + shops + custs + lands
    names = rng.choice(len(WORDS), size=(len(pts), 3), replace=True)
    addr = []
    for row in names:
        w = ".".join(WORDS[k] for k in row)
        while w in addr:
            w = ".".join(WORDS[k] for k in rng.choice(len(WORDS), 3))
        addr.append(w)
    site = out / "website"
    for w, p in zip(addr, pts, strict=True):
        write_atomic(site / "words" / Path(*w.split(".")) / "details.json", _details(w, p))
    menus, items = [], []
    for k, (shop, (kind, *fillings)) in enumerate(SHOPS):
        base = int(rng.integers(16, 60)) * 5
        menu = []
        for f in fillings:
            for size, extra in SIZES:
                name = f"{f} {kind} ({size})"
                menu.append({"item": name, "pence": base + extra + 5 * int(rng.integers(0, 8))})
                items.append((name, k))
        menus.append({"name": shop, "location": addr[1 + k], "menu": menu})
    write_atomic(site / "menus" / "menus.json", json.dumps(menus, indent=2) + "\n")
    fc = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {"name": f"Building {chr(65 + k)}"},
         "geometry": {"type": "Polygon",
                      "coordinates": [np.asarray(z.exterior.coords).tolist()]}}
        for k, z in enumerate(zones)]}
    write_atomic(site / "buildings" / "no-fly-zones.geojson", json.dumps(fc, indent=1) + "\n")
    lm = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {"name": f"Landmark {k + 1}", "location": w},
         "geometry": {"type": "Point", "coordinates": list(p)}}
        for k, (w, p) in enumerate(zip(addr[-2:], lands, strict=True))]}
    write_atomic(site / "buildings" / "landmarks.geojson", json.dumps(lm, indent=1) + "\n")
    write_atomic(site / "area.json", json.dumps(
        {"home": addr[0], "confinement": [round(v, 6) for v in box.bounds],
         "town": TOWN}, indent=1) + "\n")
    orders, details, used = ["orderNo,deliveryDate,customer,deliverTo"], ["orderNo,item"], set()
    cust_words = addr[1 + len(SHOPS):1 + len(SHOPS) + customers]
    for d in range(days):
        day = start + dt.timedelta(days=d)
        for _ in range(orders_per_day):
            no = f"{int(rng.integers(0, 2**32)):08x}"
            while no in used:
                no = f"{int(rng.integers(0, 2**32)):08x}"
            used.add(no)
            orders.append(f"{no},{day.isoformat()},s{day:%y}{int(rng.integers(0, 99999)):05d},"
                          f"{cust_words[int(rng.integers(0, customers))]}")
            two = rng.random() < 0.6
            shop_ids = rng.choice(len(SHOPS), 2 if two else 1, replace=False)
            n = int(rng.integers(max(1, len(shop_ids)), 5))
            for j in range(n):
                s = int(shop_ids[j % len(shop_ids)])
                pool = [name for name, k in items if k == s]
                details.append(f"{no},{pool[int(rng.integers(0, len(pool)))]}")
    write_atomic(out / "database" / "orders.csv", "\n".join(orders) + "\n")
    write_atomic(out / "database" / "orderDetails.csv", "\n".join(details) + "\n")
    return {"folder": str(out), "days": days, "first": start.isoformat(),
            "last": (start + dt.timedelta(days=days - 1)).isoformat(),
            "orders": days * orders_per_day, "shops": len(SHOPS), "customers": customers,
            "zones": len(zones)}
