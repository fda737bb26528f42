"""What a fleet run achieved, as the flat numbers of ``report.json``.

Rates count only the measured window ``[warm-up, horizon]``: the first
:data:`~skyroute.fleet.simulate.WARMUP_SHARE` of the horizon (drones spreading out from
their start gates) is excluded. ``offered`` are the packages spawned in the window,
``delivered`` the hand-overs completed in it (whenever the package spawned), so
``served_share`` compares two rates over one window (None when nothing was offered: a
share of nothing is undefined, not 100%). Delivery times (spawn to hand-over)
are those of the packages delivered in the window.

``lost`` is counted from the event log alone, not from the simulation's own arrays: a
package is lost unless its events read spawn, then at most one assign, pickup and
delivery in that order, picked up at its origin gate and delivered at its destination
gate, with nothing after the delivery. ``conflicts``, ``min_horizontal_m`` and
``min_vertical_m`` come from the independent separation checker
(:func:`skyroute.fleet.separation.check`) over every airborne piece of every flight;
``min_vertical_m`` is the least vertical distance of pairs closer than
``sep_horizontal`` horizontally (infinite when no pair came that close).

``capacity_bound_per_hour`` is what the fleet would deliver in the window with no drone
ever idle, at the drone time it spent per delivered package there: ``drones * 3600 /
mean_cycle_s``, the cycle being the drones' **busy time** in the window divided by the
packages delivered in it. A drone is busy with a package from its assignment to the
hand-over at the destination (a repositioning flight, ground holds, loading, the
delivery flight with its loiters, unloading), and idle from then until its next
assignment; a drone works on one package at a time, so its busy spans do not overlap,
and the fleet's busy time in the window is at most ``drones * window``. Hence
``delivered_per_hour <= capacity_bound_per_hour`` in every run, equal when no drone was
idle in the window: the bound is ``delivered_per_hour`` divided by ``busy_share``, the
drones' busy time over ``drones * window``. Busy time is clipped to the window (work
before the warm-up on a package delivered in it is not counted, work on a package still
on its way at the end is), and taken from the assignment and hand-over times as
``packages.csv`` writes them.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from skyroute.fleet.separation import SeparationReport, check
from skyroute.fleet.simulate import SAMPLE_DT, WARMUP_SHARE, Simulation, written

FIELDS = ("offered", "delivered", "delivered_per_hour", "served_share", "p50_delivery_s",
          "p95_delivery_s", "max_wait_s", "loiters", "loiter_s", "conflicts",
          "min_horizontal_m", "min_vertical_m", "lost", "capacity_bound_per_hour",
          "simulated_hours", "wall_seconds")


def lost_packages(events: list[dict], run: Simulation) -> list[int]:
    """Package ids whose event history is not a proper one (see the module docstring)."""
    st = run.stream
    ids = [a.id for a in run.scenario.airports]
    seen: dict[int, list[dict]] = {}
    for e in events:
        if "package" in e and e["kind"] in ("spawn", "assign", "pickup", "delivered"):
            seen.setdefault(e["package"], []).append(e)
    bad = []
    for p in range(len(st)):
        if st.t[p] >= run.horizon:  # the run spawns packages before the horizon only
            continue
        hist = seen.get(p, [])
        kinds = [e["kind"] for e in hist]
        ok = (kinds in (["spawn"], ["spawn", "assign"], ["spawn", "assign", "pickup"],
                        ["spawn", "assign", "pickup", "delivered"])
              and all(a["t"] <= b["t"] for a, b in itertools.pairwise(hist)))
        if ok and "pickup" in kinds:
            e = hist[2]
            ok = e["airport"] == ids[st.origin[p]] and e["gate"] == st.origin_gate[p]
        if ok and "delivered" in kinds:
            e = hist[3]
            ok = (e["airport"] == ids[st.destination[p]]
                  and e["gate"] == st.destination_gate[p])
        if not ok:
            bad.append(p)
    return bad


def window_counts(run: Simulation) -> tuple[int, int]:
    """(offered, delivered) of the report: the packages spawned in the measured window
    ``[warm-up, horizon)`` and the hand-overs completed in ``[warm-up, horizon]``, each
    time as the files write it (:func:`~skyroute.fleet.simulate.written`)."""
    return int(_offered_in_window(run).sum()), int(_delivered_in_window(run).sum())


# Which side of an edge a time falls on is decided on the millisecond the files show: a
# spawn at warm-up - 0.4 ms reads as the warm-up itself in events.jsonl and packages.csv,
# and was left out here while a count from the files took it in. The files hold the
# events up to the horizon by the exact time, so that stays a condition too.
def _offered_in_window(run: Simulation) -> np.ndarray:
    H, t = run.horizon, run.stream.t
    shown = written(t)
    return (t < H) & (shown >= WARMUP_SHARE * H) & (shown < H)


def _delivered_in_window(run: Simulation) -> np.ndarray:
    H, t = run.horizon, run.delivered
    shown = written(t)
    return (t <= H) & (shown >= WARMUP_SHARE * H) & (shown <= H)


def flights_flown(run: Simulation) -> list:
    """The flights of the report: those that took off by the horizon, one ``takeoff``
    event each in the log and one track each in ``fleet.geojson`` (a run also holds
    flights planned to leave after it, and flights still taxiing out at its end, whose
    departure no file shows for an empty repositioning flight)."""
    return [f for f in run.flights if f.plan.phase("takeoff").end <= run.horizon]


def report(run: Simulation, separation: SeparationReport | None = None) -> dict:
    """The ``report.json`` numbers of ``run`` (:data:`FIELDS` first, then
    ``settings`` and a few more counts); runs the separation checker unless given its
    report."""
    s = run.scenario
    sep = separation
    if sep is None:
        pieces = run.pieces()
        sep = check(pieces, sep_horizontal=s.airspace.sep_horizontal,
                    sep_vertical=s.airspace.sep_vertical)
    H = run.horizon
    w0 = WARMUP_SHARE * H
    hours = (H - w0) / 3600.0
    st = run.stream
    done = _delivered_in_window(run)
    offered, delivered = window_counts(run)
    times = (run.delivered - st.t)[done]
    waited = np.where(np.isnan(run.pickup) | (run.pickup > H), H, run.pickup) - st.t
    waited = waited[st.t < H]
    flights = flights_flown(run)
    loiter_s = 2 * math.pi * s.drone.turn_radius / s.drone.cruise_speed
    circles = sum(sum(1 for j in range(f.plan.loiters)
                      if f.plan.landing_request + j * loiter_s <= H) for f in flights)
    busy = _busy_seconds(run)
    # the drones' busy share of the window: at most 1 (spans of one drone never
    # overlap); min() only absorbs the last bits of a float sum, so that a run with no
    # idle drone reports the bound equal to its rate, never a hair below it
    share = min(busy / (s.drones * (H - w0)), 1.0)
    cycle = busy / delivered if delivered else None
    out = {
        "offered": offered,
        "delivered": delivered,
        "delivered_per_hour": delivered / hours,
        "served_share": delivered / offered if offered else None,
        "p50_delivery_s": float(np.percentile(times, 50)) if len(times) else None,
        "p95_delivery_s": float(np.percentile(times, 95)) if len(times) else None,
        "max_wait_s": float(waited.max()) if len(waited) else 0.0,
        "loiters": circles,
        "loiter_s": circles * loiter_s,
        "conflicts": len(sep.conflicts),
        "min_horizontal_m": _finite(sep.min_horizontal_m),
        "min_vertical_m": _finite(sep.min_vertical_m),
        "lost": len(lost_packages(run.events, run)),
        "capacity_bound_per_hour": delivered / hours / share if cycle else None,
        "simulated_hours": run.hours,
        "wall_seconds": run.wall_seconds,
        "offered_per_hour": offered / hours,
        "mean_cycle_s": cycle,
        "busy_share": share,
        "flights": len(flights),
        "reposition_flights": sum(f.kind == "reposition" for f in flights),
        "sim_seconds_per_wall_second": H / run.wall_seconds if run.wall_seconds else None,
        "settings": {
            "scenario": s.name, "airports": len(s.airports), "drones": s.drones,
            "rate_per_hour": run.rate_per_hour, "hours": run.hours, "seed": run.seed,
            "scheduler": run.scheduler, "airspace": run.airspace,
            "sep_horizontal": s.airspace.sep_horizontal,
            "sep_vertical": s.airspace.sep_vertical, "warmup_s": w0, "end_s": H,
            "handover_seconds": s.handover_seconds, "reservation_step_s": SAMPLE_DT,
        },
    }
    return out


def _finite(x: float) -> float | None:
    """JSON has no infinity: None when no pair came near."""
    return float(x) if math.isfinite(x) else None


def _busy_seconds(run: Simulation) -> float:
    """The drones' busy time in the measured window (see the module docstring): for
    every package assigned by the horizon, ``[assigned, hand-over]`` (to the horizon when
    not handed over by then) clipped to ``[warm-up, horizon]``, times as the files write
    them (rounding keeps their order, so one drone's spans still do not overlap)."""
    H = run.horizon
    a, d = run.assigned, run.delivered
    given = a <= H  # not NaN
    w0 = WARMUP_SHARE * H
    start = np.clip(written(a[given]), w0, H)
    end = np.clip(np.where(d[given] <= H, written(d[given]), H), w0, H)
    return float((end - start).sum())
