"""Hybrid A* (Dolgov, Thrun, Montemerlo & Diebel 2010) for vehicles that drive forward
and turn no tighter than a radius, among polygon obstacles.

>>> import numpy as np, shapely
>>> from skyroute.world.world import World
>>> wall = np.array([shapely.box(45, 0, 55, 60)], dtype=object)
>>> world = World(wall, [-np.inf], [np.inf], ("wall",), boundary=shapely.box(0, 0, 100, 100))
>>> r = plan(world, (20, 20, 0.0), (80, 20, 0.0), radius=5)
>>> r.status.value, r.length > 60, bool(np.allclose(r.sample(1.0)[-1], (80, 20, 0)))
('found', True, True)

The search runs on a continuous lattice: nodes keep their exact pose, states are
(cell, heading bin); each expansion drives a left arc, a straight and a right arc of
``step`` metres (:mod:`skyroute.motion.hybrid_search`, compiled). Every arc and straight
is tested exactly against the obstacles' and the boundary's edges
(:mod:`skyroute.motion.arc_kernels`); the path ends with an analytic Dubins expansion
and is then shortcut (:mod:`skyroute.motion.smooth`).

Choices, and why:

- ``step`` (default: the arc that turns 360/18 degrees, r pi / 9, about 1.75 m for r =
  5) is a whole number of heading bins, so the lattice headings stay exact multiples of
  the bin width from the start heading; smaller steps multiply expansions without
  shortening the smoothed paths much (docs/architecture.md, benchmarks).
- Cell size ``step / sqrt(2)``: a straight primitive always leaves its cell, and an arc's
  chord (at least 0.98 step here) nearly always does, so one expansion never lands back
  in its own state.
- Heuristic max(Dubins ignoring obstacles, exact 2D distance around the obstacles): the
  2D distance from a per-goal table of each convex corner's shortest distance to the
  goal (:class:`skyroute.motion.step_drone.DistanceBound`, a Dijkstra over the corner
  visibility graph) and, per node, the corners it sees. A raster distance field is
  cheaper per node but is a lower bound only after losing a cell diagonal and the
  8-connected metric's 8 %, which costs more expansions than the sight tests cost.
- A start without heading seeds every heading bin, measured from the direction towards
  the goal (so driving straight at it is one of them); a goal without heading is reached
  by the turn-then-tangent Dubins paths (every heading bin when it lies inside a turning
  circle).
- Without a boundary, states are kept within the bounding box of the obstacles, start
  and goal grown by 4 r + 2 step, so an enclosed goal ends in ``no_path``.
"""

from __future__ import annotations

import math
import numbers
import time
import weakref
from dataclasses import dataclass, field

import numpy as np

from skyroute.errors import OptionError, QueryError
from skyroute.motion import hybrid_search
from skyroute.motion.arc_kernels import chain_free, edge_index
from skyroute.motion.dubins_kernel import TURNS
from skyroute.motion.pieces import Piece, chain, merge, sample
from skyroute.motion.smooth import length, shortcut
from skyroute.motion.zone_kernels import zone_arrays
from skyroute.search.result import STATUS_OF_CODE, Status
from skyroute.world.world import World

Pose = tuple[float, float, float]


@dataclass(frozen=True)
class HybridResult:
    """A planned path of arcs and straights, its status and statistics.

    ``segments`` are :class:`~skyroute.motion.pieces.Piece` objects laid end to end
    (empty unless found); ``length`` their total (inf unless found); ``start`` and
    ``goal`` the poses the path joins (the goal heading is the arrival heading when none
    was asked for); ``expanded`` nodes expanded; ``seconds`` wall time of the planning.
    ``extra``: ``raw_length`` before shortcutting, analytic ``tries``, ``shortcut_tries``.
    """

    status: Status
    length: float
    segments: tuple[Piece, ...]
    start: Pose
    goal: Pose
    radius: float
    expanded: int = 0
    seconds: float = 0.0
    extra: dict = field(default_factory=dict, compare=False)

    @property
    def found(self) -> bool:
        """True when a path was found."""
        return self.status is Status.FOUND

    def sample(self, step: float) -> np.ndarray:
        """(K, 3) poses (x, y, heading in [0, 2 pi)) every ``step`` metres along each
        piece and at every joint; the first row is exactly ``start`` and the last exactly
        ``goal``. Empty unless found."""
        if not (isinstance(step, numbers.Real) and math.isfinite(step) and step > 0):
            raise OptionError(f"step={step!r} must be a positive number")
        if not self.found:
            return np.empty((0, 3))
        return sample(list(self.segments), float(step), self.start, self.goal)


