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

Choices, and why (measured on the curvature benchmark's worlds, :mod:`skyroute.bench.
curvature`; numbers in docs/architecture.md):

- ``step``: by default the arc that turns 20 degrees (r pi / 9, 1.75 m for r = 5),
  rounded to whole heading bins so lattice headings stay exact multiples of the bin
  width from the start heading. Turns of 15 degrees gave the same smoothed lengths (mean
  within 0.1 %) at up to twice the time on hard queries; 30 degrees was faster still
  but 1.5 % longer on average, with some detours.
- Cell size ``step / sqrt(2)``: a straight primitive always leaves its cell (an arc's
  chord nearly always), so an expansion does not land back in its own state.
- Heuristic max(Dubins length ignoring obstacles, 2D distance around the obstacles),
  both lower bounds. The 2D term comes from a per-goal table of every convex corner's
  exact shortest distance to the goal (:mod:`skyroute.motion.corner_distance`: the
  corners' bitangent visibility graph once per world, a compiled Dijkstra per goal in
  well under a millisecond) and, per node, the cheapest corners it sees; after 3 blocked
  candidates the next candidate's value is taken, still a bound. Evaluated lazily: a new
  node gets max(|q - goal|, parent's bound - step) and the exact value only when popped.
  No raster: a grid distance field stays a lower bound only after losing a cell
  diagonal and the 8-neighbour metric's 8 %, and needs a raster per goal.
- Analytic expansion (the shortest of up to 3 Dubins words that fits) from every node
  that sees the goal and every 10th node, when it can still beat the best path found;
  the search runs on until no open node can (f >= best), then the path is shortcut.
- Time reversal first: a path driven backwards is a forward path from the goal turned
  round to the start turned round, so a short (500-expansion) search that way ends at
  once when the goal cannot be reached (say, facing the boundary), and when it finishes
  its path is the answer; otherwise the forward search runs.
- A start without heading seeds every heading bin, measured from the direction towards
  the goal (so driving straight at it is one), and first the two headings that reach a
  goal circle on a tangent; a goal without heading is reached by the turn-then-tangent
  Dubins paths (every heading bin when it lies inside a turning circle).
- Without a boundary, states are kept within the bounding box of the obstacles, start
  and goal grown by 4 r + 2 step, so an enclosed goal ends in ``no_path``.
- ``reverse=True`` keeps all of the above with six primitives and the cusp-free
  Reeds-Shepp words (forward or backward Dubins paths); the full 48-word Reeds-Shepp
  family (paths with cusps inside the analytic expansion) is not implemented, so
  manoeuvres with cusps come from the lattice and its shortcutting.
- ``no_path`` means no path on this lattice (Hybrid A* is resolution-complete only in
  the limit): every state reachable by the primitives was expanded.
"""

from __future__ import annotations

import itertools
import math
import numbers
import time
from dataclasses import dataclass, field

import numpy as np
import shapely

from skyroute.errors import (
    OptionError,
    QueryError,
    budget,
    check_instance,
    check_seed,
    flag,
    real,
    whole,
)
from skyroute.keywords import strict_keywords, unknown_keywords
from skyroute.motion import hybrid_search
from skyroute.motion.arc_kernels import chain_free, edge_index
from skyroute.motion.corner_distance import corner_graph
from skyroute.motion.dubins_kernel import TURNS, tangent_heading, words
from skyroute.motion.pieces import (
    Piece,
    chain,
    drop_slivers,
    merge,
    sample,
    time_reversed,
    turned_round,
)
from skyroute.motion.smooth import length, shortcut
from skyroute.result import FOUND, NO_PATH, STATUS_OF_CODE, Status
from skyroute.search import interrupt
from skyroute.world.world import World

Pose = tuple[float, float, float]
_EVERY, _WORDS = 10, 3  # analytic expansion: every 10th node; 3 words
_SIGHT_TESTS = 3  # corners tried per node by the 2D bound
_WEIGHT = 1.0  # f = g + weight h; 1 keeps the search best-first on the true bound
_REVERSE_BUDGET = 500  # expansions of the reversed search that comes first
_BACK_COST = 1.0  # reverse=True: a metre driven backwards costs as much as one forwards
_SWITCH = 1.0  # reverse=True: each change of direction costs this many turning radii
#: max_expansions=None: enough to finish the search, capped so that it stores at most this
#: many nodes (each expansion adds at most one per primitive; about 2 GB): 10,000,000
#: expansions (5,000,000 with reverse).
#: The largest searches measured that find a path used 3,000,000 (radius 5 m across the
#: 930 m FCND city, docs/architecture.md); without a cap a radius tiny beside the world
#: (0.01 m in 100 m) filled 10 GB in 5 minutes.
MAX_NODES = 30_000_000


@dataclass(frozen=True)
class HybridResult:
    """A planned path of arcs and straights, its status and statistics.

    ``segments`` are :class:`~skyroute.motion.pieces.Piece` objects laid end to end in
    the world's plane (empty unless found); ``length`` their total (inf unless found);
    ``start`` and ``goal`` the plane poses the path joins (the goal heading is the arrival
    heading when none was asked for); ``expanded`` nodes expanded; ``seconds`` wall time
    of the planning. :meth:`sample` gives poses in the world's frame. ``extra``:
    ``raw_length`` before shortcutting, analytic ``tries``, ``shortcut_tries``; on
    ``budget_exhausted``, the ``budget`` spent, ``radii_across`` (the search region's
    longer side in turning radii) and a one-line ``hint``; on ``no_path``, which end's
    states ran out (``closed``: "goal", no lattice state outside a few around the goal
    reaches it, or "start", every state the start reaches was expanded) and after how
    many expansions of that search (``closed_after``: a few hundred or less means that
    end is boxed in, as a pose facing a wall).
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
    world: World | None = field(default=None, compare=False, repr=False)
    given: tuple = field(default=(None, None), compare=False, repr=False)

    @property
    def found(self) -> bool:
        """True when a path was found."""
        return self.status is Status.FOUND

    def sample(self, step: float) -> np.ndarray:
        """(K, 3) poses every ``step`` plane units along each piece and at every joint,
        in the world's frame (points as the world reads them, headings in [0, 2 pi) in
        its convention); the first row is exactly the start as given and the last
        exactly the goal (its heading too, when one was given). Empty unless found."""
        step = real("step", step, low=0.0, strict=True)
        if not self.found:
            return np.empty((0, 3))
        poses = sample(list(self.segments), float(step), self.start, self.goal)
        if self.world is None:
            return poses
        out = np.c_[self.world.from_plane(poses[:, :2]),
                    self.world.heading_from_plane(poses[:, 2])]
        for row, pose in ((0, self.given[0]), (-1, self.given[1])):
            if pose is not None:
                out[row, :len(pose)] = pose
                out[row, 2] %= 2 * math.pi
        return out


def runway_goal(threshold, runway_heading: float, approach_length: float) -> tuple[Pose,
                                                                                  Piece]:
    """The pose where a straight final approach of ``approach_length`` metres begins, and
    that final piece, which ends on the runway ``threshold`` (x, y) flying
    ``runway_heading`` (the gate of :func:`skyroute.motion.dubins.runway_approach`)."""
    tx, ty = _xy(threshold, "threshold")
    h = real("runway_heading", runway_heading)
    a = real("approach_length", approach_length, low=0.0)
    gate = (tx - a * math.cos(h), ty - a * math.sin(h), h)
    return gate, Piece("S", gate, a, math.inf)


@strict_keywords
def plan(world: World, start, goal, radius: float, *, heading_bins: int = 72,
         step: float | None = None, reverse: bool = False,
         max_expansions: int | None = None, approach: float | None = None,
         smooth: bool = True, seed: int = 0, **misspelt) -> HybridResult:
    """A short path of arcs (radius ``radius``) and straights from ``start`` to ``goal``
    that meets no obstacle interior and stays strictly inside the boundary.

    Parameters
    ----------
    world : World
        Obstacles and boundary; points are read in the world's frame.
    start, goal : (a, b) or (a, b, heading)
        A point in the world's frame and a heading in radians in its convention
        (anticlockwise from +x in "enu" and "degrees", clockwise from north in "ned" and
        "lonlat"). Without one the planner picks the start heading, or accepts any
        arrival heading.
    radius : float
        Smallest turning radius, > 0, in plane units (metres; degrees in "degrees").
    heading_bins : int
        Heading resolution of the closed set, >= 4.
    step : float, optional
        Arc length of one primitive, in (0, pi r]; default r pi / 9 rounded to whole
        heading bins.
    reverse : bool
        Allow driving backwards (a car, not a plane): the lattice gains three reverse
        primitives, a metre backwards costs as much as one forwards and each change of
        direction costs one turning radius (``extra["cusps"]`` counts them; ``length``
        stays the geometric length). The analytic expansion tries Dubins paths driven
        wholly forwards or wholly backwards, the Reeds-Shepp words without a cusp; cusps
        come from the lattice. The Dubins heuristic gives way to max(straight distance,
        r times the heading change), which stays a bound with reversing.
    max_expansions : int, optional
        Stop with ``budget_exhausted`` (or with the best path found so far) after this
        many expansions. None: enough to finish the search (every lattice state of the
        search region), capped to protect memory at :data:`MAX_NODES` divided by the
        primitives per expansion, 10,000,000 (5,000,000 with ``reverse``): about 2 GB and
        a few minutes at most, far above the searches that find a path in city-sized
        worlds at radii of metres, and the guard against a radius tiny beside the world,
        whose lattice has billions of states. Running out says so in ``extra["hint"]``,
        with the world's size in turning radii. Ctrl-C stops the search within 4,096
        expansions (:mod:`skyroute.search.interrupt`).
    approach : float, optional
        ``goal`` is a runway threshold (x, y, runway heading) and the path ends with a
        straight final approach this long along the runway (:func:`runway_goal`).
    smooth : bool
        Shortcut the path with free Dubins connections.
    seed : int
        Seed of the shortcutting's random pairs, an integer from 0 to 2**32 - 1
        (:data:`skyroute.errors.SEED_MAX`).

    Returns
    -------
    HybridResult

    Raises
    ------
    QueryError
        a malformed pose, or a start or goal inside an obstacle (or on a face two
        touching obstacles share: inside their union), outside the boundary, or on an
        obstacle's edge or within 1e-9 of the extent of an edge, where every piece
        would meet it.
    OptionError
        an out-of-range option.
    """
    if misspelt:
        raise unknown_keywords(plan, misspelt)
    check_instance("world", world, World, "a skyroute World")
    r, H, step, limit = _options(radius, heading_bins, step, reverse, max_expansions, seed,
                                 smooth)
    if max_expansions is None:
        limit = MAX_NODES // (6 if reverse else 3)
    reverse, smooth, seed = bool(reverse), bool(smooth), int(seed)
    (s_typed, s_h), (g_typed, g_h) = _pose(start, "start"), _pose(goal, "goal")
    sxy, sth = _in_plane(world, s_typed, s_h)
    gxy, gth = _in_plane(world, g_typed, g_h)
    given = tuple(tuple(float(v) for v in p) for p in (start, goal))
    world.check_plane_point(sxy, "start", given=s_typed)  # shown as typed, not round-tripped
    final = None
    if approach is not None:
        if gth is None:
            raise QueryError("goal needs a runway heading (x, y, heading) with approach=")
        approach = real("approach", approach, low=0.0)
        threshold = gxy
        world.check_plane_point(threshold, "goal", given=g_typed)
        gate, final = runway_goal(threshold, gth, approach)
        gxy = np.array(gate[:2])
        if approach == 0:
            final = None
    world.check_plane_point(gxy, "goal", given=g_typed if approach is None else None)
    t0 = time.perf_counter()
    index = edge_index(world, _bucket(world))
    _off_edges(world, index, sxy, "start", s_typed)
    _off_edges(world, index, gxy, "goal", g_typed if approach is None else None)
    if final is not None:
        ok = _free(index, [Piece("S", final.start, final.length, r)])
        if not ok:
            raise QueryError(f"goal: the final approach of {approach:g} m to "
                             f"({threshold[0]:.2f}, {threshold[1]:.2f}) is not free")
    region = _region(world, sxy, gxy, 4 * r + 2 * step)
    lattice = _Lattice(world, index, r, H, step, region, reverse)
    # Time reversal: a path from start to goal driven backwards is a forward path from
    # the goal turned round to the start turned round (with reverse gears: a path from
    # the goal to the start, every piece's direction swapped). A short search that way
    # first ends at once when the goal is boxed in (facing a wall, or only reachable from
    # outside the boundary), which the forward search would learn only after exhausting
    # the whole world; when it finishes it is the answer.
    first = min(limit, _REVERSE_BUDGET)
    if reverse:
        back = lattice.search(gxy, gth, sxy, sth, first)
    else:
        back = lattice.search(gxy, _turned(gth), sxy, _turned(sth), first)
    if back.code == NO_PATH or (back.code == FOUND and back.expanded < first):
        res, expanded = back.reversed(reverse), back.expanded
        closed = ("goal", back.expanded)
    else:
        res = lattice.search(sxy, sth, gxy, gth, limit - back.expanded)
        expanded = back.expanded + res.expanded
        closed = ("start", res.expanded)
    status = STATUS_OF_CODE[res.code]
    start_pose = (float(sxy[0]), float(sxy[1]), math.nan if sth is None else float(sth))
    goal_pose = (float(gxy[0]), float(gxy[1]), math.nan if gth is None else float(gth))
    if status is not Status.FOUND:
        extra = {"tries": back.tries + res.tries}
        if status is Status.NO_PATH:
            extra.update(closed=closed[0], closed_after=int(closed[1]))
        if status is Status.BUDGET_EXHAUSTED:
            extra.update(budget=limit, radii_across=_across(region) / r,
                         hint=_hint(limit, max_expansions is None, _across(region) / r, r))
        return HybridResult(status, math.inf, (), start_pose, goal_pose, r, int(expanded),
                            time.perf_counter() - t0, extra, world, given)
    pieces = res.pieces
    if pieces:  # exactly the given start (a reversed search ends there within rounding)
        head = pieces[0].start[2] if sth is None else sth
        start_pose = (float(sxy[0]), float(sxy[1]), float(head))
        pieces[0] = Piece(pieces[0].kind, start_pose, pieces[0].length, r, pieces[0].reverse)
        goal_pose = (float(gxy[0]), float(gxy[1]), float(res.goal[2] if gth is None else gth))
    else:
        head = sth if sth is not None else (gth if gth is not None else 0.0)
        start_pose = (float(sxy[0]), float(sxy[1]), float(head))
        goal_pose = (float(gxy[0]), float(gxy[1]), float(head))
    raw = length(pieces)
    shortcut_tries = 0
    if smooth:
        pieces, shortcut_tries = shortcut(pieces, r, index, seed=seed, reverse=reverse,
                                          back_cost=_BACK_COST, switch_cost=_SWITCH * r)
    # a piece of rounding's length (1e-15 m: a Dubins word's last arc) sampled as a
    # repeat of the goal; gone within the 1e-12 of the extent that a path may miss by
    pieces = drop_slivers(pieces, 1e-3 * index.eps)
    if final is not None:
        pieces.append(Piece("S", goal_pose, final.length, r))
        goal_pose = (float(threshold[0]), float(threshold[1]), goal_pose[2])
    return HybridResult(Status.FOUND, length(pieces), tuple(pieces), start_pose, goal_pose,
                        r, int(expanded), time.perf_counter() - t0,
                        {"raw_length": raw + (final.length if final else 0.0),
                         "tries": back.tries + res.tries, "shortcut_tries": shortcut_tries,
                         "reversed": res.flipped,
                         "cusps": sum(a.reverse != b.reverse
                                      for a, b in itertools.pairwise(pieces))},
                        world, given)


@dataclass
class _Found:
    """One direction's outcome: kernel code, expansions, analytic tries, and the pieces
    and goal pose when found."""

    code: int
    expanded: int
    tries: int
    pieces: list = field(default_factory=list)
    goal: Pose | None = None
    flipped: bool = False

    def reversed(self, gears: bool) -> _Found:
        """The path run backwards in time: with reverse ``gears``, each piece driven the
        other way; without, also turned round (forward again, L and R swapped)."""
        if self.code != FOUND:
            return _Found(self.code, self.expanded, self.tries)
        out = time_reversed(self.pieces)
        start = self.pieces[0].start if self.pieces else self.goal
        if not gears:
            out = turned_round(out)
            start = (start[0], start[1], start[2] + math.pi)
        return _Found(self.code, self.expanded, self.tries, out, start, True)


class _Lattice:
    """The search's fixed inputs for one query: edges, lattice sizes, region."""

    def __init__(self, world, index, r, H, step, region, reverse):
        self.world, self.index, self.r, self.H, self.step = world, index, r, H, step
        self.region = np.array(region, dtype=float)
        self.graph = corner_graph(world)
        self.reverse = reverse
        n = 6 if reverse else 3
        self.k = np.array([1, 0, -1, 1, 0, -1][:n], np.int64)  # left, straight, right
        self.u = np.array([1.0, 1.0, 1.0, -1.0, -1.0, -1.0][:n]) * step  # > 0 forward
        self.c = np.abs(self.u) * np.where(self.u < 0, _BACK_COST, 1.0)

    def search(self, sxy, sth, gxy, gth, budget) -> _Found:
        r, H, step = self.r, self.H, self.step
        dth = 2 * math.pi / H
        ref = sth if sth is not None else (
            math.atan2(gxy[1] - sxy[1], gxy[0] - sxy[0]) if np.any(gxy != sxy) else 0.0)
        if sth is not None:
            seeds = np.array([[sxy[0], sxy[1], sth]])
        else:
            heads = ref + np.arange(H) * dth
            if gth is not None:  # first the headings that leave straight on a tangent
                # of a goal circle: the best ones without obstacles (time-reversed
                # turn-then-tangent paths from the goal turned round)
                tang = [tangent_heading(gxy[0], gxy[1], gth + math.pi, sxy[0], sxy[1], r,
                                        side) + math.pi for side in (1, -1)]
                heads = np.r_[[h for h in tang if math.isfinite(h)], heads]
            seeds = np.c_[np.tile(sxy, (len(heads), 1)), heads]
        g = self.graph
        code, end, end_head, end_word, end_back, _, expanded, tries, x, y, th, parent, prim = \
            interrupt.run(
                hybrid_search.search, seeds, float(gxy[0]), float(gxy[1]),
                0.0 if gth is None else float(gth), gth is not None, r, self.k, self.u,
                self.c, float(ref), dth, H, step / math.sqrt(2), self.region,
                *self.index.args(), g.corners, g.to(gxy), g.edges, *g.grid, _SIGHT_TESTS,
                _WEIGHT, budget, _EVERY, _WORDS, self.reverse, _BACK_COST, _SWITCH * r)
        if code != FOUND:
            return _Found(int(code), int(expanded), int(tries))
        nodes = [end]
        while parent[nodes[-1]] >= 0:
            nodes.append(parent[nodes[-1]])
        nodes.reverse()
        start_pose = (float(sxy[0]), float(sxy[1]), float(th[nodes[0]]))
        head = end_head - (math.pi if end_back else 0.0)
        goal_pose = (float(gxy[0]), float(gxy[1]), float(head if gth is None else gth))
        turns = [int(self.k[prim[n]]) for n in nodes[1:]]
        back = [bool(self.u[prim[n]] < 0) for n in nodes[1:]]
        node_end = (float(x[end]), float(y[end]), float(th[end]))
        if end_back:  # the forward Dubins path of the vehicle turned round, in reverse
            a = (node_end[0], node_end[1], node_end[2] + math.pi)
            b = (goal_pose[0], goal_pose[1], goal_pose[2] + math.pi)
            segs, _ = words(*a, *b, r)
            last = turned_round(chain(a, TURNS[end_word], segs[end_word], r))
        else:
            segs, _ = words(*node_end, *goal_pose, r)
            last = chain(node_end, TURNS[end_word], segs[end_word], r)
        pieces = merge(chain(start_pose, turns, [step] * len(turns), r, back) + last)
        return _Found(int(code), int(expanded), int(tries), pieces, goal_pose)


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
        # floats, whatever the piece holds: a piece of whole numbers ((10, 60, 0), 80)
        # was another signature, compiled afresh (15 s) beside the planner's own
        x, y, th = (float(v) for v in p.start)
        turns = np.array([p.k], np.int64)
        lens = np.array([p.signed_length], np.float64)
        r = float(p.radius) if p.k != 0 else 1.0
        if not chain_free(x, y, th, turns, lens, r, *index.args(), stamp, tick):
            return False
    return True


def _off_edges(world: World, index, p: np.ndarray, what: str, given) -> None:
    """A QueryError when the plane point ``p`` lies on an obstacle's edge, or within
    ``index.eps`` of an obstacle's or the boundary's edge. Such a point is free in the
    world, but every piece from or to it meets that edge: the search ended in no_path
    after hundreds of expansions. (A point on a face two touching obstacles share lies
    inside their union: :meth:`World.check_point` refuses it first.)"""
    shown = world._fmt(p) if given is None else world._fmt_frame(given)
    fix = "a turning vehicle's path keeps clear of every edge: move it off the edge"
    if len(world.obstacles):
        touch = world.tree.query(shapely.Point(p), predicate="intersects")
        if len(touch):
            raise QueryError(f"{what} {shown} lies on the edge of obstacle "
                             f"{world.names[int(touch.min())]!r}; {fix}")
    e = index.edges
    if len(e) and _gap(e, p) <= index.eps:
        raise QueryError(f"{what} {shown} lies within {index.eps:.1g} of an obstacle's or "
                         f"the boundary's edge; {fix}")


def _gap(edges: np.ndarray, p: np.ndarray) -> float:
    """The distance from point ``p`` to the nearest of the (E, 4) segments."""
    a, d = edges[:, :2], edges[:, 2:] - edges[:, :2]
    L2 = np.einsum("ij,ij->i", d, d)
    t = np.clip(np.einsum("ij,ij->i", p - a, d) / np.where(L2 > 0, L2, 1.0), 0.0, 1.0)
    return float(np.hypot(*(a + t[:, None] * d - p).T).min())


def _bucket(world: World) -> float:
    """Edge buckets: about 64 across the world."""
    xmin, ymin, xmax, ymax = world.bounds if (world.boundary is not None or
                                              len(world.obstacles)) else (0, 0, 1, 1)
    return max(xmax - xmin, ymax - ymin) / 64.0


def _across(region) -> float:
    """The longer side of the search region (plane units)."""
    return float(max(region[2] - region[0], region[3] - region[1]))


def _hint(limit: int, default: bool, across: float, r: float) -> str:
    """Why a search ran out of its budget, and what to change."""
    which = "the default max_expansions" if default else "max_expansions"
    return (f"stopped after {limit:,} expansions ({which}); the world is {across:,.0f} "
            f"turning radii across (radius={r:g}), and the states to search grow with "
            f"its square: give a larger max_expansions, or a larger radius")


def _turned(h: float | None) -> float | None:
    return None if h is None else h + math.pi


def _region(world: World, s, g, margin: float) -> tuple[float, float, float, float]:
    if world.boundary is not None:
        return world.bounds
    return world.extent_with([s, g], margin=margin) if len(world.obstacles) else (
        min(s[0], g[0]) - margin, min(s[1], g[1]) - margin,
        max(s[0], g[0]) + margin, max(s[1], g[1]) + margin)


def _options(radius, heading_bins, step, reverse, max_expansions, seed, smooth):
    """The options checked (numpy numbers and 0-d arrays read as numbers), each error
    naming its parameter."""
    try:
        r = real("radius", radius, low=0.0, strict=True)
    except OptionError:
        raise OptionError(f"radius={radius!r} must be > 0 and finite", param="radius") \
            from None
    H = whole("heading_bins", heading_bins, low=4)
    if step is None:
        arc = r * 2 * math.pi / H
        step = arc * max(1, round(H / 18))
    else:
        try:
            step = real("step", step, low=0.0, strict=True, high=math.pi * r)
        except OptionError:
            raise OptionError(f"step={step!r} must be in (0, pi * radius] = "
                              f"(0, {math.pi * r:g}]", param="step") from None
    flag("reverse", reverse)
    flag("smooth", smooth)
    check_seed(seed)
    return r, H, float(step), budget(max_expansions)


def _pose(p, what: str) -> tuple[np.ndarray, float | None]:
    """(x, y) array and heading (None when absent) of a start or goal."""
    try:
        vals = [v[()] if isinstance(v, np.ndarray) and v.ndim == 0 else v for v in p]
    except TypeError:
        raise QueryError(f"{what}={p!r} must be (x, y) or (x, y, heading)") from None
    if len(vals) not in (2, 3) or not all(
            isinstance(v, numbers.Real) and not isinstance(v, bool | np.bool_) for v in vals):
        raise QueryError(f"{what}={p!r} must be (x, y) or (x, y, heading) numbers")
    if not all(math.isfinite(float(v)) for v in vals):
        raise QueryError(f"{what}={p!r} must be finite numbers")
    xy = np.array([float(vals[0]), float(vals[1])])
    return xy, (float(vals[2]) if len(vals) == 3 else None)


def _in_plane(world: World, xy: np.ndarray, heading: float | None):
    """A pose read in the world's frame, in its plane."""
    p = world.to_plane(xy, "pose")[0]
    return p, (None if heading is None else float(world.heading_to_plane(heading)))


def _xy(p, what: str) -> tuple[float, float]:
    xy, h = _pose(p, what)
    if h is not None:
        raise QueryError(f"{what}={p!r} must be (x, y)")
    return float(xy[0]), float(xy[1])
