"""Plan on a Grid: validate the query and options, run a compiled kernel, build the result."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from skyroute.caches import register
from skyroute.errors import OptionError, budget, check_choice, real
from skyroute.result import STATUS_OF_CODE, PlanResult
from skyroute.search import heap
from skyroute.search.astar import astar_kernel
from skyroute.search.bfs import bfs_kernel
from skyroute.search.canonical import CANONICAL, EVERY
from skyroute.search.entry_points import entry_point
from skyroute.search.jps import NO_PIVOTS, jps_kernel
from skyroute.search.moves import HEURISTICS
from skyroute.search.prune import PRUNE_MODES, prune_collinear, prune_los
from skyroute.search.space import SearchSpace, space_of
from skyroute.search.theta import theta_kernel
from skyroute.search.trace import to_cells
from skyroute.world.grid import Grid

GRID_ALGORITHMS = ("bfs", "dijkstra", "astar", "jps", "theta", "lazy_theta")
ANY_ANGLE = ("theta", "lazy_theta")


@dataclass(frozen=True)
class GridOptions:
    """Validated search options (see :func:`plan_grid`)."""

    algorithm: str
    connectivity: int
    corner_cutting: bool
    heuristic: str
    weight: float
    prune: str
    max_expansions: int


def grid_options(algorithm: str = "astar", *, connectivity: int | None = None,
                 corner_cutting: bool = False, heuristic: str | None = None,
                 weight: float = 1.0, prune: str | None = None,
                 max_expansions: int | None = None) -> GridOptions:
    """Check every option and fill in the algorithm's defaults; raise OptionError."""
    try:
        return _grid_options(algorithm, connectivity, corner_cutting, heuristic, weight, prune,
                             max_expansions)
    except TypeError:  # unhashable values: validate uncached for the error message
        return _grid_options.__wrapped__(algorithm, connectivity, corner_cutting, heuristic,
                                         weight, prune, max_expansions)


@lru_cache(maxsize=256, typed=True)  # typed: 5.0 and True must not pass as 5 and 1
def _grid_options(algorithm, connectivity, corner_cutting, heuristic, weight, prune,
                  max_expansions) -> GridOptions:
    check_choice("algorithm", algorithm, GRID_ALGORITHMS)
    if connectivity is None:
        connectivity = 4 if algorithm == "bfs" else 8
    check_choice("connectivity", connectivity, (4, 8))
    check_choice("corner_cutting", corner_cutting, (False, True))
    if algorithm == "bfs" and connectivity != 4:
        raise OptionError("algorithm='bfs' is 4-connected; use connectivity=4 or "
                          "algorithm='dijkstra' for 8-connected unit costs",
                          param=("connectivity", "algorithm"))
    if connectivity == 4 and corner_cutting:  # read by no search: refused, not ignored
        if algorithm == "bfs":
            raise OptionError("algorithm='bfs' is 4-connected, so it has no corners to cut; "
                              "drop corner cutting", param=("corner_cutting", "algorithm"))
        raise OptionError("connectivity=4 has no diagonal steps, so no corners to cut; "
                          "drop corner cutting or use connectivity=8",
                          param=("corner_cutting", "connectivity"))
    if algorithm == "jps" and (connectivity != 8 or corner_cutting):
        # the parameters named in the message too: the CLI speaks of them as its flags
        raise OptionError("algorithm='jps' needs connectivity=8 and no corner cutting",
                          param=("connectivity", "algorithm") if connectivity != 8 else
                          ("corner_cutting", "algorithm", "connectivity"))
    if heuristic is None:
        heuristic = _default_h(algorithm, connectivity)
    check_choice("heuristic", heuristic, tuple(HEURISTICS))
    if algorithm in ("bfs", "dijkstra", "jps") and heuristic != _default_h(algorithm,
                                                                             connectivity):
        raise OptionError(f"algorithm={algorithm!r} takes no heuristic option "
                          f"(it uses {_default_h(algorithm, connectivity)!r})",
                          param=("heuristic", "algorithm"))
    weight = real("weight", weight, low=1.0, need="a number >= 1")  # numpy's too; no bool
    if weight != 1.0 and algorithm in ("bfs", "dijkstra", "jps"):
        raise OptionError(f"algorithm={algorithm!r} takes no weight; use algorithm='astar'",
                          param=("weight", "algorithm"))
    prune = "none" if prune is None else prune
    check_choice("prune", prune, PRUNE_MODES)
    return canonical(GridOptions(algorithm, int(connectivity), bool(corner_cutting),
                                 heuristic, weight, prune, budget(max_expansions)))


_CANONICAL: dict[GridOptions, GridOptions] = {}  # one object per distinct option set
register(_CANONICAL.clear)  # cleared, equal sets still agree: the next one seen stands


def canonical(opts: GridOptions) -> GridOptions:
    """The one object standing for every option set equal to ``opts``: a grid keeps its
    query calls by that object's id, so equal sets share one (after the option cache
    evicted a set, or for a set unpickled or made by hand)."""
    return _CANONICAL.setdefault(opts, opts)


def _default_h(algorithm: str, connectivity: int) -> str:
    if algorithm in ANY_ANGLE:
        return "euclidean"
    if algorithm == "dijkstra":
        return "zero"
    if algorithm == "bfs":
        return "manhattan"
    return "octile" if connectivity == 8 else "manhattan"


