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

from skyroute.errors import OptionError
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


def _zones(rng, box: shapely.Polygon) -> list[shapely.Polygon]:
    """Buildings in the middle of the box: rotated blocks and L shapes, kept apart."""
    x0, y0, x1, y1 = box.bounds
    w, h = x1 - x0, y1 - y0
    zones: list[shapely.Polygon] = []
    while len(zones) < 6:
        cx = x0 + w * rng.uniform(0.25, 0.75)
        cy = y0 + h * rng.uniform(0.2, 0.8)
        a, b = w * rng.uniform(0.04, 0.1), h * rng.uniform(0.08, 0.22)
        z = shapely.box(cx - a, cy - b, cx + a, cy + b)
        if rng.random() < 0.5:  # an L: cut a corner out
            z = z.difference(shapely.box(cx, cy, cx + a, cy + b))
        z = affinity.rotate(z, rng.uniform(-35, 35), origin="centroid")
        z = shapely.Polygon(np.round(np.asarray(z.exterior.coords), 6))
        if z.is_valid and all(z.distance(o) > 3 * STEP for o in zones) and \
                box.buffer(-4 * STEP).contains(z):
            zones.append(z)
    return zones


def _places(rng, box, zones, n: int, taken: list) -> list[tuple[float, float]]:
    """Free points at least 2 steps from zones and edges, 3 steps from each other."""
    x0, y0, x1, y1 = box.bounds
    inner = box.buffer(-2 * STEP)
    out = []
    while len(out) < n:
        p = (round(float(rng.uniform(x0, x1)), 6), round(float(rng.uniform(y0, y1)), 6))
        pt = shapely.Point(p)
        if inner.contains(pt) and all(z.distance(pt) > 2 * STEP for z in zones) and \
                all(math.dist(p, q) > 3 * STEP for q in taken + out):
            out.append(p)
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
    if days < 1 or orders_per_day < 0 or customers < 1:
        raise OptionError(f"days={days} and customers={customers} must be at least 1, "
                          f"orders_per_day={orders_per_day} >= 0", param="days")
    rng = np.random.default_rng(seed)
    box = shapely.box(ORIGIN[0], ORIGIN[1], ORIGIN[0] + SIZE[0], ORIGIN[1] + SIZE[1])
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
