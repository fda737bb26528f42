"""Plan on a continuous World: the visibility graph, PRM, or any grid algorithm on the
rasterised world. Roadmaps and rasters are built once per world and kept.

Grid planners rasterise with a clearance of half a cell's diagonal (r / sqrt 2): every
point of a free cell is then outside every obstacle's interior, so each grid move and
each Theta* segment is free in the exact world too. The cell path is mapped back to
world coordinates, joined to the exact start and goal, and shortcut greedily by the
exact segment test, which never lengthens it.
"""

from __future__ import annotations

import math
import time
import weakref

import numpy as np

from skyroute.errors import OptionError, QueryError, check_choice
from skyroute.result import PlanResult, Status
from skyroute.search.grid_plan import GRID_ALGORITHMS, grid_options, plan_grid
from skyroute.world.world import World

WORLD_ALGORITHMS = ("visibility", "prm", *GRID_ALGORITHMS)
_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _cached(world: World, key: tuple, build):
    per_world = _CACHE.setdefault(world, {})
    if key not in per_world:
        per_world[key] = build()
    return per_world[key]


def plan_world(world: World, start, goal, *, algorithm: str = "visibility",
               resolution: float | None = None, samples: int = 1000, neighbours: int = 10,
               prm_star: bool = False, seed: int = 0, max_expansions: int | None = None,
               **grid_kwargs) -> PlanResult:
    """See :func:`skyroute.plan`; ``start`` and ``goal`` are world (x, y) points."""
    check_choice("algorithm", algorithm, WORLD_ALGORITHMS)
    world.check_point(start, "start")  # errors name the obstacles as loaded
    world.check_point(goal, "goal")
    if algorithm == "visibility":
        from skyroute.roadmap.visibility import VisibilityGraph

        graph = _cached(world, ("visibility",), lambda: VisibilityGraph(world))
        return graph.plan(start, goal, max_expansions=max_expansions)
    if algorithm == "prm":
        from skyroute.roadmap.prm import PRM

        rm = _cached(world, ("prm", samples, neighbours, prm_star, seed),
                     lambda: PRM(world, samples=samples, neighbours=neighbours,
                                 prm_star=prm_star, rng=np.random.default_rng(seed)))
        return rm.plan(start, goal, max_expansions=max_expansions)
    return _plan_on_raster(world, start, goal, algorithm, resolution, max_expansions,
                           grid_kwargs)


def default_resolution(world: World) -> float:
    """About 1000 cells along the longer side of the world."""
    xmin, ymin, xmax, ymax = world.bounds
    return max(xmax - xmin, ymax - ymin) / 1000.0


def _plan_on_raster(world, start, goal, algorithm, resolution, max_expansions, kwargs):
    s = world.check_point(start, "start")
    t = world.check_point(goal, "goal")
    r = default_resolution(world) if resolution is None else float(resolution)
    if not (math.isfinite(r) and r > 0):
        raise OptionError(f"resolution={resolution!r} must be a positive number")
    opts = grid_options(algorithm, max_expansions=max_expansions, **kwargs)
    t0 = time.perf_counter()
    box = world.extent_with([s, t], margin=4 * r)
    grid = _cached(world, ("raster", r, box),
                   lambda: world.merged().rasterize(r, clearance=r / math.sqrt(2) * 1.0001,
                                                    bounds=box))
    setup = time.perf_counter() - t0
    cs, ct = _entry_cell(world, grid, s, "start"), _entry_cell(world, grid, t, "goal")
    res = plan_grid(grid, cs, ct, opts)
    t1 = time.perf_counter()
    if not res.found:
        return PlanResult(res.status, np.empty((0, 2)), math.inf, res.expanded,
                          res.max_frontier, res.los_checks, res.seconds, algorithm,
                          {"resolution": r, "setup_seconds": setup})
    pts = np.vstack([s, grid.to_world(res.path), t])
    pts, checks = shortcut(world, pts)
    cost = float(np.hypot(*np.diff(pts, axis=0).T).sum())
    seconds = res.seconds + time.perf_counter() - t1
    return PlanResult(Status.FOUND, pts, cost, res.expanded, res.max_frontier,
                      res.los_checks + checks, seconds, algorithm,
                      {"resolution": r, "setup_seconds": setup + res.extra.get(
                          "setup_seconds", 0.0)})


