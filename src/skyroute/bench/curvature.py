"""Turning-radius planning against OMPL: skyroute's Hybrid A* vs RRT* and BIT* in OMPL's
DubinsStateSpace, on seeded random worlds.

Each world is 100 m x 100 m inside a boundary, with 20 axis-aligned and 5 rotated
rectangles (sides 5-20 m); each query joins two free poses at least 60 m apart with a
free 2D path between them (random headings). Every path of every planner is re-checked
with the exact arc test (:func:`skyroute.motion.hybrid.path_free`): OMPL checks states
along its Dubins curves at a resolution, with a Python callback on the prepared union
of the obstacles, so its paths may clip corners; between two of its states the motion
is the shortest Dubins path, which is what is checked. Lengths are also given as ratios
to a lower bound: max(free-space Dubins length, exact 2D shortest path).

OMPL is PyPI ``ompl`` (a bench extra); without it only skyroute's rows are made.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable

import numpy as np
import shapely
from shapely import affinity

from skyroute.world.world import World


def curvature_world(seed: int, *, size: float = 100.0, axis_aligned: int = 20,
                    rotated: int = 5) -> World:
    """Seeded world: ``axis_aligned`` + ``rotated`` rectangles, sides 5-20 % of ``size``,
    in a square boundary."""
    rng = np.random.default_rng(seed)
    lo = rng.uniform(0, size * 0.9, size=(axis_aligned, 2))
    wh = rng.uniform(size * 0.05, size * 0.2, size=(axis_aligned, 2))
    hi = np.minimum(lo + wh, size)
    boxes = list(shapely.box(lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1]))
    for _ in range(rotated):
        c = rng.uniform(0, size, 2)
        w, h = rng.uniform(size * 0.05, size * 0.2, 2)
        box = shapely.box(c[0] - w / 2, c[1] - h / 2, c[0] + w / 2, c[1] + h / 2)
        boxes.append(affinity.rotate(box, rng.uniform(0, 180), origin="centroid"))
    n = len(boxes)
    return World(np.array(boxes, dtype=object), np.full(n, -np.inf), np.full(n, np.inf), (),
                 shapely.box(0, 0, size, size), "enu", name=f"curvature-{seed}")


def query_poses(world: World, rng: np.random.Generator, min_dist: float = 60.0) -> tuple:
    """Start and goal poses: free points ``min_dist`` apart, joined by a free 2D path."""
    from skyroute.bench.world import free_pair

    a, b = free_pair(world, rng, min_dist)
    h = rng.uniform(-math.pi, math.pi, 2)
    return (float(a[0]), float(a[1]), float(h[0])), (float(b[0]), float(b[1]), float(h[1]))


def lower_bound(world: World, start, goal, radius: float) -> float:
    """max(free-space Dubins length, exact 2D shortest path)."""
    from skyroute.motion.dubins import shortest_path
    from skyroute.planner import plan

    d2 = plan(world, start[:2], goal[:2])
    return max(shortest_path(start, goal, radius).length, d2.cost if d2.found else math.inf)


def dubins_chain_free(world: World, states: np.ndarray, radius: float) -> bool:
    """The shortest Dubins paths between consecutive poses, exactly free."""
    from skyroute.motion.hybrid import path_free
    from skyroute.motion.smooth import dubins_pieces

    pieces = []
    for a, b in itertools.pairwise(states):
        pieces += dubins_pieces(tuple(a), tuple(b), radius)
    return path_free(world, pieces)


def run_skyroute(world: World, start, goal, radius: float) -> dict:
    """Hybrid A* on a fresh copy of ``world`` (edge buckets and corner table built and
    timed), then again on the same world (those reused)."""
    from skyroute.motion.hybrid import path_free, plan

    fresh = World(world.obstacles, world.floors, world.ceilings, world.names,
                  world.boundary, world.frame, world.home, world.name, world.source)
    t0 = time.perf_counter()
    r = plan(fresh, start, goal, radius)
    cold = time.perf_counter() - t0
    t0 = time.perf_counter()
    r = plan(fresh, start, goal, radius)
    warm = time.perf_counter() - t0
    return {"runner": "skyroute hybrid", "budget": None, "seconds": warm,
            "cold_seconds": cold, "found": r.found, "length": r.length if r.found else None,
            "raw_length": r.extra.get("raw_length"), "expanded": r.expanded,
            "valid": path_free(world, r.segments) if r.found else None,
            "status": r.status.value}


def dubins_checker(world: World) -> Callable[[object], bool]:
    """OMPL's state validity callback for a ``DubinsStateSpace``: strictly inside the
    boundary and outside every obstacle (the prepared union). It runs inside OMPL's timed
    solve, so when the boundary is the bounds rectangle (``boundary_is_bounds``), four
    comparisons replace the polygon test; some test must stay, as OMPL checks states
    along Dubins curves, which can swing outside its bounds."""
    from skyroute.bench.world import boundary_is_bounds

    union = shapely.unary_union(world.obstacles)
    shapely.prepare(union)
    if boundary_is_bounds(world):
        xmin, ymin, xmax, ymax = world.bounds

        def valid_box(state) -> bool:
            x, y = state.getX(), state.getY()
            return xmin < x < xmax and ymin < y < ymax and \
                not shapely.contains_xy(union, x, y)
        return valid_box
    inside = shapely.Polygon(world.boundary)
    shapely.prepare(inside)

    def valid(state) -> bool:
        x, y = state.getX(), state.getY()
        return bool(shapely.contains_xy(inside, x, y)) and not shapely.contains_xy(union, x, y)
    return valid


def run_ompl(world: World, start, goal, radius: float, planner: str,
             seconds: float) -> dict:
    """One OMPL solve in a DubinsStateSpace: time, exact solution or not, raw and
    simplified lengths, exact validity of both paths, and ``simplifySolution()``'s time
    (``simplify_seconds``; not in ``seconds``)."""
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    from skyroute.bench.world import ompl_bounds

    ou.setLogLevel(ou.LOG_NONE)
    space = ob.DubinsStateSpace(radius)
    space.setBounds(ompl_bounds(ob, world))
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(dubins_checker(world))
    s, g = space.allocState(), space.allocState()
    s.setX(start[0]), s.setY(start[1]), s.setYaw(start[2])
    g.setX(goal[0]), g.setY(goal[1]), g.setYaw(goal[2])
    ss.setStartAndGoalStates(s, g)
    ss.setPlanner(getattr(og, planner)(ss.getSpaceInformation()))
    t0 = time.perf_counter()
    status = ss.solve(seconds)
    took = time.perf_counter() - t0
    row = {"runner": f"ompl {planner}", "budget": seconds, "seconds": took,
           "found": str(status) == "Exact solution" and ss.haveExactSolutionPath()}
    if not row["found"]:
        return {**row, "length": None, "valid": None, "simplified": None,
                "simplified_valid": None, "simplify_seconds": None}

    def states():
        p = ss.getSolutionPath()
        return p.length(), np.array([(p.getState(i).getX(), p.getState(i).getY(),
                                      p.getState(i).getYaw())
                                     for i in range(p.getStateCount())])

    length, pts = states()
    row.update(length=length, valid=dubins_chain_free(world, pts, radius))
    t0 = time.perf_counter()
    ss.simplifySolution()
    row["simplify_seconds"] = time.perf_counter() - t0
    slength, spts = states()
    row.update(simplified=slength, simplified_valid=dubins_chain_free(world, spts, radius))
    return row


def city_world(path, *, altitude: float = 10.0, safety: float = 2.0) -> World:
    """A colliders city (e.g. ``examples/city.csv``) as a plane world inside a boundary
    around its buildings, for OMPL's bounded state space. A city no building of which
    counts at ``altitude`` is an OptionError on ``city`` (:func:`curvature_benchmark`'s
    parameter; the altitude is fixed there)."""
    from skyroute.bench.world import check_altitude, no_building_at
    from skyroute.errors import OptionError
    from skyroute.world.load import load_world

    check_altitude(altitude)
    whole = load_world(path, safety=safety, frame="enu")
    city = whole.at(altitude)
    if len(city.obstacles) == 0:
        raise OptionError(f"city={path}: the benchmark flies at {altitude:g} m, and "
                          f"{no_building_at(whole, altitude, safety)}", param="city")
    x0, y0, x1, y1 = city.bounds
    box = shapely.box(x0 - 20, y0 - 20, x1 + 20, y1 + 20)
    return World(city.obstacles, city.floors, city.ceilings, city.names, box, "enu",
                 city.home, f"{city.name} (boundary 20 m out)", city.source)


def curvature_queries(worlds: int = 10, seed: int = 0, *, city=None,
                      city_queries: int = 5) -> list[tuple]:
    """(world, index, start, goal): one query per seeded world and ``city_queries`` on
    the ``city`` colliders file when given, all drawn before any timing, so a city that
    cannot be read or has no query fails first."""
    cases = [(curvature_world(seed + w), np.random.default_rng([seed, w]), w)
             for w in range(worlds)]
    if city is not None:
        cw = city_world(city)
        cases += [(cw, np.random.default_rng([seed, 1000 + q]), q)
                  for q in range(city_queries)]
    return [(world, w, *query_poses(world, rng)) for world, rng, w in cases]


def curvature_benchmark(worlds: int = 10, seed: int = 0, budgets: tuple = (1.0, 5.0), *,
                        planners: tuple = ("RRTstar", "BITstar"), radius: float = 5.0,
                        city=None, city_queries: int = 5,
                        on_step: Callable[[dict], None] | None = None) -> list[dict]:
    """One query per seeded world (and ``city_queries`` on the ``city`` colliders file
    when given); one row per planner run (:func:`run_queries`)."""
    return run_queries(curvature_queries(worlds, seed, city=city, city_queries=city_queries),
                       budgets, planners=planners, radius=radius, on_step=on_step)


def run_queries(queries: list[tuple], budgets: tuple = (1.0, 5.0), *,
                planners: tuple = ("RRTstar", "BITstar"), radius: float = 5.0,
                on_step: Callable[[dict], None] | None = None) -> list[dict]:
    """One row per planner run on each of :func:`curvature_queries`' queries (``world``,
    ``runner``, ``budget``, ``seconds``, ``found``, ``length``, ``valid``, ``ratio`` to
    the lower bound, ...). ``on_step`` is called with each row as it is made."""
    from skyroute.bench.world import ompl_available

    rows = []
    for world, w, start, goal in queries:
        bound = lower_bound(world, start, goal, radius)
        runs = [(run_skyroute, ())]
        if ompl_available():
            runs += [(run_ompl, (p, b)) for b in budgets for p in planners]
        for run, extra in runs:
            row = {"world": f"{world.name} #{w}", "start": start, "goal": goal,
                   "bound": bound,
                   **run(world, start, goal, radius, *extra)}
            row["ratio"] = row["length"] / bound if row["length"] is not None else None
            rows.append(row)
            if on_step:
                on_step(row)
    return rows


def summary(rows: list[dict]) -> dict:
    """Per runner and budget: solved, exactly valid, median length ratio; skyroute's
    median and p95 times; how often skyroute is no longer than RRT* at the largest
    budget, and its worst length ratio to it."""
    out: dict = {}
    for key in sorted({(r["runner"], r["budget"] or 0) for r in rows}):
        sel = [r for r in rows if (r["runner"], r["budget"] or 0) == key]
        found = [r for r in sel if r["found"]]
        out[f"{key[0]} @ {key[1]:g}s" if key[1] else key[0]] = {
            "queries": len(sel), "found": len(found),
            "valid": sum(bool(r["valid"]) for r in found),
            "median_ratio": float(np.median([r["ratio"] for r in found])) if found else None,
            "median_ms": float(np.median([r["seconds"] for r in sel]) * 1e3),
            "p95_ms": float(np.percentile([r["seconds"] for r in sel], 95) * 1e3),
        }
    ours = {r["world"]: r for r in rows if r["runner"] == "skyroute hybrid"}
    top = max((r["budget"] for r in rows if r["budget"]), default=None)
    if top is not None:
        for name in sorted({r["runner"] for r in rows if r["budget"]}):
            peer = {r["world"]: r for r in rows if r["runner"] == name and r["budget"] == top}
            both = [w for w in ours if ours[w]["found"] and w in peer and peer[w]["found"]]
            ratios = [ours[w]["length"] / peer[w]["length"] for w in both]
            out[f"skyroute vs {name} @ {top:g}s"] = {
                "peer_solved_we_missed": sum(1 for w in peer if peer[w]["found"] and
                                             not ours[w]["found"]),
                "no_longer": sum(x <= 1.0 + 1e-9 for x in ratios), "compared": len(both),
                "worst_ratio": max(ratios) if ratios else None}
    return out


def tour_benchmark(instances: int = 20, seed: int = 0, *, targets: int = 10,
                   radius: float = 10.0, headings: int = 16, size: float = 200.0) -> dict:
    """Seeded random tours in free space (start pose and ``targets`` points in a square
    of ``size`` metres): the exact tour (Held-Karp), the local search alone (its gap to
    the exact one) and the greedy nearest-first baseline (how much longer it is)."""
    from skyroute.motion.tour import tour

    gaps, longer, exact_s, local_s = [], [], [], []
    for i in range(instances):
        rng = np.random.default_rng([seed, i])
        start = (*rng.uniform(0, size, 2), rng.uniform(0, 2 * math.pi))
        pts = rng.uniform(0, size, (targets, 2))
        exact = tour(start, pts, radius, headings=headings)
        local = tour(start, pts, radius, headings=headings, exact_limit=0)
        gaps.append(local.length / exact.length - 1)
        longer.append(exact.greedy_bound / exact.length - 1)
        exact_s.append(exact.seconds)
        local_s.append(local.seconds)
    return {"instances": instances, "targets": targets, "radius": radius,
            "headings": headings,
            "greedy_longer_mean": float(np.mean(longer)),
            "greedy_longer_min": float(np.min(longer)),
            "greedy_longer_max": float(np.max(longer)),
            "local_gap_mean": float(np.mean(gaps)), "local_gap_max": float(np.max(gaps)),
            "local_exact": int(sum(g < 1e-9 for g in gaps)),
            "exact_ms_median": float(np.median(exact_s) * 1e3),
            "local_ms_median": float(np.median(local_s) * 1e3)}
