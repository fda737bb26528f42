"""Grid planners on a continuous World: rasterise its plane, search the grid, map the
cells back and shortcut them exactly.

The raster has a clearance of half a cell's diagonal (r / sqrt 2): every point of a free
cell is then outside every obstacle's interior, so each grid move and each Theta* segment
is free in the exact world too. The cell path is mapped back to plane coordinates,
joined to the exact start and goal, and shortcut greedily by the exact segment test,
which never lengthens it. Rasters are built once per (world, resolution, extent).
"""

from __future__ import annotations

import math
import time
import weakref

import numpy as np

from skyroute.caches import register
from skyroute.errors import OptionError, QueryError, real
from skyroute.result import PlanResult, Status
from skyroute.roadmap.simplify import shortcut
from skyroute.search.grid_plan import plan_grid
from skyroute.world.grid import Grid
from skyroute.world.points import MAX_METRES
from skyroute.world.world import World

_RASTERS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
register(_RASTERS.clear)


def default_resolution(world: World, points=()) -> float:
    """About 1000 cells along the longer side of the world's extent holding ``points``
    (the plane points a query must reach)."""
    xmin, ymin, xmax, ymax = world.extent_with(points) if len(points) else world.bounds
    return max(xmax - xmin, ymax - ymin) / 1000.0


def raster_box(world: World, s, t, r: float) -> tuple[float, float, float, float]:
    """The plane box a raster of cell size ``r`` covers: the world's boundary, or, in an
    unbounded world, its obstacles and plane points ``s`` and ``t`` with 4 cells round
    them all (without them, obstacles that span the extent had no way round)."""
    box = world.extent_with([s, t], margin=4 * r)
    if world.boundary is None:
        box = (box[0] - 4 * r, box[1] - 4 * r, box[2] + 4 * r, box[3] + 4 * r)
    return box


def check_reach(world: World, box, r: float) -> None:
    """An OptionError naming ``resolution`` when a raster of cell size ``r`` over plane
    ``box`` reaches past a local plane's :data:`~skyroute.world.points.MAX_METRES` from
    home: its cells' centres, a path's corners, would be no points of the world (a path
    "more than 1e+07 m from home", or far-off lon/lat, came back instead)."""
    if world.plane != "metres":
        return
    reach = max(abs(v) for v in box)
    if reach > MAX_METRES:
        raise OptionError(f"resolution={r:g} makes a raster reaching {reach:.3g} m from "
                          f"home, past the {MAX_METRES:.0e} m of this world's local "
                          "plane (it grows 8 cells round the obstacles and points); use "
                          "a finer resolution", param="resolution")


def world_raster(world: World, s: np.ndarray, t: np.ndarray,
                 resolution: float | None) -> Grid:
    """The world's plane rasterised with a half-diagonal clearance, holding plane points
    ``s`` and ``t`` (built once per world, resolution and extent)."""
    if resolution is None:
        r = default_resolution(world, [s, t])
    else:
        r = real("resolution", resolution)
        if r <= 0:
            raise OptionError(f"resolution={resolution!r} must be a positive number",
                              param="resolution")
    box = raster_box(world, s, t, r)
    if resolution is not None:
        check_reach(world, box, r)
    per_world = _RASTERS.setdefault(world, {})
    key = (r, box)
    if key not in per_world:
        per_world[key] = world.merged().rasterize(r, safety=r / math.sqrt(2) * 1.0001,
                                                  bounds=box)
    return per_world[key]


def plan_on_raster(world: World, s: np.ndarray, t: np.ndarray, opts,
                   resolution: float | None) -> PlanResult:
    """A grid planner (validated ``opts``) between free plane points; plane path."""
    t0 = time.perf_counter()
    grid = world_raster(world, s, t, resolution)
    setup = time.perf_counter() - t0
    r = grid.resolution
    cs, ct = entry_cell(world, grid, s, "start"), entry_cell(world, grid, t, "goal")
    res = plan_grid(grid, cs, ct, opts)
    t1 = time.perf_counter()
    if not res.found:
        return PlanResult(res.status, np.empty((0, 2)), math.inf, res.expanded,
                          res.max_frontier, res.los_checks, res.seconds, opts.algorithm,
                          {"resolution": r, "setup_seconds": setup})
    pts = np.vstack([s, grid.to_world(res.path), t])
    pts, checks = shortcut(world, pts)
    if np.array_equal(s, t):  # one point, as the grid planners return for start == goal
        pts = pts[:1]
    cost = float(np.hypot(*np.diff(pts, axis=0).T).sum())
    seconds = res.seconds + time.perf_counter() - t1
    return PlanResult(Status.FOUND, pts, cost, res.expanded, res.max_frontier,
                      res.los_checks + checks, seconds, opts.algorithm,
                      {"resolution": r, "setup_seconds": setup + res.extra.get(
                          "setup_seconds", 0.0)})


def entry_cell(world: World, grid: Grid, p: np.ndarray, what: str) -> tuple[int, int]:
    """The free cell whose centre plane point p can reach in a straight line, nearest
    first; a QueryError naming ``what`` when none within 3 cells can."""
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
    raise QueryError(f"{what} {world._fmt(p)} is too close to an obstacle for a "
                     f"{grid.resolution:.3g} grid; use a finer resolution or the visibility graph",
                     param=what)
