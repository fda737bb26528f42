"""Tours: visit several targets with a vehicle that turns no tighter than a radius, in
the order and with the arrival headings that make the flown length shortest.

A target may be reached on any heading; the search picks one of ``headings`` evenly
spaced arrival headings per target. Leg costs are Dubins lengths (free space) or, among
obstacles, max(Dubins length, shortest 2D distance round the obstacles), a lower bound
on the leg Hybrid A* then flies. With those costs:

- up to ``exact_limit`` (12) targets, Held-Karp dynamic programming over subsets gives
  the exact optimum over the heading set (:func:`skyroute.motion.tour_dp.held_karp`;
  0.14 s for 12 targets and 16 headings);
- beyond, nearest-first order improved by 2-opt and or-opt moves, each candidate order
  scored with its best headings by a chain DP (:func:`~skyroute.motion.tour_dp.improve`).

The seed's drone visited targets greedily, nearest first (straight-line distance), each
leg the shortest Dubins path from where it was; ``greedy_length`` is that baseline over
the same heading set, for comparison (docs/benchmarks.md).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from skyroute.errors import QueryError, check_instance, check_seed, real, whole
from skyroute.keywords import strict_keywords, unknown_keywords
from skyroute.motion import hybrid
from skyroute.motion.dubins_kernel import TURNS, shortest_length, words
from skyroute.motion.pieces import chain, check_samples, sample
from skyroute.motion.tour_dp import held_karp, improve, nearest_first
from skyroute.result import Status
from skyroute.world.points import as_points
from skyroute.world.world import World

# numba caches these kernels with dubins_kernel's code compiled in, keyed by this
# file's date alone: edit this file when dubins_kernel changes (as for ZERO, its
# rounding rule), or a checkout keeps running the old words from the cache.

TWO_PI = 2 * math.pi


@dataclass(frozen=True)
class TourResult:
    """A tour: ``order`` (target indices as given, in visiting order), ``headings`` (the
    arrival heading at each target in visiting order: ``headings[i]`` at
    ``targets[order[i]]``, radians in the world's convention, or anticlockwise from +x
    without a world; the tour ends on the last one), ``legs`` (free space: lists of
    :class:`Piece`; among obstacles: :class:`~skyroute.motion.hybrid.HybridResult`),
    flown ``length``, ``method`` ("exact" or "local search"), ``bound`` (the tour's cost
    in the leg table: its length in free space, a lower bound among obstacles) and
    ``greedy_bound`` (nearest-first's cost in the same table)."""

    status: Status
    order: tuple[int, ...]
    headings: np.ndarray
    legs: tuple
    length: float
    method: str
    bound: float
    greedy_bound: float
    seconds: float
    extra: dict = field(default_factory=dict, compare=False)

    @property
    def found(self) -> bool:
        """True when every leg was flown."""
        return self.status is Status.FOUND

    def sample(self, step: float) -> np.ndarray:
        """(K, 3) poses along the whole tour (the world's frame among obstacles)."""
        if not self.found:
            return np.empty((0, 3))
        step = real("step", step, low=0.0, strict=True)
        check_samples(self.length, step)
        parts = []
        for leg in self.legs:
            poses = leg.sample(step) if isinstance(leg, hybrid.HybridResult) else \
                sample(leg, step, leg[0].start) if leg else np.empty((0, 3))
            parts.append(poses if not parts else poses[1:])
        return np.vstack(parts) if parts else np.empty((0, 3))


@njit(cache=True)
def _leg(sx, sy, sth, gx, gy, gth, r):
    """:func:`shortest_length` as a call of its own: inlined twice into the table's
    loops it made one function that took 16-27 s to compile (now about 1 s; the call
    costs nothing next to the trigonometry)."""
    return shortest_length(sx, sy, sth, gx, gy, gth, r)


@njit(cache=True)
def _dubins_table(starts, pts, cand, r):
    """c0 from the start pose to every (target, heading), C between them (inf on the
    same target)."""
    n, H = len(pts), len(cand)
    P = n * H
    c0 = np.empty(P)
    C = np.full((P, P), np.inf)
    for p in range(P):
        k, h = p // H, p % H
        c0[p] = _leg(starts[0], starts[1], starts[2], pts[k, 0], pts[k, 1], cand[h], r)
        for q in range(P):
            j, g = q // H, q % H
            if j != k:
                C[p, q] = _leg(pts[k, 0], pts[k, 1], cand[h], pts[j, 0], pts[j, 1],
                               cand[g], r)
    return c0, C


@strict_keywords
def tour(start_pose, targets, radius: float, *, world: World | None = None,
         headings: int = 16, exact_limit: int = 12, max_expansions: int | None = None,
         seed: int = 0, **misspelt) -> TourResult:
    """The shortest tour from ``start_pose`` (x, y, heading) through every target (x, y).

    The start heading is given, not chosen (``fly --targets`` without one starts on 0);
    each arrival heading is chosen among ``headings`` evenly spaced ones.
    Without ``world``: plane coordinates, heading in radians anticlockwise from +x, legs
    are Dubins paths. With ``world``: points in the world's frame and headings in
    radians in its convention (clockwise from north in "lonlat" and "ned", anticlockwise
    from +x in "enu" and "degrees"), and each leg is flown by
    :func:`skyroute.motion.hybrid.plan` (``max_expansions``, ``seed``) to the chosen
    arrival heading. A leg it finds no path for (a target reached heading into a wall
    is a dead end, which the table's lower bounds do not see) takes its arcs out of the
    table and the tour is solved again (``extra["repairs"]`` counts these); a leg out of
    budget makes the tour's status. ``no_path`` with no legs: no order has a finite cost
    (a target walled off).
    """
    if misspelt:
        raise unknown_keywords(tour, misspelt)
    t0 = time.perf_counter()
    radius = real("radius", radius, low=0.0, strict=True)  # numpy numbers too
    headings = whole("headings", headings, low=1, high=72)
    exact_limit = whole("exact_limit", exact_limit, low=0)
    seed = check_seed(seed)  # as hybrid.plan reads it (also when no leg needs it)
    start = as_points(start_pose, "start_pose", dims=3)[0]
    pts = as_points(targets, "targets")
    if len(pts) == 0:
        raise QueryError("targets must hold at least one (x, y) point")
    s = start.copy()
    if world is not None:
        check_instance("world", world, World, "a skyroute World (or None: no obstacles)")
        s[:2] = world.check_point(start[:2], "start_pose")
        s[2] = float(world.heading_to_plane(start[2]))
        plane = np.array([world.check_point(p, f"targets[{i}]") for i, p in enumerate(pts)])
    else:
        plane = pts
    n, H = len(plane), headings
    cand = np.arange(H) * TWO_PI / H
    c0, C = _dubins_table(s, plane, cand, float(radius))
    if world is not None:
        c0, C = _with_obstacles(world, s, plane, H, c0, C)
    dist0 = np.hypot(*(plane - s[:2]).T)
    D = np.hypot(*(plane[:, None] - plane[None]).transpose(2, 0, 1))
    greedy_bound, greedy = nearest_first(c0, C, dist0, D, n, H)
    method = "exact" if n <= exact_limit else "local search"
    flown: dict = {}  # (place before or -1 for the start, place) -> HybridResult
    repairs = 0
    while True:
        if n <= exact_limit:
            bound, places = held_karp(c0, C, n, H)
        else:
            bound, places = improve(greedy // H, c0, C, H, 50)
        if not math.isfinite(bound):  # no order in the table: a target walled off in
            # 2D (Held-Karp's places are then no tour), or every way cut below
            return TourResult(Status.NO_PATH, (), np.empty(0), (), math.inf, method,
                              math.inf, float(greedy_bound), time.perf_counter() - t0,
                              {"headings": H, "targets": n, "repairs": repairs})
        legs, status, length, failed = _fly(world, s, plane, places, cand, float(radius),
                                            max_expansions, seed, flown)
        if status is not Status.NO_PATH or not _cut(c0, C, places, failed, legs[-1]):
            break
        repairs += 1
    order = tuple(int(p // H) for p in places)
    heads = cand[places % H]
    out_heads = heads if world is None else world.heading_from_plane(heads)
    return TourResult(status, order, np.asarray(out_heads, dtype=float), tuple(legs), length,
                      method, float(bound), float(greedy_bound), time.perf_counter() - t0,
                      {"headings": H, "targets": n, "repairs": repairs})


def _cut(c0, C, places, failed: int, leg) -> bool:
    """Take out of the leg table (in place) the arcs that made leg ``failed`` of the tour
    ``places`` a ``no_path``, so the next order avoids them; False when the tour cannot
    be flown at all (the start pose is boxed in).

    A target reached on one heading may be a dead end (facing a wall a metre away, no
    turn gets out) or reachable from nowhere (a wall behind it), which the table's lower
    bounds do not see. Hybrid A* says which end ran out of states
    (``extra["closed"]``): a start boxed in (its search ran out within the few hundred
    expansions of the reversed one) loses every arc out of its place, which may still end
    the tour; otherwise the goal's place loses every arc into it. Each cut removes arcs
    the tour used, so the repairs end, after at most two per place."""
    a = places[failed - 1] if failed else -1
    b = places[failed]
    if leg.extra.get("closed") == "start" and \
            leg.extra.get("closed_after", math.inf) <= hybrid._REVERSE_BUDGET:
        if a < 0:
            return False
        C[a, :] = math.inf
    else:
        c0[b] = math.inf
        C[:, b] = math.inf
    return True


def _with_obstacles(world, s, plane, H, c0, C):
    """Leg costs among obstacles: max(Dubins, shortest 2D distance round them)."""
    from skyroute.roadmap.world_plan import visibility_graph

    graph = visibility_graph(world)
    pts = np.vstack([s[:2], plane])
    m = len(pts)
    d2 = np.zeros((m, m))
    for a in range(m):
        for b in range(a + 1, m):
            r = graph.plan(pts[a], pts[b])
            d2[a, b] = d2[b, a] = r.cost if r.found else math.inf
    c0 = np.maximum(c0, np.repeat(d2[0, 1:], H))
    C = np.maximum(C, np.repeat(np.repeat(d2[1:, 1:], H, axis=0), H, axis=1))
    return c0, C


def _fly(world, s, plane, places, cand, r, max_expansions, seed, flown):
    """The legs in visiting order (Dubins pieces, or Hybrid A* among obstacles), the
    status, the length and the index of the leg that failed (len(places) when none).
    ``flown`` keeps the Hybrid A* legs by (place before, place) for a repaired order."""
    legs, length, pose, prev = [], 0.0, tuple(float(v) for v in s), -1
    H = len(cand)
    for i, p in enumerate(places):
        p = int(p)
        goal = (float(plane[p // H, 0]), float(plane[p // H, 1]), float(cand[p % H]))
        if world is None:
            lens, total = words(*pose, *goal, r)
            w = int(np.argmin(total))
            leg = chain(pose, TURNS[w], lens[w], r)
            legs.append(leg)
            length += float(total[w])
        else:
            if (prev, p) not in flown:
                a = (*world.from_plane([pose[:2]])[0], float(world.heading_from_plane(pose[2])))
                b = (*world.from_plane([goal[:2]])[0], float(world.heading_from_plane(goal[2])))
                flown[prev, p] = hybrid.plan(world, a, b, r, max_expansions=max_expansions,
                                             seed=seed)
            leg = flown[prev, p]
            legs.append(leg)
            if not leg.found:
                return legs, leg.status, math.inf, i
            length += leg.length
        pose, prev = goal, p
    return legs, Status.FOUND, length, len(places)
