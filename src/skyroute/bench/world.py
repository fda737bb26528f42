"""``skyroute bench world``: continuous planners against OMPL on the same worlds.

Worlds: seeded random rectangle worlds and, when given, a colliders.csv city at an
altitude. Each query runs skyroute's visibility graph (first query on a fresh graph,
build included and not read from the disk cache, then the same query again), PRM and
Theta* on a raster, and OMPL's PRM, PRM*, RRT*, RRTConnect and InformedRRT* (PyPI
``ompl``, a bench extra) with a time budget, each in a fresh SimpleSetup. OMPL checks
states with a Python callback on the prepared union of the obstacles and checks motions
at its default resolution; every returned path, ours and OMPL's, is re-checked with the
exact segment test.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import numpy as np
import shapely

from skyroute.errors import OptionError, SkyrouteError, real
from skyroute.world.load import ALTITUDE, MIN_ALTITUDE
from skyroute.world.world import World

OMPL_PLANNERS = ("PRM", "PRMstar", "RRTstar", "RRTConnect", "InformedRRTstar")


def random_rect_world(seed: int, *, count: int = 20, size: float = 100.0) -> World:
    """``count`` axis-aligned rectangles (sides 5-20% of ``size``) in a square boundary."""
    rng = np.random.default_rng(seed)
    lo = rng.uniform(0, size * 0.9, size=(count, 2))
    wh = rng.uniform(size * 0.05, size * 0.2, size=(count, 2))
    hi = np.minimum(lo + wh, size)
    boxes = shapely.box(lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1])
    return World(boxes, np.full(count, -np.inf), np.full(count, np.inf), (),
                 shapely.box(0, 0, size, size), "enu", name=f"random-rects-{seed}")


def check_altitude(altitude: float) -> None:
    """An OptionError unless ``altitude`` is a finite number >= 0 (metres above ground),
    worded as :func:`skyroute.world.load.load_world` words it."""
    real("altitude", altitude, low=MIN_ALTITUDE, need=ALTITUDE)


def load_city(path, *, altitude: float, safety: float) -> World:
    """A colliders city in the enu frame with the obstacles that count at ``altitude``.
    An altitude no building reaches is an OptionError naming the file and the tallest
    top: the empty world left would have no extent to plan in; so is a city too large
    for the visibility graph the benchmark builds on it (before any timing)."""
    from skyroute.roadmap.visibility import check_size
    from skyroute.world.load import load_world

    check_altitude(altitude)
    city = load_world(path, safety=safety, frame="enu")
    world = city.at(altitude)
    if len(world.obstacles) == 0:
        raise OptionError(f"altitude={altitude:g}: {no_building_at(city, altitude, safety)}",
                          param="altitude")
    check_size(world)
    return world


def no_building_at(city: World, altitude: float, safety: float) -> str:
    """Why no obstacle of ``city`` (read with ``safety``) counts at ``altitude``: the
    buildings are all lower, or (boxes off the ground) none spans it."""
    top, low = float(city.ceilings.max()) - safety, float(city.floors.min()) + safety
    if altitude >= top + safety:
        grown = f"; {top + safety:g} m with the {safety:g} m safety margin" if safety else ""
        return f"no building of {city.name} reaches {altitude:g} m (the tallest is " \
               f"{top:g} m{grown})"
    return f"no building of {city.name} spans {altitude:g} m (they span {low:g} to {top:g} m)"


def free_pair(world: World, rng: np.random.Generator, min_dist: float) -> tuple:
    """Two free points at least ``min_dist`` apart with a path between them; none in
    1000 draws (the world nearly all obstacle) is a SkyrouteError."""
    from skyroute.planner import plan

    xmin, ymin, xmax, ymax = world.bounds
    for _ in range(1000):
        p = rng.uniform([xmin, ymin], [xmax, ymax], size=(2, 2))
        if world.is_free(p).all() and math.dist(*p) >= min_dist and \
                plan(world, p[0], p[1]).found:
            return p[0], p[1]
    raise SkyrouteError(f"{world.where}: no two free points {min_dist:g} apart with a path "
                        "between them in 1000 draws")


def path_exactly_free(world: World, path: np.ndarray) -> bool:
    """Every segment of ``path`` free under the exact test."""
    p = np.asarray(path)
    return bool(len(p) >= 2 and world.segments_free(p[:-1], p[1:]).all())


def ompl_available() -> bool:
    import importlib.util

    return importlib.util.find_spec("ompl") is not None


def run_ompl(world: World, start, goal, planner: str, seconds: float) -> dict:
    """One OMPL solve: raw and simplified lengths, exact validity of both, the solve's
    time (``seconds``) and ``simplifySolution()``'s (``simplify_seconds``)."""
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    ou.setLogLevel(ou.LOG_NONE)
    space = ob.RealVectorStateSpace(2)
    space.setBounds(ompl_bounds(ob, world))
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(ompl_checker(world))
    s, g = space.allocState(), space.allocState()
    s[0], s[1] = float(start[0]), float(start[1])
    g[0], g[1] = float(goal[0]), float(goal[1])
    ss.setStartAndGoalStates(s, g)
    si = ss.getSpaceInformation()
    ss.setPlanner(getattr(og, planner)(si))
    t0 = time.perf_counter()
    solved = ss.solve(seconds)
    seconds = time.perf_counter() - t0
    out = {"runner": f"ompl {planner}", "seconds": seconds, "exact": str(solved) ==
           "Exact solution"}
    if not out["exact"]:
        return {**out, "raw": None, "simplified": None, "valid": None,
                "simplify_seconds": None}
    path = ss.getSolutionPath()
    raw = path.length()
    raw_pts = np.array([(path.getState(i)[0], path.getState(i)[1])
                        for i in range(path.getStateCount())])
    t0 = time.perf_counter()
    ss.simplifySolution()
    out["simplify_seconds"] = time.perf_counter() - t0
    path = ss.getSolutionPath()
    pts = np.array([(path.getState(i)[0], path.getState(i)[1])
                    for i in range(path.getStateCount())])
    return {**out, "raw": raw, "simplified": path.length(),
            "valid": path_exactly_free(world, pts),
            "raw_valid": path_exactly_free(world, raw_pts)}