def _entry_cell(world: World, grid, p: np.ndarray, what: str) -> tuple[int, int]:
    """The free cell whose centre p can reach in a straight line, nearest first."""
    c = grid.to_cell([p])[0]
    for radius in range(0, 4):
        xs = np.arange(c[0] - radius, c[0] + radius + 1)
        ys = np.arange(c[1] - radius, c[1] + radius + 1)
        gx, gy = np.meshgrid(xs, ys)
        cells = np.c_[gx.ravel(), gy.ravel()]
        ok = (cells[:, 0] >= 0) & (cells[:, 0] < grid.width) & (cells[:, 1] >= 0) & \
            (cells[:, 1] < grid.height)
        cells = cells[ok]
        cells = cells[~grid.blocked[cells[:, 1], cells[:, 0]]]
        if len(cells):
            centres = grid.to_world(cells)
            order = np.argsort(np.hypot(*(centres - p).T))
            free = world.segments_free(np.broadcast_to(p, (len(cells), 2)), centres[order])
            if free.any():
                return tuple(int(v) for v in cells[order][np.argmax(free)])
    raise QueryError(f"{what} ({p[0]:.6g}, {p[1]:.6g}) is too close to an obstacle for a "
                     f"{grid.cell_size:.3g} grid; use a finer resolution or the visibility graph")


def shortcut(world: World, pts: np.ndarray) -> tuple[np.ndarray, int]:
    """Greedy exact line-of-sight shortcutting: from each kept point jump to the farthest
    later point it sees. Returns (points, segment tests)."""
    keep = [0]
    i = 0
    tests = 0
    while i < len(pts) - 1:
        later = np.arange(len(pts) - 1, i, -1)
        free = world.segments_free(np.broadcast_to(pts[i], (len(later), 2)), pts[later])
        tests += len(later)
        i = int(later[np.argmax(free)]) if free.any() else i + 1
        keep.append(i)
    return pts[keep], tests


def smooth(world: World, pts: np.ndarray, rng: np.random.Generator,
           tries: int = 300) -> tuple[np.ndarray, int]:
    """Random sub-segment shortcuts (as OMPL's path simplifier does): pick two points along
    the path by arc length; when the segment between them is free, splice it in. Never
    longer (triangle inequality), every new segment checked. Returns (points, tests)."""
    tests = 0
    for _ in range(tries):
        if len(pts) < 3:
            break
        seg = np.hypot(*np.diff(pts, axis=0).T)
        cum = np.concatenate([[0.0], np.cumsum(seg)])
        a, b = np.sort(rng.uniform(0, cum[-1], size=2))
        i, j = np.searchsorted(cum, [a, b], side="right") - 1
        if i == j:
            continue
        pa = pts[i] + (pts[i + 1] - pts[i]) * ((a - cum[i]) / seg[i])
        pb = pts[j] + (pts[j + 1] - pts[j]) * ((b - cum[j]) / seg[j])
        tests += 1
        if world.segment_free(pa, pb):
            pts = np.vstack([pts[: i + 1], pa, pb, pts[j + 1:]])
    keep = np.r_[True, np.any(np.diff(pts, axis=0) != 0, axis=1)]
    return pts[keep], tests


def roadmap_edges(world: World, algorithm: str, *, samples: int = 1000,
                  neighbours: int = 10, prm_star: bool = False, seed: int = 0):
    """(E, 2, 2) segments of the roadmap a planner built on ``world`` (for plots): the
    edges a visibility graph has checked and found free, or a PRM's edges; None else."""
    per_world = _CACHE.get(world, {})
    if algorithm == "visibility" and ("visibility",) in per_world:
        g = per_world[("visibility",)]
        pairs = np.array([k for k, ok in g._verdicts.items() if ok], dtype=np.int64)
        return g.corners[pairs] if len(pairs) else None
    key = ("prm", samples, neighbours, prm_star, seed)
    if algorithm == "prm" and key in per_world:
        rm = per_world[key]
        return rm.points[rm.edges]
    return None
