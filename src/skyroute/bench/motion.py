"""``skyroute bench motion``: Dubins batch speed against OMPL, and the step drone's
fewest-moves search against rounding a Theta* path, over every pair of ILP places."""

from __future__ import annotations

import itertools
import json
import math
import time
from pathlib import Path

import numpy as np


def dubins_speed(n: int = 100_000, seed: int = 0, radius: float = 1.7) -> dict:
    """Microseconds per query: our compiled batch, and OMPL's distance() called from Python."""
    from skyroute.motion.dubins import lengths

    rng = np.random.default_rng(seed)
    s = np.c_[rng.uniform(-10, 10, (n, 2)), rng.uniform(-math.pi, math.pi, n)]
    g = np.c_[rng.uniform(-10, 10, (n, 2)), rng.uniform(-math.pi, math.pi, n)]
    lengths(s[:10], g[:10], radius)
    best = min(_timed(lambda: lengths(s, g, radius)) for _ in range(5))
    out = {"queries": n, "skyroute_us": best / n * 1e6}
    try:
        from ompl import base as ob
    except ImportError:
        return out
    space = ob.DubinsStateSpace(radius)
    a, b = space.allocState(), space.allocState()
    m = min(n, 20_000)
    t0 = time.perf_counter()
    for i in range(m):
        a.setX(s[i, 0]), a.setY(s[i, 1]), a.setYaw(s[i, 2])
        b.setX(g[i, 0]), b.setY(g[i, 1]), b.setYaw(g[i, 2])
        space.distance(a, b)
    out["ompl_us"] = (time.perf_counter() - t0) / m * 1e6
    return out


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def step_drone_pairs(data: Path, *, max_expansions: int, merge: float, on_pair=None) -> dict:
    """plan_moves and follow (on a Theta* path) for every ordered pair of ILP places."""
    from skyroute.motion.step_drone import follow, plan_moves
    from skyroute.planner import plan
    from skyroute.world.load import load_world

    world = load_world(data / "website/buildings/no-fly-zones.geojson", frame="degrees",
                       boundary=data / "testing/confinement-zone.geojson")
    doc = json.loads((data / "testing/all.geojson").read_text())
    places = {f["properties"]["name"]: f["geometry"]["coordinates"] for f in doc["features"]
              if f["geometry"]["type"] == "Point"}
    rows = []
    for a, b in itertools.permutations(places, 2):
        t0 = time.perf_counter()
        m = plan_moves(world, places[a], places[b], max_expansions=max_expansions, merge=merge)
        ms = (time.perf_counter() - t0) * 1e3
        route = plan(world, places[a], places[b], algorithm="theta")
        f = follow(world, route.path)
        rows.append({"from": a, "to": b, "moves": m.moves if m.status.value == "found"
                     else None, "ms": ms, "expanded": m.expanded,
                     "follow": f.moves if f.status.value == "found" else None})
        if on_pair:
            on_pair()
    both = [r for r in rows if r["moves"] is not None and r["follow"] is not None]
    times = np.array([r["ms"] for r in rows])
    return {"pairs": len(rows), "solved": sum(r["moves"] is not None for r in rows),
            "follow_solved": sum(r["follow"] is not None for r in rows),
            "moves_total": sum(r["moves"] for r in both),
            "follow_total": sum(r["follow"] for r in both),
            "ratio": sum(r["moves"] for r in both) / max(1, sum(r["follow"] for r in both)),
            "median_ms": float(np.median(times)), "p90_ms": float(np.percentile(times, 90)),
            "max_ms": float(times.max()), "rows": rows}