def ompl_rows(run: dict) -> list[dict]:
    """:func:`run_ompl`'s result as table rows, each time beside the path it made: the
    solve (raw path) and, when solved, "<runner>, simplified", timed as solve plus
    ``simplifySolution()`` (as "prm, shortcut" times our search and shortcutting)."""
    solve = {"runner": run["runner"], "seconds": run["seconds"], "exact": run["exact"],
             "raw": run["raw"], "valid": run.get("raw_valid")}
    if run["simplified"] is None:
        return [solve]
    return [solve, {"runner": f"{run['runner']}, simplified",
                    "seconds": run["seconds"] + run["simplify_seconds"],
                    "simplify_seconds": run["simplify_seconds"],
                    "simplified": run["simplified"], "valid": run["valid"]}]


def run_ours(world: World, start, goal, other: tuple | None = None) -> list[dict]:
    """skyroute's planners on one query (fresh caches: the build is timed); ``other``, a
    second query timed on the graph the first one built."""
    from skyroute.planner import plan
    from skyroute.roadmap.world_plan import visibility_graph

    fresh = World(world.obstacles, world.floors, world.ceilings, world.names,
                  world.boundary, world.frame, world.home, world.name, world.source)
    rows = []
    t0 = time.perf_counter()
    visibility_graph(fresh, cache=False)  # built here, not read from the disk cache
    r = plan(fresh, start, goal)
    rows.append({"runner": "visibility (1st, with build)",
                 "seconds": time.perf_counter() - t0, "length": r.cost,
                 "valid": path_exactly_free(world, r.path)})
    t0 = time.perf_counter()
    r = plan(fresh, start, goal)
    rows.append({"runner": "visibility (again)",
                 "seconds": time.perf_counter() - t0, "length": r.cost,
                 "valid": path_exactly_free(world, r.path)})
    if other is not None:
        t0 = time.perf_counter()
        r2 = plan(fresh, *other)
        rows.append({"runner": "visibility (other query)",
                     "seconds": time.perf_counter() - t0, "length": None,
                     "valid": path_exactly_free(world, r2.path) if r2.found else None})
    for label, kw in (("prm, shortcut", {"algorithm": "prm"}),
                      ("theta* on raster", {"algorithm": "theta"})):
        t0 = time.perf_counter()
        r = plan(fresh, start, goal, **kw)
        rows.append({"runner": label, "seconds": time.perf_counter() - t0,
                     "length": r.cost if r.found else None,
                     "valid": path_exactly_free(world, r.path) if r.found else None})
    return rows


def bench_query(world: World, start, goal, *, seconds: float, planners: tuple,
                rrt_budgets: tuple, other: tuple | None = None,
                on_step: Callable[[], None] | None = None) -> dict:
    """All runners on one query; lengths relative to the visibility optimum."""
    rows = run_ours(world, start, goal, other)
    optimum = rows[1]["length"]
    if ompl_available():
        for planner in planners:
            rows += ompl_rows(run_ompl(world, start, goal, planner, seconds))
            if on_step:
                on_step()
        reached = None
        for b in rrt_budgets:
            r = run_ompl(world, start, goal, "RRTstar", b)
            if r["raw"] is not None and r["raw"] <= 1.01 * optimum:
                reached = b
                break
    for row in rows:
        for k in ("length", "raw", "simplified"):
            if row.get(k) is not None:
                row[k + "_ratio"] = row[k] / optimum
    return {"world": world.name, "start": list(map(float, start)),
            "goal": list(map(float, goal)), "optimum": optimum, "rows": rows,
            "rrtstar_budget_within_1pct": reached if ompl_available() else None}