def runway_goal(threshold, runway_heading: float, approach_length: float) -> tuple[Pose,
                                                                                  Piece]:
    """The pose where a straight final approach of ``approach_length`` metres begins, and
    that final piece, which ends on the runway ``threshold`` (x, y) flying
    ``runway_heading`` (the gate of :func:`skyroute.motion.dubins.runway_approach`)."""
    tx, ty = _xy(threshold, "threshold")
    h = float(runway_heading)
    a = float(approach_length)
    if not (math.isfinite(h) and math.isfinite(a) and a >= 0):
        raise OptionError(f"runway_heading={runway_heading!r} and approach_length="
                          f"{approach_length!r} must be finite, approach_length >= 0")
    gate = (tx - a * math.cos(h), ty - a * math.sin(h), h)
    return gate, Piece("S", gate, a, math.inf)


def plan(world: World, start, goal, radius: float, *, heading_bins: int = 72,
         step: float | None = None, reverse: bool = False,
         max_expansions: int | None = None, approach: float | None = None,
         smooth: bool = True, seed: int = 0) -> HybridResult:
    """A short path of arcs (radius ``radius``) and straights from ``start`` to ``goal``
    that meets no obstacle interior and stays strictly inside the boundary.

    Parameters
    ----------
    world : World
        Obstacles and boundary in its plane (x, y).
    start, goal : (x, y) or (x, y, heading)
        Heading in radians anticlockwise from +x. Without one the planner picks the
        start heading, or accepts any arrival heading.
    radius : float
        Smallest turning radius, > 0.
    heading_bins : int
        Heading resolution of the closed set, >= 4.
    step : float, optional
        Arc length of one primitive, in (0, pi r]; default r pi / 9 rounded to whole
        heading bins.
    reverse : bool
        Backward driving; not supported yet (raises OptionError).
    max_expansions : int, optional
        Stop with ``budget_exhausted`` (or with the best path found so far) after this
        many expansions.
    approach : float, optional
        ``goal`` is a runway threshold (x, y, runway heading) and the path ends with a
        straight final approach this long along the runway (:func:`runway_goal`).
    smooth : bool
        Shortcut the path with free Dubins connections.
    seed : int
        Seed of the shortcutting's random pairs.

    Returns
    -------
    HybridResult

    Raises
    ------
    QueryError
        a malformed pose, or a start or goal inside an obstacle or outside the boundary.
    OptionError
        an out-of-range option.
    """
    r, H, step, budget = _options(radius, heading_bins, step, reverse, max_expansions, seed)
    sxy, sth = _pose(start, "start")
    gxy, gth = _pose(goal, "goal")
    world.check_point(sxy, "start")
    final = None
    if approach is not None:
        if gth is None:
            raise QueryError("goal needs a runway heading (x, y, heading) with approach=")
        if not (isinstance(approach, numbers.Real) and math.isfinite(approach) and
                approach >= 0):
            raise OptionError(f"approach={approach!r} must be a number >= 0")
        threshold = gxy
        world.check_point(threshold, "goal")
        gate, final = runway_goal(threshold, gth, approach)
        gxy = np.array(gate[:2])
        if approach == 0:
            final = None
    world.check_point(gxy, "goal")
    t0 = time.perf_counter()
    index = edge_index(world, _bucket(world))
    if final is not None:
        ok = _free(index, [Piece("S", final.start, final.length, r)])
        if not ok:
            raise QueryError(f"goal: the final approach of {approach:g} m to "
                             f"({threshold[0]:.2f}, {threshold[1]:.2f}) is not free")
    dth = 2 * math.pi / H
    ref = sth if sth is not None else (
        math.atan2(gxy[1] - sxy[1], gxy[0] - sxy[0]) if np.any(gxy != sxy) else 0.0)
    seeds = np.array([[sxy[0], sxy[1], sth]]) if sth is not None else \
        np.c_[np.tile(sxy, (H, 1)), ref + np.arange(H) * dth]
    from skyroute.motion.step_drone import DistanceBound

    table = DistanceBound(world, gxy)
    sight = _sight_edges(world)
    cell = step / math.sqrt(2)
    region = _region(world, sxy, gxy, 4 * r + 2 * step)
    prim_k = np.array([1, 0, -1], np.int64)
    prim_u = np.full(3, step)
    prim_c = np.full(3, step)
    code, end, end_head, end_word, best, expanded, tries, x, y, th, parent, prim = \
        hybrid_search.search(
            seeds, float(gxy[0]), float(gxy[1]), 0.0 if gth is None else float(gth),
            gth is not None, r, prim_k, prim_u, prim_c, float(ref), dth, H, cell,
            np.array(region, dtype=float), *index.args(),
            np.ascontiguousarray(table.corners, dtype=float),
            np.ascontiguousarray(table.dist, dtype=float), sight, budget, 10, 3)
    status = STATUS_OF_CODE[code]
    goal_pose = (float(gxy[0]), float(gxy[1]), float(end_head if gth is None else gth))
    start_pose = (float(sxy[0]), float(sxy[1]), float(sth if sth is not None else 0.0))
    if status is not Status.FOUND:
        return HybridResult(status, math.inf, (), start_pose, goal_pose if gth is not None
                            else (goal_pose[0], goal_pose[1], math.nan), r, int(expanded),
                            time.perf_counter() - t0, {"tries": int(tries)})
    nodes = [end]
    while parent[nodes[-1]] >= 0:
        nodes.append(parent[nodes[-1]])
    nodes.reverse()
    root = nodes[0]
    start_pose = (float(sxy[0]), float(sxy[1]), float(th[root]))
    turns = [int(prim_k[prim[n]]) for n in nodes[1:]]
    lens = [float(prim_u[prim[n]]) for n in nodes[1:]]
    node_end = (float(x[end]), float(y[end]), float(th[end]))
    from skyroute.motion.dubins_kernel import words

    segs, _ = words(*node_end, *goal_pose, r)
    pieces = merge(chain(start_pose, turns, lens, r) +
                   chain(node_end, TURNS[end_word], segs[end_word], r))
    raw = length(pieces)
    shortcut_tries = 0
    if smooth:
        pieces, shortcut_tries = shortcut(pieces, start_pose, r, lambda p: _free(index, p),
                                          np.random.default_rng(seed))
        pieces = merge(pieces)
    if final is not None:
        pieces.append(Piece("S", goal_pose, final.length, r))
        goal_pose = (float(threshold[0]), float(threshold[1]), goal_pose[2])
    return HybridResult(Status.FOUND, length(pieces), tuple(pieces), start_pose, goal_pose,
                        r, int(expanded), time.perf_counter() - t0,
                        {"raw_length": raw + (final.length if final else 0.0),
                         "tries": int(tries), "shortcut_tries": shortcut_tries,
                         "best": float(best)})


