"""``plan()`` on a continuous World: the visibility graph, PRM, or any grid algorithm on
the rasterised world. Points come in and paths go out in the world's frame; planners
work on its plane in between. Roadmaps are built once per world and kept.
"""

from __future__ import annotations

import dataclasses
import weakref

import numpy as np

from skyroute.caches import register
from skyroute.errors import check_choice
from skyroute.result import PlanResult
from skyroute.roadmap.prm import PRM
from skyroute.roadmap.raster import plan_on_raster
from skyroute.roadmap.visibility import VisibilityGraph
from skyroute.search.grid_plan import GRID_ALGORITHMS, grid_options
from skyroute.world.world import World

WORLD_ALGORITHMS = ("visibility", "prm", *GRID_ALGORITHMS)
_ROADMAPS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
register(_ROADMAPS.clear)


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
    return _roadmap(world, ("prm", samples, neighbours, prm_star, seed),
                    lambda: PRM(world, samples=samples, neighbours=neighbours,
                                prm_star=prm_star, seed=seed))


def plan_world(world: World, start, goal, *, algorithm: str = "visibility",
               resolution: float | None = None, samples: int = 1000, neighbours: int = 10,
               prm_star: bool = False, seed: int = 0, max_expansions: int | None = None,
               **grid_kwargs) -> PlanResult:
    """See :func:`skyroute.plan`: ``start`` and ``goal`` in the world's frame, the path
    in it too (and in lon/lat as ``path_lonlat`` where the world has a home)."""
    check_choice("algorithm", algorithm, WORLD_ALGORITHMS)
    s = world.check_point(start, "start")  # errors speak the caller's frame
    t = world.check_point(goal, "goal")
    if algorithm == "visibility":
        res = visibility_graph(world).plan(s, t, max_expansions=max_expansions)
    elif algorithm == "prm":
        rm = prm_roadmap(world, samples=samples, neighbours=neighbours, prm_star=prm_star,
                         seed=seed)
        res = rm.plan(s, t, max_expansions=max_expansions)
    else:
        opts = grid_options(algorithm, max_expansions=max_expansions, **grid_kwargs)
        res = plan_on_raster(world, s, t, opts, resolution)
    return in_frame(world, res, start, goal)


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
