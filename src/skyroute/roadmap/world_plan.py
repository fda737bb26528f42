"""``plan()`` on a continuous World: the visibility graph, PRM, or any grid algorithm on
the rasterised world. Points come in and paths go out in the world's frame; planners
work on its plane in between. Roadmaps are built once per world and kept.
"""

from __future__ import annotations

import dataclasses
import time
import weakref

import numpy as np

from skyroute.caches import register
from skyroute.errors import OptionError, check_choice
from skyroute.keywords import unknown_keywords
from skyroute.result import PlanResult
from skyroute.roadmap.prm import PRM, prm_options
from skyroute.roadmap.raster import plan_on_raster
from skyroute.roadmap.visibility import VisibilityGraph
from skyroute.search.grid_plan import GRID_ALGORITHMS, grid_options
from skyroute.world.world import World

WORLD_ALGORITHMS = ("visibility", "prm", *GRID_ALGORITHMS)
_ROADMAPS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
register(_ROADMAPS.clear)
_QUERIED: set[str] = set()  # the roadmap kinds this process has queried (kernels loaded)


def _roadmap(world: World, key: tuple, build):
    per_world = _ROADMAPS.setdefault(world, {})
    if key not in per_world:
        per_world[key] = build()
    return per_world[key]


def visibility_graph(world: World, *, cache: bool | None = None) -> VisibilityGraph:
    """The world's visibility graph (built on first use, kept with the world; ``cache``:
    the disk cache's use on that first build, see :class:`VisibilityGraph`)."""
    return _roadmap(world, ("visibility",), lambda: VisibilityGraph(world, cache=cache))


def prm_roadmap(world: World, *, samples: int = 1000, neighbours: int = 10,
                prm_star: bool = False, seed: int = 0) -> PRM:
    """The world's PRM for these options (built on first use, kept with the world)."""
    samples, neighbours, prm_star, seed = prm_options(samples, neighbours, prm_star, seed)
    return _roadmap(world, ("prm", samples, neighbours, prm_star, seed),
                    lambda: PRM(world, samples=samples, neighbours=neighbours,
                                prm_star=prm_star, seed=seed))


PRM_OPTIONS = ("samples", "neighbours", "prm_star", "seed")
GRID_OPTIONS = ("resolution", "connectivity", "corner_cutting", "heuristic", "weight", "prune")


def options_for(algorithm: str, **given) -> dict:
    """The options of ``given`` that ``algorithm`` reads (for callers such as the CLI
    and the service, which fill every option with a default whatever the algorithm)."""
    reads = () if algorithm == "visibility" else PRM_OPTIONS if algorithm == "prm" \
        else GRID_OPTIONS
    return {k: v for k, v in given.items() if k in reads or k not in (*PRM_OPTIONS,
                                                                      *GRID_OPTIONS)}


def plan_world(world: World, start, goal, *, algorithm: str = "visibility",
               max_expansions: int | None = None, **options) -> PlanResult:
    """See :func:`skyroute.plan`: ``start`` and ``goal`` in the world's frame, the path
    in it too (and in lon/lat as ``path_lonlat`` where the world has a home).
    ``options``: PRM's (:data:`PRM_OPTIONS`) or the grid algorithms'
    (:data:`GRID_OPTIONS`); one the algorithm does not read is an OptionError, one that
    no planner reads (a misspelt option) a KeywordError naming the closest."""
    unknown = [name for name in options if name not in (*PRM_OPTIONS, *GRID_OPTIONS)]
    if unknown:
        raise unknown_keywords(plan_world, unknown, ("world", "start", "goal", "algorithm",
                                                     "max_expansions", *PRM_OPTIONS,
                                                     *GRID_OPTIONS))
    check_choice("algorithm", algorithm, WORLD_ALGORITHMS)
    for name, value in options.items():
        if name not in options_for(algorithm, **{name: value}):
            reads = "PRM" if name in PRM_OPTIONS else "the grid algorithms"
            raise OptionError(f"{name}={value!r} does not apply to algorithm={algorithm!r} "
                              f"(it is read by {reads})", param=name)
    s = world.check_point(start, "start")  # errors speak the caller's frame
    t = world.check_point(goal, "goal")
    if algorithm in ("visibility", "prm"):
        res = _on_roadmap(world, algorithm, s, t, max_expansions, options)
    else:
        resolution = options.pop("resolution", None)
        opts = grid_options(algorithm, max_expansions=max_expansions, **options)
        res = plan_on_raster(world, s, t, opts, resolution)
    return in_frame(world, res, start, goal)


def _on_roadmap(world: World, algorithm: str, s: np.ndarray, t: np.ndarray,
                max_expansions: int | None, options: dict) -> PlanResult:
    """A query on the world's visibility graph or PRM. What the first query sets up -
    the roadmap (built, or read from the disk cache) and, once a process, the query's
    compiled kernels (loaded from numba's cache, or compiled) - is timed apart as
    ``extra["setup_seconds"]``, as :func:`~skyroute.search.grid_plan.plan_grid` times a
    grid's, so ``seconds`` is the search alone (a first ``plan-world`` on the FCND city
    reported the kernels' 4 s as its search time, and the graph's build nowhere). A
    later query's is the roadmap's look-up, microseconds: every world result has the
    key, found or not, as on a raster."""
    t0 = time.perf_counter()
    rm = visibility_graph(world) if algorithm == "visibility" else \
        prm_roadmap(world, **options)
    if algorithm not in _QUERIED:  # the process's first: its kernels loaded by a query
        # of one expansion on the graph, not the whole search twice (PRM's scipy
        # Dijkstra takes no budget: its query runs whole)
        rm.plan(s, t, max_expansions=1 if algorithm == "visibility" else max_expansions)
        _QUERIED.add(algorithm)
    setup = time.perf_counter() - t0
    res = rm.plan(s, t, max_expansions=max_expansions)
    return dataclasses.replace(res, extra={**res.extra, "setup_seconds": setup})


def in_frame(world: World, res: PlanResult, start, goal) -> PlanResult:
    """A plane result with its path in the world's frame, its ends exactly the caller's
    ``start`` and ``goal``, and, where the world has a home (or is in degrees), the path
    in lon/lat too."""
    path = world.from_plane(res.path)
    lonlat = world.plane_to_lonlat(res.path) if world.has_lonlat else None
    if len(path):
        path[0], path[-1] = np.ravel(start).astype(float), np.ravel(goal).astype(float)
        if lonlat is not None:
            lonlat[0], lonlat[-1] = world.to_lonlat(start)[0], world.to_lonlat(goal)[0]
    extra = {**res.extra, "frame": world.frame}
    return dataclasses.replace(res, path=path, path_lonlat=lonlat, extra=extra)


def roadmap_edges(world: World, algorithm: str, *, samples: int = 1000,
                  neighbours: int = 10, prm_star: bool = False,
                  seed: int = 0) -> np.ndarray | None:
    """(E, 2, 2) plane segments of the roadmap a planner has built on ``world`` (for
    plots): the free edges of a visibility graph, or a PRM's edges;
    None when that planner has built nothing on this world."""
    per_world = _ROADMAPS.get(world, {})
    if algorithm == "visibility" and ("visibility",) in per_world:
        return per_world[("visibility",)].edge_segments()
    key = ("prm", samples, neighbours, prm_star, seed)
    if algorithm == "prm" and key in per_world:
        return per_world[key].edge_segments()
    return None