def plan_grid(grid: Grid, start: tuple[int, int], goal: tuple[int, int],
              opts: GridOptions) -> PlanResult:
    """Run one validated query; see :func:`skyroute.plan` for the contract.

    ``seconds`` times the search alone. What the first query on a grid (or in a process)
    builds or loads - move masks, JPS's jump table, the workspace, compiled kernels from
    numba's cache - is timed apart and reported as ``extra["setup_seconds"]``.
    """
    space = space_of(grid)
    s, t = space.flat_pair(start, goal)
    entry = space.runners.get(id(opts))  # by id: GridOptions.__hash__ is a Python call
    if entry is None:  # not the canonical object? (its id is the key when it is)
        opts = canonical(opts)
        entry = space.runners.get(id(opts))
    extra = {}
    if entry is not None:
        run = entry[1]
    else:
        t_setup = time.perf_counter()
        run = _runner(space, opts)
        path = run(s, s)[4]  # start == start: loads, builds, warms
        if opts.prune != "none":
            _pruned(space, path, 0, opts.prune)  # and the pruning kernels
        space.runners[id(opts)] = (opts, run)
        extra["setup_seconds"] = time.perf_counter() - t_setup
    t0 = time.perf_counter()
    code, expanded, frontier, los, path, cost = run(s, t)
    seconds = time.perf_counter() - t0
    if code == 0 and opts.prune != "none":
        path, cost, los = _pruned(space, path, los, opts.prune)
    return PlanResult.of_search(STATUS_OF_CODE[code], path, cost, expanded, frontier, los,
                                seconds, opts.algorithm, extra)


def _pruned(space: SearchSpace, path: np.ndarray, los: int, prune: str):
    """(path, cost, los_checks) of a found path pruned as ``prune`` asks (the kernels
    return every cell; pruning works on their flat indices)."""
    flat = ((path[:, 1] + 1) * space.Wp + path[:, 0] + 1).astype(np.int64)
    flat = prune_collinear(flat, space.Wp)
    if prune == "los":
        flat, checks = prune_los(space.blocked, space.Wp, flat)
        los += checks
    path, cost = to_cells(flat, space.Wp)
    return path, cost, los


def _runner(space: SearchSpace, o: GridOptions):
    """``run(s, t) -> (code, expanded, max_frontier, los_checks, path, length)`` for one
    option set on one grid: its kernel's compiled entry with every argument but the two
    cells bound, so a query pays neither the dispatcher's typing of a dozen arguments
    nor the choice of kernel."""
    blk, Wp = space.blocked, space.Wp
    fs = _f_scale(space, o.weight) if o.algorithm != "bfs" else 0.0
    floats, ints, keys = space.workspace()
    if o.algorithm == "bfs":
        call = entry_point(bfs_kernel, blk, Wp, 0, 0, o.max_expansions, floats, ints)

        def run(s, t):
            code, exp, front, path, length = call(blk, Wp, s, t, o.max_expansions, floats,
                                                  ints)
            return code, exp, front, 0, path, length
        return run
    if o.algorithm == "jps":
        args = (space.move_mask(8, False), CANONICAL, space.jump_table(), Wp)
        tail = (o.max_expansions, floats, ints, keys, NO_PIVOTS, fs)
        call = entry_point(jps_kernel, *args, 0, 0, *tail)

        def run(s, t):
            code, exp, front, path, length = call(*args, s, t, *tail)
            return code, exp, front, 0, path, length
        return run
    mask = space.move_mask(o.connectivity, o.corner_cutting)
    hkind = HEURISTICS[o.heuristic]
    if o.algorithm in ANY_ANGLE:
        tail = (hkind, o.weight, o.max_expansions, o.algorithm == "lazy_theta", floats,
                ints, keys, fs)
        call = entry_point(theta_kernel, blk, mask, Wp, 0, 0, *tail)
        return lambda s, t: call(blk, mask, Wp, s, t, *tail)
    succ = CANONICAL if o.connectivity == 8 and not o.corner_cutting else EVERY
    tail = (hkind, o.weight, o.max_expansions, floats, ints, keys, fs)
    call = entry_point(astar_kernel, mask, succ, Wp, 0, 0, *tail)

    def run(s, t):
        code, exp, front, path, length = call(mask, succ, Wp, s, t, *tail)
        return code, exp, front, 0, path, length
    return run


def _f_scale(space: SearchSpace, weight: float) -> float:
    """The heap keys' unit of f for a search with ``weight`` on ``space``
    (:meth:`SearchSpace.f_scale`); an OptionError naming weight when its keys could not
    hold every f (a weight no search needs: above about 5e8 on the largest grids)."""
    fs = space.f_scale(weight)
    if fs > 0.0:
        return fs
    top = space.f_bound(0.0)
    span = float(space.width + space.height)
    most = math.floor((2.0 ** heap.F_BITS - 1.0 - top) / span)  # f in units of 1
    while space.f_scale(most) == 0.0:  # float rounding: step down to a weight that fits
        most = math.floor(most * (1.0 - 1e-12)) - 1
    raise OptionError(f"weight={weight:g} is too large for this {space.width}x{space.height} "
                      f"grid: its search keys would overflow; use a weight from 1 to "
                      f"{most:,}", param="weight")
