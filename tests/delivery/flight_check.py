"""An independent check of a stored delivery day (SPEC.md 4.2-4.4), from the raw table
rows, the data files and shapely; nothing of skyroute's is used."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import shapely

STEP = 0.00015


def website(root: Path) -> dict:
    """Menus (item -> (pence, shop)), shop places, zones, the area and home."""
    site = root / "website"

    def place(words: str) -> tuple[float, float]:
        d = json.loads((site / "words" / Path(*words.split(".")) / "details.json").read_text())
        return d["coordinates"]["lng"], d["coordinates"]["lat"]

    menus = json.loads((site / "menus" / "menus.json").read_text())
    # spaces round a name or a place are read past, as skyroute and the CSVs read them
    items = {it["item"].strip(): (it["pence"], s["name"]) for s in menus for it in s["menu"]}
    shops = {s["name"]: place(s["location"].strip()) for s in menus}
    zones = [shapely.geometry.shape(f["geometry"]) for f in json.loads(
        (site / "buildings" / "no-fly-zones.geojson").read_text())["features"]]
    area_file = site / "area.json"
    if area_file.exists():
        area = json.loads(area_file.read_text())
        box, home = tuple(area["confinement"]), place(area["home"])
    else:  # the ILP constants, SPEC.md 4.2-4.3
        box, home = (-3.192473, 55.942617, -3.184319, 55.946233), (-3.186874, 55.944494)
    return {"items": items, "shops": shops, "zones": zones, "box": box, "home": home,
            "place": place}


def order_book(root: Path) -> dict[str, dict]:
    """orderNo -> {date, deliverTo, items} straight from the CSVs."""
    book = {}
    with (root / "database" / "orders.csv").open(newline="") as f:
        for row in csv.DictReader(f):
            book[row["orderNo"]] = {"date": row["deliveryDate"], "to": row["deliverTo"],
                                    "items": []}
    with (root / "database" / "orderDetails.csv").open(newline="") as f:
        for row in csv.DictReader(f):
            book[row["orderNo"]]["items"].append(row["item"])
    return book


def check_day(site: dict, book: dict, date: str, deliveries: list, flightpath: list
              ) -> list[str]:
    """Problems with one day's rows: deliveries (date, order_no, delivered_to, cost) and
    flightpath (date, seq, order_no, from_lon, from_lat, angle, to_lon, to_lat)."""
    bad = []
    x0, y0, x1, y1 = site["box"]
    if len(flightpath) > 1500:
        bad.append(f"{len(flightpath)} moves")
    pos = site["home"]
    for k, (_, seq, _, flon, flat, angle, tlon, tlat) in enumerate(flightpath):
        if seq != k:
            bad.append(f"seq {seq} at row {k}")
        if (flon, flat) != tuple(pos):
            bad.append(f"move {k} does not start where the last ended")
        if angle == -999:
            if (tlon, tlat) != (flon, flat):
                bad.append(f"hover {k} moves")
        else:
            if not (0 <= angle <= 350 and angle % 10 == 0):
                bad.append(f"move {k}: angle {angle}")
            if abs(math.hypot(tlon - flon, tlat - flat) - STEP) > 1e-12:
                bad.append(f"move {k}: length")
            ex = (flon + STEP * math.cos(math.radians(angle)),
                  flat + STEP * math.sin(math.radians(angle)))
            if abs(ex[0] - tlon) > 1e-12 or abs(ex[1] - tlat) > 1e-12:
                bad.append(f"move {k}: wrong end position")
            seg = shapely.LineString([(flon, flat), (tlon, tlat)])
            if any(z.intersects(seg) for z in site["zones"]):
                bad.append(f"move {k} meets a no-fly zone")
        if not (x0 < tlon < x1 and y0 < tlat < y1):
            bad.append(f"move {k} leaves the confinement area")
        pos = (tlon, tlat)
    if not math.dist(pos, site["home"]) < STEP:
        bad.append("does not end close to home")
    hovers = [(r[2], (r[6], r[7])) for r in flightpath if r[5] == -999]
    for _, order_no, to, cost in deliveries:
        o = book[order_no]
        if o["date"] != date or o["to"] != to:
            bad.append(f"{order_no}: wrong date or place")
        if cost != 50 + sum(site["items"][i][0] for i in o["items"]):
            bad.append(f"{order_no}: cost {cost}")
        shops = {site["items"][i][1] for i in o["items"]}
        mine = [p for n, p in hovers if n == order_no]
        cust = site["place"](to)
        at_cust = [j for j, p in enumerate(mine) if math.dist(p, cust) < STEP]
        if not at_cust:
            bad.append(f"{order_no}: no hover at the customer")
            continue
        left = set(shops)  # each shop needs a hover of its own before the drop-off
        for p in mine[:at_cust[-1]]:
            s = next((s for s in sorted(left) if math.dist(p, site["shops"][s]) < STEP), None)
            left.discard(s)
        if left:
            bad.append(f"{order_no}: no hover at {sorted(left)} before the drop-off")
    return bad


def money_pct(site: dict, book: dict, date: str, deliveries: list) -> float:
    """SPEC.md 4.7: delivered cost over the cost of every order placed that day, x 100."""
    placed = sum(50 + sum(site["items"][i][0] for i in o["items"])
                 for o in book.values() if o["date"] == date)
    return 100.0 * sum(d[3] for d in deliveries) / placed
