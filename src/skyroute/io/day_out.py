"""What a delivery day leaves on disk: ``drone-DD-MM-YYYY.geojson`` (the flight as one
LineString, SPEC.md 4.6), a PNG map of the day and a JSON report; each file is written
whole or not at all. (Its rows in the store, :func:`skyroute.delivery.store.store_day`,
are committed with them: :func:`skyroute.jobs.deliver.run_days`.)
"""

from __future__ import annotations

import datetime as dt
from pathlib import Path

import numpy as np

from skyroute.delivery.day import DayResult
from skyroute.files import check_writable, write_atomic, written_together
from skyroute.io.json_text import to_json


def stem(date: dt.date) -> str:
    """The ILP file name stem of a day: ``drone-DD-MM-YYYY``."""
    return f"drone-{date:%d-%m-%Y}"


def geojson(result: DayResult, home) -> str:
    f = result.flight.flight
    pts = np.vstack([f.frm[:1], f.to]) if f.moves else np.array([home, home], dtype=float)
    return to_json({"type": "FeatureCollection", "features": [{
        "type": "Feature", "properties": {"date": result.date.isoformat(),
                                          "moves": f.moves},
        "geometry": {"type": "LineString", "coordinates": pts.tolist()}}]})


def plot_day(site, result: DayResult, path: Path) -> Path:
    """Zones, area, the flight, shops, customer places (:func:`customer_places`: served,
    partly served or not served, each kind in the legend only when the day has one,
    with its count), home."""
    from skyroute.io.plot import new_figure, place_labels, save_figure, set_title
    from skyroute.io.world_out import draw_world, finish_axes

    fig, ax = new_figure((10, 6))
    draw_world(ax, site.world, label="no-fly zone")
    f = result.flight.flight
    if f.moves:
        pts = np.vstack([f.frm[:1], f.to])
        ax.plot(pts[:, 0], pts[:, 1], "-", color="tab:blue", lw=0.8, label="flight")
    shops = np.array([s.lonlat for s in site.shops], dtype=float).reshape(-1, 2)
    ax.plot(shops[:, 0], shops[:, 1], "s", color="tab:purple", ms=7, zorder=5, label="shop")
    places = customer_places(site, result)
    for kind, counts in places.items():
        if counts:
            a = np.array(list(counts), dtype=float)
            ax.plot(a[:, 0], a[:, 1], linestyle="none", zorder=5, label=_place_label(kind, counts),
                    **_PLACE_STYLE[kind])
    ax.plot(*site.home, "*", color="black", ms=13, zorder=6, label="home")
    set_title(ax, day_title(result))
    finish_axes(ax, site.world)
    # shop names last, on the final axes, each where it covers no other name or marker
    # (shops a few metres apart had their names piled on one another's squares)
    place_labels(ax, shops, [s.name for s in site.shops], fontsize=7,
                 avoid=[p for counts in places.values() for p in counts] + [site.home])
    return save_figure(fig, path)


def day_title(result: DayResult) -> list[str]:
    """The parts of a day picture's title: the orders delivered of those placed, the
    share of the money and the moves, with thousands separators as the table has them
    (it read "1442 moves" under a table of "1,442"). A day without orders says so
    ("0/0 orders, no orders, 0 moves" before), and a day whose orders are all invalid
    that none was valid (it read "0/5 orders, no orders")."""
    day = f"Delivery day {result.date:%d %b %Y}"
    if not result.orders:
        return [f"{day}: no orders stored", "nothing flown"]
    pct = result.money_pct
    return [f"{day}: {len(result.delivered)}/{len(result.orders)} orders",
            "none valid" if pct is None else f"{pct:.1f}% of the money",
            f"{result.flight.flight.moves:,} moves"]


SERVED, PARTLY, NOT_SERVED = "served", "partly served", "not served"

# a partly served place must not pass for a served one: another shape, half green, half red
_PLACE_STYLE = {
    SERVED: {"marker": "o", "color": "tab:green", "ms": 7},
    PARTLY: {"marker": "D", "color": "tab:green", "markerfacecoloralt": "tab:red",
             "fillstyle": "left", "markeredgecolor": "black", "markeredgewidth": 0.6,
             "ms": 7},
    NOT_SERVED: {"marker": "o", "color": "tab:red", "ms": 7},
}


def customer_places(site, result: DayResult) -> dict[str, dict[tuple[float, float],
                                                                tuple[int, int]]]:
    """The day's customer places (lon, lat) by how they were served, each with
    (orders delivered there, valid orders placed for it): ``"served"`` (every one
    delivered), ``"partly served"`` (some) and ``"not served"`` (none), in that order,
    places sorted. Invalid orders are left out: never flown, the report lists them.

    A place with 3 orders of which 2 were flown is partly served: the picture drew it
    as served, since it only asked whether anything was delivered there."""
    invalid = {o.order_no for o, _ in result.invalid}
    delivered = {p.order.order_no for p in result.delivered}
    counts: dict[tuple[float, float], tuple[int, int]] = {}
    for o in result.orders:
        if o.order_no in invalid:
            continue
        place = tuple(site.locate(o.deliver_to))
        done, placed = counts.get(place, (0, 0))
        counts[place] = (done + (o.order_no in delivered), placed + 1)
    out: dict = {SERVED: {}, PARTLY: {}, NOT_SERVED: {}}
    for place, (done, placed) in sorted(counts.items()):
        kind = SERVED if done == placed else NOT_SERVED if done == 0 else PARTLY
        out[kind][place] = (done, placed)
    return out


def _place_label(kind: str, counts: dict) -> str:
    """``customer served (5 places)``; a partly served kind also counts its orders."""
    n = len(counts)
    text = f"customer {kind} ({n} place{'' if n == 1 else 's'}"
    if kind == PARTLY:
        done = sum(d for d, _ in counts.values())
        placed = sum(p for _, p in counts.values())
        text += f", {done} of {placed} orders"
    return text + ")"


def output_paths(out: Path, date: dt.date, *, plot: bool = True) -> list[Path]:
    """The files :func:`write_outputs` writes for ``date`` in ``out``, in that order:
    GeoJSON, report and (with ``plot``) PNG."""
    base = Path(out) / stem(date)
    paths = [base.with_suffix(".geojson"), Path(out) / f"report-{date:%d-%m-%Y}.json"]
    return [*paths, base.with_suffix(".png")] if plot else paths


def check_outputs(out: Path, dates, *, plot: bool = True) -> list[Path]:
    """Fail now, before any day is flown or stored, if a file :func:`write_outputs`
    would write for one of ``dates`` cannot be written (:func:`skyroute.files.
    check_writable`); the paths otherwise."""
    paths = [p for d in dates for p in output_paths(out, d, plot=plot)]
    for p in paths:
        check_writable(p)
    return paths


def write_outputs(site, result: DayResult, out: Path, *, plot: bool = True) -> list[Path]:
    """The day's GeoJSON, report and (optionally) PNG in ``out``
    (:func:`output_paths`)."""
    paths = output_paths(out, result.date, plot=plot)
    with written_together():  # a Ctrl-C halfway leaves none of the day's files
        write_atomic(paths[0], geojson(result, site.home))
        write_atomic(paths[1], to_json(result.report(), indent=1))
        if plot:
            paths[2] = plot_day(site, result, paths[2])
    return paths