def random_free_pair(world: World, rng: np.random.Generator, min_dist: float) -> tuple:
    """Two free points drawn uniformly over the world's extent, at least ``min_dist``
    apart (whether a path joins them is not checked)."""
    xmin, ymin, xmax, ymax = world.bounds
    for _ in range(100_000):
        p = rng.uniform([xmin, ymin], [xmax, ymax], size=(2, 2))
        if math.dist(*p) >= min_dist and world.is_free(p).all():
            return p[0], p[1]
    raise SkyrouteError(f"{world.where}: no two free points {min_dist:g} apart in 100,000 "
                        "draws")


def city_queries(world: World, count: int, rng: np.random.Generator, *,
                 no_path: int = 5, far: float = 0.6) -> dict:
    """Plan once, query many on ``world`` (a city): the visibility graph built without
    the disk cache (``build_seconds``), built again from the disk cache
    (``cached_build_seconds``), the first query on the fresh graph (``first_seconds``),
    then ``count`` random far pairs (free points at least ``far`` x the longer side of
    the extent apart; median, 95th percentile, worst), and ``no_path`` pairs that lie
    in different free regions (drawn at any distance until that many answer no path)."""
    from skyroute.roadmap.visibility import VisibilityGraph

    t0 = time.perf_counter()
    graph = VisibilityGraph(world, cache=False)
    build = time.perf_counter() - t0
    xmin, ymin, xmax, ymax = world.bounds
    min_dist = far * max(xmax - xmin, ymax - ymin)
    pairs = [random_free_pair(world, rng, min_dist) for _ in range(count + 1)]
    t0 = time.perf_counter()
    graph.plan(*pairs[0])
    first = time.perf_counter() - t0
    times, found = [], 0
    for s, g in pairs[1:]:
        t0 = time.perf_counter()
        r = graph.plan(s, g)
        times.append(time.perf_counter() - t0)
        found += r.found
    VisibilityGraph(world, cache=True)  # writes the cache file (when not there yet)
    t0 = time.perf_counter()
    VisibilityGraph(world, cache=True)
    cached = time.perf_counter() - t0
    none, tries = [], 0
    while len(none) < no_path and tries < 200 * max(no_path, 1):
        tries += 1
        s, g = random_free_pair(world, rng, 0.0)
        t0 = time.perf_counter()
        r = graph.plan(s, g)
        dt = time.perf_counter() - t0
        if r.status.value == "no_path":
            none.append(dt)
    t = np.array(times) * 1e3
    n = np.array(none) * 1e3
    return {"build_seconds": build, "cached_build_seconds": cached, "first_seconds": first,
            "first_with_build_seconds": build + first, "queries": count, "found": found,
            "min_dist": min_dist, "median_ms": float(np.median(t)),
            "p95_ms": float(np.percentile(t, 95)), "max_ms": float(t.max()),
            "no_path_pairs": len(n), "no_path_median_ms": float(np.median(n)) if len(n)
            else None, "no_path_max_ms": float(n.max()) if len(n) else None,
            "corners": len(graph.corners)}


def boundary_is_bounds(world: World) -> bool:
    """The world's boundary is exactly its bounds rectangle (which OMPL's state space is
    given), so a state sampled or interpolated on a straight line inside those bounds is
    inside the boundary too."""
    return world.boundary is not None and \
        shapely.Polygon(world.boundary).equals(shapely.box(*world.bounds))


def ompl_checker(world: World) -> Callable[[object], bool]:
    """OMPL's state validity callback for a ``RealVectorStateSpace(2)`` over
    :func:`ompl_bounds`: outside every obstacle (the prepared union) and inside the
    boundary. It runs inside OMPL's timed solve, so the boundary test is left out when
    :func:`boundary_is_bounds`: OMPL samples and interpolates (straight lines) only inside
    its bounds. Only a state exactly on their edge then passes, and every returned path
    is re-checked with the exact segment test."""
    union = shapely.unary_union(world.obstacles)
    shapely.prepare(union)
    if world.boundary is None or boundary_is_bounds(world):
        def valid(state) -> bool:
            return not shapely.contains_xy(union, state[0], state[1])
        return valid
    inside = shapely.Polygon(world.boundary)
    shapely.prepare(inside)

    def valid_inside(state) -> bool:
        x, y = state[0], state[1]
        return bool(shapely.contains_xy(inside, x, y)) and \
            not shapely.contains_xy(union, x, y)
    return valid_inside


def ompl_bounds(ob, world: World):
    """OMPL RealVectorBounds of the world's (x, y) extent (``ob`` is ``ompl.base``)."""
    xmin, ymin, xmax, ymax = world.bounds
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0, xmin)
    bounds.setLow(1, ymin)
    bounds.setHigh(0, xmax)
    bounds.setHigh(1, ymax)
    return bounds
