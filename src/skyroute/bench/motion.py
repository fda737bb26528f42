"""``skyroute bench motion``: Dubins batch speed against OMPL, and the step drone's
fewest-moves search against rounding a Theta* path, over every pair of ILP places."""

from __future__ import annotations

import itertools
import json
import math
import time
from pathlib import Path

import numpy as np

from skyroute.errors import InputFormatError, OptionError
from skyroute.files import cannot_read


def dubins_speed(*, sizes=(100_000, 1_000_000), threads=(1, 2), repeats: int = 7,
                 seed: int = 0, radius: float = 1.7, ompl_calls: int = 5_000) -> dict:
    """Microseconds per query of the compiled batch (:func:`skyroute.motion.dubins.lengths`)
    for each batch size and numba thread count: the median of ``repeats`` runs, each run
    followed by ``ompl_calls`` calls of OMPL's ``DubinsStateSpace.distance()`` from Python
    (interleaved, so both see the same machine load; compare the ratio). OMPL's states
    are made before its clock starts, which then times only the ``distance()`` calls (as
    ours times only ``lengths()`` on ready arrays). Also the largest difference from OMPL
    over the first 100,000 queries (the tests' bound: 1e-9)."""
    import numba

    from skyroute.motion.dubins import lengths

    rng = np.random.default_rng(seed)
    n_max = max(sizes)
    s = np.c_[rng.uniform(-10, 10, (n_max, 2)), rng.uniform(-math.pi, math.pi, n_max)]
    g = np.c_[rng.uniform(-10, 10, (n_max, 2)), rng.uniform(-math.pi, math.pi, n_max)]
    lengths(s[:10], g[:10], radius)  # compile (or load) first
    space = _ompl_space(radius)
    if space is not None:  # made before any clock starts: OMPL's times hold distance() only
        m_max = min(n_max, ompl_calls)
        a, b = _ompl_states(space, s[:m_max]), _ompl_states(space, g[:m_max])
    out = {"radius": radius, "seed": seed, "repeats": repeats, "ompl_calls": ompl_calls,
           "threading_layer": None, "rows": []}
    before = numba.get_num_threads()
    try:
        for n in sizes:
            for t in threads:
                numba.set_num_threads(min(t, numba.config.NUMBA_NUM_THREADS))
                ours, theirs = [], []
                for _ in range(repeats):
                    ours.append(_timed(lambda n=n: lengths(s[:n], g[:n], radius)) / n * 1e6)
                    if space is not None:
                        m = min(n, ompl_calls)
                        pairs = a[:m], b[:m]
                        theirs.append(_timed(lambda p=pairs: list(map(space.distance, *p)))
                                      / m * 1e6)
                row = {"queries": n, "threads": numba.get_num_threads(),
                       "skyroute_us": float(np.median(ours)), "skyroute_min_us": min(ours)}
                if theirs:
                    row["ompl_us"] = float(np.median(theirs))
                out["rows"].append(row)
    finally:
        numba.set_num_threads(before)
    out["threading_layer"] = numba.threading_layer()
    if space is not None:
        k = min(n_max, 100_000)
        out["max_abs_diff_ompl"] = float(np.max(np.abs(lengths(s[:k], g[:k], radius)
                                                       - _ompl_lengths(space, s[:k], g[:k]))))
    return out


def _ompl_space(radius: float):
    """OMPL's ``DubinsStateSpace(radius)``; None without OMPL."""
    try:
        from ompl import base as ob
    except ImportError:
        return None
    return ob.DubinsStateSpace(radius)


def _ompl_states(space, poses: np.ndarray) -> list:
    """One OMPL state of ``space`` per pose (x, y, yaw). Made once per benchmark: the
    bindings leak about 125 bytes of each state when it is collected."""
    states = []
    for x, y, yaw in poses.tolist():
        state = space.allocState()
        state.setX(x), state.setY(y), state.setYaw(yaw)
        states.append(state)
    return states


def _ompl_lengths(space, s: np.ndarray, g: np.ndarray) -> np.ndarray:
    """OMPL's distance for each pose pair through two reused states (the agreement
    check; not timed)."""
    a, b = space.allocState(), space.allocState()
    out = np.empty(len(s))
    for i in range(len(s)):
        a.setX(s[i, 0]), a.setY(s[i, 1]), a.setYaw(s[i, 2])
        b.setX(g[i, 0]), b.setY(g[i, 1]), b.setYaw(g[i, 2])
        out[i] = space.distance(a, b)
    return out


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


ZONES = "website/buildings/no-fly-zones.geojson"
CONFINEMENT = "testing/confinement-zone.geojson"
PLACES = "testing/all.geojson"


def load_ilp(data: str | Path) -> tuple:
    """(world, places) of the ILP data folder ``data``: the no-fly zones inside the
    confinement zone (degrees frame) and the named points of testing/all.geojson. Read
    before any timing, so a wrong folder is an OptionError on ``data`` naming what is
    missing, and a broken file an InputFormatError naming it."""
    from skyroute.world.load import load_world

    data = Path(data)
    if not data.is_dir():
        raise OptionError(f"data={data}: no such folder", param="data")
    for name in (ZONES, CONFINEMENT, PLACES):
        if not (data / name).is_file():
            raise OptionError(f"data={data}: no {name} in it (give the ILP data folder, with "
                              "website/ and testing/)", param="data")
    world = load_world(data / ZONES, frame="degrees", boundary=data / CONFINEMENT)
    places = ilp_places(data / PLACES)
    for name, point in places.items():  # a place in a zone fails here, not mid-run
        world.check_point(point, f"{data / PLACES}: place {name!r}")
    return world, places


def ilp_places(path: Path) -> dict:
    """{name: [lon, lat]} of the named Point features of a GeoJSON FeatureCollection."""
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
        places = {f["properties"]["name"]: f["geometry"]["coordinates"]
                  for f in doc["features"] if f["geometry"]["type"] == "Point"}
    except OSError as exc:
        raise cannot_read(path, exc) from None
    except (UnicodeDecodeError, ValueError) as exc:
        raise InputFormatError(path, f"cannot read: {exc}") from None
    except (KeyError, TypeError, AttributeError):
        raise InputFormatError(path, "expected a FeatureCollection of Point features with "
                                     "a name property") from None
    if len(places) < 2:
        raise InputFormatError(path, f"{len(places)} named Point features; need 2 or more")
    return places


def step_drone_pairs(world, places: dict, *, max_expansions: int, merge: float,
                     on_pair=None) -> dict:
    """plan_moves and follow (on a Theta* path) for every ordered pair of ``places`` in
    ``world`` (:func:`load_ilp`)."""
    from skyroute.motion.step_drone import follow, plan_moves
    from skyroute.planner import plan

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
