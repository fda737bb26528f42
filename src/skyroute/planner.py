"""``plan()``: the one call that covers the common case."""

from __future__ import annotations

from typing import TYPE_CHECKING

from skyroute.errors import OptionError
from skyroute.keywords import strict_keywords, unknown_keywords
from skyroute.result import PlanResult
from skyroute.search.grid_plan import _grid_options, grid_options, plan_grid
from skyroute.world.grid import Grid

if TYPE_CHECKING:
    from skyroute.world.world import World


@strict_keywords
def plan(grid: Grid | World, start, goal, *, algorithm: str | None = None,
         connectivity: int | None = None, corner_cutting: bool = False,
         heuristic: str | None = None, weight: float | None = None, prune: str | None = None,
         max_expansions: int | None = None, resolution: float | None = None,
         samples: int | None = None, neighbours: int | None = None,
         prm_star: bool | None = None, seed: int | None = None, **misspelt) -> PlanResult:
    """Plan a path on a Grid from cell ``start`` to cell ``goal``, both (x, y) = (column,
    row), or on a World between two points given in the world's frame.

    On a World (see :func:`skyroute.load_world`), ``start`` and ``goal`` are read in the
    frame the world was loaded in ((lon, lat) for "lonlat" and "degrees", (north, east)
    for "ned", (east, north) for "enu"), and ``path`` comes back in it, with
    ``path_lonlat`` beside it where the world has a home. ``algorithm`` is "visibility"
    (the default: the exact shortest path), "prm" (``samples``, ``neighbours``,
    ``prm_star``, ``seed``; the same seed gives the same path), or any grid algorithm on
    the world rasterised at ``resolution`` (default: 1000 cells along the longer side);
    the cost is in plane units (metres; degrees in the degrees frame).

    Parameters
    ----------
    algorithm : {"astar", "dijkstra", "bfs", "jps", "theta", "lazy_theta"}
        ``bfs`` is 4-connected with unit steps; ``jps`` is 8-connected without corner
        cutting; ``theta`` and ``lazy_theta`` return any-angle paths.
    connectivity : {4, 8}, optional
        Default 8 (4 for ``bfs``).
    corner_cutting : bool
        False (MovingAI's rule): a diagonal step needs both side cells free. True: one
        free side suffices; squeezing between two diagonal blocked cells is never legal.
        8-connected only (not ``jps``).
    heuristic : {"octile", "euclidean", "manhattan", "zero"}, optional
        Default octile (8-connected), Manhattan (4-connected), Euclidean (any-angle).
        Manhattan is admissible only 4-connected: with diagonal or any-angle steps
        the path may be longer than the optimum.
    weight : float, optional
        >= 1 (default 1); weighted A* returns a cost at most ``weight`` x the optimum.
    prune : {"none", "collinear", "los"}, optional
        Drop straight-on points, or also shortcut by line of sight. Never illegal or longer.
    max_expansions : int, optional
        Stop with status ``budget_exhausted`` after this many expansions. None: enough to
        finish the search, with no cap (the grid's cells or the roadmap's nodes bound it).
    resolution : float, optional
        A World planned by a grid algorithm: the cell size in plane units.
    samples, neighbours, prm_star, seed : optional
        A World planned by "prm": 1000 samples, 10 neighbours (or k-PRM*'s), seed 0.

    An option that the chosen planner does not read (``seed`` on a Grid, ``heuristic``
    with "visibility", ``resolution`` with "prm", ...) is an OptionError, not ignored.

    Returns
    -------
    PlanResult
        ``status`` found / no_path / budget_exhausted; ``path`` (K, 2) cells; ``cost``.

    Raises
    ------
    QueryError
        start or goal outside the grid or on a blocked cell (or outside the World or
        inside an obstacle), or not two numbers (two integers on a Grid).
    OptionError
        an unknown, out-of-range or inapplicable option (the message lists the valid
        ones), or ``grid`` not a Grid or World; a misspelt keyword (``algoritm=``) is
        its child KeywordError (a TypeError too), naming the closest valid one.

    Examples
    --------
    >>> import skyroute
    >>> grid = skyroute.load_map("den312d")
    >>> r = skyroute.plan(grid, (50, 76), (60, 13))  # den312d.map.scen: 112.55634918
    >>> r.status.value, round(r.cost, 8), len(r.path)
    ('found', 112.55634919, 109)
    >>> skyroute.plan(grid, (50, 76), (60, 13), algorithm="theta").cost < r.cost
    True
    """
    if misspelt:
        raise unknown_keywords(plan, misspelt)
    if not isinstance(grid, Grid):
        # shapely and the roadmaps are imported only here: a grid plan never loads them
        from skyroute.roadmap.world_plan import plan_world
        from skyroute.world.world import World

        if not isinstance(grid, World):
            raise OptionError(f"grid must be a skyroute Grid or World, got "
                              f"{type(grid).__name__}{_hint(grid)}", param="grid")
        extra = {k: v for k, v in (("connectivity", connectivity), ("heuristic", heuristic),
                                   ("prune", prune), ("resolution", resolution))
                 if v is not None}
        if corner_cutting is not False:
            extra["corner_cutting"] = corner_cutting
        if weight is not None:
            extra["weight"] = weight
        roadmap = {k: v for k, v in (("samples", samples), ("neighbours", neighbours),
                                     ("prm_star", prm_star), ("seed", seed)) if v is not None}
        return plan_world(grid, start, goal, algorithm=algorithm or "visibility",
                          max_expansions=max_expansions, **roadmap, **extra)
    if resolution is not None or samples is not None or neighbours is not None or \
            prm_star is not None or seed is not None:  # chained: the grid path is hot
        name, value = next((n, v) for n, v in (
            ("resolution", resolution), ("samples", samples), ("neighbours", neighbours),
            ("prm_star", prm_star), ("seed", seed)) if v is not None)
        raise OptionError(f"{name}={value!r} applies to planning on a World "
                              f"(a grid is searched as it is)", param=name)
    weight = 1.0 if weight is None else weight
    try:  # the cached option set straight away: on a 32x32 map a query takes 9 us
        opts = _grid_options(algorithm or "astar", connectivity, corner_cutting, heuristic,
                             weight, prune, max_expansions)
    except TypeError:  # an unhashable option: validated uncached, for its message
        opts = grid_options(algorithm or "astar", connectivity=connectivity,
                            corner_cutting=corner_cutting, heuristic=heuristic,
                            weight=weight, prune=prune, max_expansions=max_expansions)
    return plan_grid(grid, start, goal, opts)


def _hint(grid: object) -> str:
    """What to do instead, for a ``grid`` that is no Grid or World: wrap an array, or ask
    a prepared index itself."""
    if hasattr(grid, "shape") or isinstance(grid, list | tuple):
        return "; wrap an array of blocked cells as skyroute.Grid(array)"
    if type(grid).__name__ == "PreparedGrid":  # not imported: the grid path stays light
        return "; ask the index itself: index.plan(start, goal)"
    return ""