def path_free(world: World, pieces) -> bool:
    """True when the chain of pieces passes the exact test on ``world`` (the test the
    planner uses: more than 1e-9 of the extent from every obstacle and boundary edge)."""
    return _free(edge_index(world, _bucket(world)), list(pieces))


def _free(index, pieces: list[Piece]) -> bool:
    if not pieces:
        return True
    stamp = np.zeros(len(index.edges), np.int64)
    tick = np.zeros(1, np.int64)
    for p in pieces:
        turns = np.array([p.k], np.int64)
        lens = np.array([p.signed_length])
        r = p.radius if p.k != 0 else 1.0
        if not chain_free(*p.start, turns, lens, r, *index.args(), stamp, tick):
            return False
    return True


def _bucket(world: World) -> float:
    """Edge buckets: about 64 across the world."""
    xmin, ymin, xmax, ymax = world.bounds if (world.boundary is not None or
                                              len(world.obstacles)) else (0, 0, 1, 1)
    return max(xmax - xmin, ymax - ymin) / 64.0


_SIGHT: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _sight_edges(world: World) -> np.ndarray:
    """Obstacle edges (not the boundary: the 2D bound ignores it, so stays a bound)."""
    if world not in _SIGHT:
        _SIGHT[world] = np.ascontiguousarray(zone_arrays(world.merged())[0], dtype=float)
    return _SIGHT[world]


