"""Turn-aware planning: time, not distance, on a (cell, heading) lattice.

A vehicle at a cell faces one of 8 or 16 headings. It may drive forward to the next
cell along its heading (cost distance / speed; 8 headings: the 8 neighbours, no corner
cutting; 16: also the knight moves (2, 1), legal by exact line of sight) or turn in
place to a neighbouring heading (cost angle / turn_rate). A* with the heuristic
(straight-line distance) / speed finds the fastest route; :func:`travel_time` prices any
cell path under the same model, so a distance-optimal path can be compared fairly.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np
from numba import njit

from skyroute.errors import OptionError, budget, check_choice, check_instance, real
from skyroute.keywords import strict_keywords, unknown_keywords
from skyroute.result import BUDGET_EXHAUSTED, FOUND, NO_PATH, STATUS_OF_CODE, Status
from skyroute.roadmap.raster import entry_cell, world_raster
from skyroute.search import heap, interrupt
from skyroute.search.los import line_of_sight
from skyroute.search.space import space_of
from skyroute.world.grid import Grid, check_cell
from skyroute.world.points import plane_points
from skyroute.world.world import World

_DIRS = {
    8: [(1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1)],
    16: [(1, 0), (2, 1), (1, 1), (1, 2), (0, 1), (-1, 2), (-1, 1), (-2, 1), (-1, 0),
         (-2, -1), (-1, -1), (-1, -2), (0, -1), (1, -2), (1, -1), (2, -1)],
}


@dataclass(frozen=True)
class LatticeResult:
    """The fastest route: ``status``, cells (K, 2) as (x, y), headings (K,) in radians
    (on a grid from the x axis towards +y; from :func:`plan_turns_world` in the world's
    convention, clockwise from north in "lonlat" and "ned"), travel time and distance
    (inf without a route), and search statistics."""

    status: Status
    cells: np.ndarray
    headings: np.ndarray
    time: float
    distance: float
    expanded: int
    seconds: float
    path: np.ndarray | None = None  # planned on a World: the cells' centres in its frame

    def __repr__(self) -> str:
        """A summary, not the cells."""
        route = (f", {self.time:.6g} s over {self.distance:.6g}"
                 if self.status is Status.FOUND else "")
        return (f"<LatticeResult {self.status.value}{route}, {len(self.cells)} cells, "
                f"{self.expanded} expanded, {self.seconds * 1e3:.3g} ms>")

    @property
    def found(self) -> bool:
        """True when a route was found."""
        return self.status is Status.FOUND


def _tables(headings: int, Wp: int):
    dirs = np.array(_DIRS[headings], dtype=np.int64)
    offs = dirs[:, 1] * Wp + dirs[:, 0]
    lens = np.hypot(dirs[:, 0], dirs[:, 1])
    ang = np.arctan2(dirs[:, 1], dirs[:, 0])
    turn = np.abs((np.roll(ang, -1) - ang + np.pi) % (2 * np.pi) - np.pi)  # h -> h + 1
    return dirs, offs, lens, ang, turn


@njit(cache=True)
def _forward_ok(blk, Wp, c, dx, dy, off):
    n = c + off
    if blk[n]:
        return False
    if abs(dx) + abs(dy) == 1:
        return True
    if abs(dx) == 1 and abs(dy) == 1:  # diagonal: both side cells free
        return blk[c + dx] == 0 and blk[c + dy * Wp] == 0
    return line_of_sight(blk, Wp, c, n)


@njit(cache=True)
def _lattice_kernel(blk, Wp, start, start_h, goal, H, dirs, offs, lens, turn, speed, rate,
                    max_expansions, fs):
    n = blk.size * H
    g = np.full(n, np.inf)
    parent = np.full(n, -1, np.int64)
    state = np.zeros(n, np.int32)
    hc = np.empty(n, np.int32)
    hk = np.empty(n, np.int64)
    gx, gy = goal % Wp, goal // Wp
    size = 0
    for h in range(H):
        if start_h >= 0 and h != start_h:
            continue
        s = start * H + h
        g[s] = 0.0
        d = math.hypot(start % Wp - gx, start // Wp - gy)
        size = heap.push(hc, hk, state, size, s, heap.key(d / speed, 0.0, fs))
    expanded = 0
    while size > 0:
        u, size = heap.pop(hc, hk, state, size)
        c, h = u // H, u % H
        if c == goal:
            return FOUND, u, g, parent, expanded
        if interrupt.stop(expanded):  # nothing of the search kept (see interrupt)
            return interrupt.INTERRUPTED, -1, np.empty(0), np.empty(0, np.int64), expanded
        if expanded >= max_expansions:
            return BUDGET_EXHAUSTED, -1, g, parent, expanded
        expanded += 1
        # forward, turn left, turn right
        for k in range(3):
            if k == 0:
                if not _forward_ok(blk, Wp, c, dirs[h, 0], dirs[h, 1], offs[h]):
                    continue
                v = (c + offs[h]) * H + h
                cost = lens[h] / speed
            elif k == 1:
                v = c * H + (h + 1) % H
                cost = turn[h] / rate
            else:
                v = c * H + (h - 1) % H
                cost = turn[(h - 1) % H] / rate
            if state[v] < 0:
                continue
            gv = g[u] + cost
            if gv < g[v]:
                g[v] = gv
                parent[v] = u
                vc = v // H
                d = math.hypot(vc % Wp - gx, vc // Wp - gy)
                size = heap.push(hc, hk, state, size, v, heap.key(gv + d / speed, gv, fs))
    return NO_PATH, -1, g, parent, expanded


@strict_keywords
def plan_turns(grid: Grid, start: tuple[int, int], goal: tuple[int, int], *,
               headings: int = 8, speed: float = 1.0, turn_rate: float = math.pi / 2,
               start_heading: float | None = None,
               max_expansions: int | None = None, **misspelt) -> LatticeResult:
    """Fastest route from cell ``start`` to cell ``goal`` (any final heading).

    ``speed`` in cells per second, ``turn_rate`` in radians per second; ``start_heading``
    (radians, from the x axis towards +y) snaps to the nearest lattice heading, or any.
    ``max_expansions``: stop with ``budget_exhausted`` after this many; None: enough to
    finish the search, with no cap (the grid's cells times the headings bound it).
    The search is one compiled call, which Ctrl-C stops (:mod:`skyroute.search.interrupt`):
    it can run long on a fine raster (every state of 500 x 500 cells with 16 headings,
    4,000,000 expansions: 1.6 s of CPU; a city's raster has ten times the cells and more).
    """
    if misspelt:
        raise unknown_keywords(plan_turns, misspelt)
    check_instance("grid", grid, Grid, "a skyroute Grid")
    check_choice("headings", headings, (8, 16))
    speed, turn_rate = _rates(speed, turn_rate)
    start_heading = None if start_heading is None else real("start_heading", start_heading)
    budget_ = budget(max_expansions)
    s = check_cell(grid, start, "start")
    t = check_cell(grid, goal, "goal")
    space = space_of(grid)
    dirs, offs, lens, ang, turn = _tables(headings, space.Wp)
    sh = -1
    if start_heading is not None:
        sh = int(np.argmin(np.abs((ang - start_heading + np.pi) % (2 * np.pi) - np.pi)))
    fs = _f_scale(space, headings, lens, turn, speed, turn_rate)
    t0 = time.perf_counter()
    code, end, g, parent, expanded = interrupt.run(
        _lattice_kernel, space.blocked, space.Wp, space.index(s), sh, space.index(t),
        headings, dirs, offs, lens, turn, speed, turn_rate, budget_, fs)
    seconds = time.perf_counter() - t0
    if code != FOUND:
        return LatticeResult(STATUS_OF_CODE[code], np.empty((0, 2)), np.empty(0), math.inf,
                             math.inf, expanded, seconds)
    chain = [end]
    while parent[chain[-1]] >= 0:
        chain.append(parent[chain[-1]])
    chain.reverse()
    cells_flat = np.array([u // headings for u in chain])
    heads = ang[np.array([u % headings for u in chain])]
    keep = np.r_[True, (cells_flat[1:] != cells_flat[:-1]) | (heads[1:] != heads[:-1])]
    cells = np.c_[cells_flat % space.Wp - 1, cells_flat // space.Wp - 1][keep].astype(float)
    dist = float(np.hypot(*np.diff(cells, axis=0).T).sum()) if len(cells) > 1 else 0.0
    return LatticeResult(Status.FOUND, cells, heads[keep], float(g[end]), dist, expanded,
                         seconds)


def plan_turns_world(world: World, start, goal, *, resolution: float | None = None,
                     headings: int = 8, speed: float = 1.0, turn_rate: float = math.pi / 2,
                     start_heading: float | None = None,
                     max_expansions: int | None = None) -> LatticeResult:
    """:func:`plan_turns` on a World rasterised at ``resolution`` (as the grid planners
    on a World do, so every move is exactly free): ``start`` and ``goal`` in the world's
    frame, ``start_heading`` and the result's ``headings`` in its heading convention,
    ``path`` the route in its frame; ``speed`` in plane units per second, ``distance``
    in plane units. The route runs between the centres of the free cells nearest
    ``start`` and ``goal`` (reachable from them in a straight line), not the exact
    points: a leg joining them would take a turn the lattice does not price."""
    check_instance("world", world, World, "a skyroute World")
    speed, _ = _rates(speed, turn_rate)  # named as given, before it is rescaled
    s = world.check_point(start, "start")
    t = world.check_point(goal, "goal")
    grid = world_raster(world, s, t, resolution)
    cs, ct = entry_cell(world, grid, s, "start"), entry_cell(world, grid, t, "goal")
    h0 = None if start_heading is None else \
        float(world.heading_to_plane(real("start_heading", start_heading)))
    res = plan_turns(grid, cs, ct, headings=headings, speed=speed / grid.resolution,
                     turn_rate=turn_rate, start_heading=h0, max_expansions=max_expansions)
    if not res.found:
        return res
    return dataclasses.replace(res, distance=res.distance * grid.resolution,
                               headings=world.heading_from_plane(res.headings),
                               path=world.from_plane(grid.to_world(res.cells)))


def travel_time(cells, *, speed: float = 1.0, turn_rate: float = math.pi / 2,
                start_heading: float | None = None) -> float:
    """Time to drive a cell path: its length / speed plus every heading change / turn rate
    (the first move's turn counted from ``start_heading`` when given)."""
    speed, turn_rate = _rates(speed, turn_rate)
    start_heading = None if start_heading is None else real("start_heading", start_heading)
    c = plane_points(cells, "cells")
    if len(c) < 2:
        return 0.0
    d = np.diff(c, axis=0)
    d = d[np.any(d != 0, axis=1)]
    ang = np.arctan2(d[:, 1], d[:, 0])
    turns = np.abs((np.diff(ang) + np.pi) % (2 * np.pi) - np.pi).sum()
    if start_heading is not None:
        turns += abs((ang[0] - start_heading + np.pi) % (2 * np.pi) - np.pi)
    return float(np.hypot(*d.T).sum() / speed + turns / turn_rate)


def _f_scale(space, headings: int, lens, turn, speed: float, rate: float) -> float:
    """The heap keys' unit of f (:func:`heap.f_scale`) for a lattice search: every
    f is at most one longest step or turn per (free cell, heading), plus the grid's
    width + height over ``speed``; an OptionError naming speed and turn_rate when even
    that f would not fit in a key (a route could take trillions of seconds)."""
    span = float(space.width + space.height)
    states = (space.f_bound(0.0) / math.sqrt(2.0)) * headings  # (free + span) x H
    f_max = states * (float(lens.max()) / speed + float(turn.max()) / rate) + span / speed
    fs = heap.f_scale(f_max)
    if fs == 0.0:
        limit = 2.0 ** heap.F_BITS
        # no values: plan_turns_world and the CLI give them in other units
        raise OptionError(f"speed and turn_rate are too small for this {space.width}x"
                          f"{space.height} grid: a route's time could pass the {limit:.3g} s "
                          f"its search keys hold; raise them", param=("speed", "turn_rate"))
    return fs


def _rates(speed, turn_rate) -> tuple[float, float]:
    """``speed`` and ``turn_rate`` as finite floats > 0, else an OptionError naming one."""
    return (real("speed", speed, low=0.0, strict=True, need="positive"),
            real("turn_rate", turn_rate, low=0.0, strict=True, need="positive"))