def _region(world: World, s, g, margin: float) -> tuple[float, float, float, float]:
    if world.boundary is not None:
        return world.bounds
    return world.extent_with([s, g], margin=margin) if len(world.obstacles) else (
        min(s[0], g[0]) - margin, min(s[1], g[1]) - margin,
        max(s[0], g[0]) + margin, max(s[1], g[1]) + margin)


def _options(radius, heading_bins, step, reverse, max_expansions, seed):
    if isinstance(radius, bool) or not isinstance(radius, numbers.Real) or \
            not (math.isfinite(radius) and radius > 0):
        raise OptionError(f"radius={radius!r} must be > 0 and finite")
    r = float(radius)
    if isinstance(heading_bins, bool) or not isinstance(heading_bins, numbers.Integral) or \
            heading_bins < 4:
        raise OptionError(f"heading_bins={heading_bins!r} must be an integer >= 4")
    H = int(heading_bins)
    if step is None:
        arc = r * 2 * math.pi / H
        step = arc * max(1, round(H / 18))
    elif isinstance(step, bool) or not isinstance(step, numbers.Real) or \
            not (math.isfinite(step) and 0 < step <= math.pi * r):
        raise OptionError(f"step={step!r} must be in (0, pi * radius] = (0, {math.pi * r:g}]")
    if reverse:
        raise OptionError("reverse=True is not supported yet")
    if max_expansions is None:
        budget = np.iinfo(np.int64).max
    elif isinstance(max_expansions, bool) or not isinstance(max_expansions,
                                                             numbers.Integral) \
            or max_expansions < 0:
        raise OptionError(f"max_expansions={max_expansions!r} must be an integer >= 0")
    else:
        budget = int(max_expansions)
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral):
        raise OptionError(f"seed={seed!r} must be an integer")
    return r, H, float(step), budget


def _pose(p, what: str) -> tuple[np.ndarray, float | None]:
    """(x, y) array and heading (None when absent) of a start or goal."""
    try:
        vals = list(p)
    except TypeError:
        raise QueryError(f"{what}={p!r} must be (x, y) or (x, y, heading)") from None
    if len(vals) not in (2, 3) or not all(
            isinstance(v, numbers.Real) and not isinstance(v, bool) for v in vals):
        raise QueryError(f"{what}={p!r} must be (x, y) or (x, y, heading) numbers")
    if not all(math.isfinite(float(v)) for v in vals):
        raise QueryError(f"{what}={p!r} must be finite numbers")
    xy = np.array([float(vals[0]), float(vals[1])])
    return xy, (float(vals[2]) if len(vals) == 3 else None)


def _xy(p, what: str) -> tuple[float, float]:
    xy, h = _pose(p, what)
    if h is not None:
        raise QueryError(f"{what}={p!r} must be (x, y)")
    return float(xy[0]), float(xy[1])
