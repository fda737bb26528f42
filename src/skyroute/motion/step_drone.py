"""The ILP lunch drone: fixed steps at headings that are multiples of 10 degrees.

Rules (shared/data/ilp2021/SPEC.md 4.1-4.3): positions are (lon, lat) on a flat plane; a
move flies exactly ``step`` = 0.00015 degrees at an angle in {0, 10, ..., 350} (0 east,
anticlockwise) or hovers (angle -999); every move ends strictly inside the confinement
area, and no move may end in, cross or touch a no-fly zone; two points are close when
strictly less than ``step`` apart.

- :func:`plan_moves`: A* in move space, the fewest moves from a point to close to a target.
- :func:`follow`: fly a planned path by rounding headings, trying the nearest other
  headings when the rounded one is blocked (what the course's students did), never
  returning to a spot it has flown through.

Each expansion's 36 moves (and their sight of the target, for the heuristic) are tested
in one compiled call (:mod:`skyroute.motion.zone_kernels`), about 13 us.

Both return a :class:`Flight`: plain arrays of (from, angle, to), hovers included.
"""

from __future__ import annotations

import math
import time
import weakref
from dataclasses import dataclass, field

import numpy as np
import shapely

from skyroute.caches import register
from skyroute.errors import (
    OptionError,
    QueryError,
    budget,
    check_instance,
    real,
    renamed,
    whole,
)
from skyroute.keywords import strict_keywords, unknown_keywords
from skyroute.motion import edge_grid, move_search
from skyroute.motion.zone_kernels import zone_arrays
from skyroute.result import FOUND, STATUS_OF_CODE, Status
from skyroute.search import interrupt
from skyroute.world.geometry import convex_corners
from skyroute.world.world import World

STEP = 0.00015
HOVER = -999
ANGLES = np.arange(0, 360, 10)
MAX_PAIRS = 50_000  # vertex pairs up to which corners are tested pair by pair
MERGE = 5e-6  # positions in one lattice cell this wide (1/30 step) are one state
#: max_expansions=None (:func:`default_budget`): the cap in a world without a boundary,
#: whose states are unbounded, and the cap in one with a boundary (memory and time)
UNBOUNDED_BUDGET = 200_000
MAX_BUDGET = 2_000_000
_CORNER_GRAPHS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_ZONES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_BOUNDS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
for _cache in (_CORNER_GRAPHS, _ZONES, _BOUNDS):
    register(_cache.clear)


@dataclass(frozen=True, eq=False)
class Flight:
    """Moves as data: ``frm`` and ``to`` (N, 2) lon/lat, ``angle`` (N,) ints (the ILP's:
    degrees anticlockwise from east, multiples of 10; not a compass heading), -999 = hover;
    ``start`` where it starts (what a flight of no moves ends at, when it is known)."""

    frm: np.ndarray
    angle: np.ndarray
    to: np.ndarray
    status: Status = Status.FOUND
    expanded: int = 0
    seconds: float = 0.0
    extra: dict = field(default_factory=dict)
    start: np.ndarray | None = None

    def __repr__(self) -> str:
        """A summary, not the moves."""
        hovers = int(np.count_nonzero(self.angle == HOVER)) if len(self.angle) else 0
        return (f"<Flight {self.status.value}, {self.moves} moves ({hovers} hovers), "
                f"{self.expanded} expanded, {self.seconds * 1e3:.3g} ms>")

    @property
    def found(self) -> bool:
        """True when the flight ends where it was asked to (as every result's ``found``)."""
        return self.status is Status.FOUND

    @property
    def moves(self) -> int:
        """Number of moves, hovers included."""
        return len(self.angle)

    @property
    def end(self) -> np.ndarray:
        """Where the flight ends: its start if it has no moves (NaN if that is unknown)."""
        if len(self.to):
            return self.to[-1]
        return np.full(2, np.nan) if self.start is None else np.array(self.start, dtype=float)

    def rows(self) -> list[list[float]]:
        """[[from_lon, from_lat, angle, to_lon, to_lat], ...]."""
        return [[float(f[0]), float(f[1]), int(a), float(t[0]), float(t[1])]
                for f, a, t in zip(self.frm, self.angle, self.to, strict=True)]

    def then(self, other: Flight) -> Flight:
        """This flight followed by ``other``."""
        return Flight(np.vstack([self.frm, other.frm]), np.concatenate([self.angle,
                                                                         other.angle]),
                      np.vstack([self.to, other.to]), other.status,
                      self.expanded + other.expanded, self.seconds + other.seconds,
                      start=self.start if len(self.to) or self.start is not None
                      else other.start)

    def hover(self, at=None) -> Flight:
        """This flight followed by one hover (at its end, or at ``at``)."""
        p = np.asarray(self.end if at is None else at, dtype=float).reshape(1, 2)
        if np.isnan(p).any():  # a flight of no moves that does not know its start
            raise QueryError("a flight of no moves needs the place to hover: hover(at=...)")
        return self.then(Flight(p, np.array([HOVER]), p.copy()))


def _check_world(world: World) -> None:
    check_instance("world", world, World, "a skyroute World")
    if world.frame != "degrees":
        raise OptionError("the step drone flies in the 'degrees' frame (lon/lat as a plane); "
                          "load the world with frame='degrees'")


def legal(world: World, p, step: float = STEP) -> np.ndarray:
    """(36,) bool: which of the 36 headings are legal moves from ``p``."""
    step = real("step", step, low=0.0, strict=True)
    p = world.to_plane(p, "p")
    if len(p) != 1:
        raise QueryError(f"p must be one point (lon, lat), got {len(p)}")
    p = p[0]
    rad = np.radians(ANGLES)
    to = p + step * np.c_[np.cos(rad), np.sin(rad)]
    return world.segments_clear(np.broadcast_to(p, to.shape), to)


class DistanceBound:
    """The table behind A*'s heuristic: the zones' convex corners and each one's shortest
    obstacle-avoiding distance D(v) to one target.

    Built once per world (visibility among the corners) and once per target (Dijkstra).
    The compiled search bounds a point q's distance by |q - t| when q sees t, else by
    min over the corners v that q sees of |q - v| + D(v) (:func:`move_search.bound`),
    reading the corners as ``cols``, (2, N) rows of x and y.
    """

    def __init__(self, world: World, target: np.ndarray) -> None:
        self.world = world
        self.target = np.asarray(target, dtype=float)
        if world not in _CORNER_GRAPHS:
            _CORNER_GRAPHS[world] = _corner_pairs(world)
        table = _CORNER_GRAPHS[world]
        if not isinstance(table, tuple):  # a city's: the visibility graph's corner table
            self.corners = table.corners
            self.dist = table.to(self.target) if len(self.corners) else np.zeros(0)
        else:
            self.corners = table[0]
            self.dist = self._dijkstra(*table)
        self.cols = np.ascontiguousarray(self.corners.T)

    def _dijkstra(self, corners: np.ndarray, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        """D(v) through the free corner pairs (i, j) and the corners the target sees."""
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import dijkstra

        world = self.world
        n = len(corners)
        sees = world.segments_free(np.broadcast_to(self.target, (n, 2)), corners) \
            if n else np.zeros(0, bool)
        rows = np.concatenate([i, np.full(int(sees.sum()), n)])
        cols = np.concatenate([j, np.flatnonzero(sees)])
        w = np.hypot(*(np.vstack([corners, self.target])[rows] -
                       np.vstack([corners, self.target])[cols]).T) + 1e-300
        graph = coo_matrix((w, (rows, cols)), shape=(n + 1, n + 1)).tocsr()
        return dijkstra(graph, directed=False, indices=n)[:n] if n else np.zeros(0)


def _corner_pairs(world: World):
    """The convex corners and the free pairs among them, each pair tested by shapely,
    where the obstacles' vertices make at most :data:`MAX_PAIRS` pairs (the ILP map's
    zones have a few dozen corners). A city's corners are too many for that (the FCND
    city: 3,534 corners, 6.2 million pairs at about 0.4 ms each, 45 minutes and 3 GB
    before the first move): there the corner table of
    :mod:`skyroute.motion.corner_distance` (the visibility graph's, compiled, kept on
    disk) serves, and where that table refuses the world's size no corners, the
    straight-line bound (still a lower bound: A* stays exact, with more expansions)."""
    from skyroute.motion.corner_distance import CornerGraph, corner_graph

    v = int(shapely.get_num_coordinates(world.obstacles).sum())  # >= the corners
    if v * (v - 1) // 2 > MAX_PAIRS:
        try:
            return corner_graph(world)
        except OptionError:  # more corners than its table holds
            return CornerGraph(np.zeros((0, 2)), np.zeros((0, 0)), np.zeros((0, 4)))
    corners = convex_corners(world.merged())[0]
    n = len(corners)
    i, j = np.triu_indices(n, 1)
    ok = world.segments_free(corners[i], corners[j]) if n else np.zeros(0, bool)
    return corners, i[ok], j[ok]


def _bound(world: World, t: np.ndarray) -> DistanceBound:
    """The corner table for target ``t`` (kept per world: delivery legs share targets)."""
    tables = _BOUNDS.setdefault(world, {})
    key = (float(t[0]), float(t[1]))
    if key not in tables:
        if len(tables) > 256:
            tables.clear()
        tables[key] = DistanceBound(world, t)
    return tables[key]


def _zones(world: World) -> tuple:
    """The compiled kernels' view of the zones (cached per world): edges, owner, zone
    count, boundary edges, and the edges' bucket grid (meta, start, ids)."""
    z = _ZONES.get(world)
    if z is None:
        edges, owner, bedges = zone_arrays(world)
        z = _ZONES[world] = (edges, owner, len(world.obstacles), bedges, *edge_grid.build(edges))
    return z


def _coarse(p: np.ndarray, step: float) -> tuple[int, int]:
    """A spot a third of a ``step`` wide, for follow()'s loop detection (of the step
    flown: spots of the ILP step made any step under a third of it land on its own)."""
    return round(p[0] / (step / 3)), round(p[1] / (step / 3))


def default_budget(world: World, merge: float = MERGE) -> int:
    """plan_moves' budget for ``max_expansions=None``: enough to finish the search, capped
    to protect memory. In a world with a boundary, every state its search can hold (the
    ``merge``-wide lattice cells of the boundary's box: a state is expanded once, so the
    search ends found or no_path), capped at :data:`MAX_BUDGET` (2,000,000); without a
    boundary the states are unbounded and the cap is :data:`UNBOUNDED_BUDGET` (200,000).
    The ILP area at the default merge: 1,183,200 (1,632 x 725 cells)."""
    if world.boundary is None:
        return UNBOUNDED_BUDGET
    x0, y0, x1, y1 = shapely.Polygon(world.boundary).bounds
    cells = (math.floor((x1 - x0) / merge) + 2) * (math.floor((y1 - y0) / merge) + 2)
    return int(min(cells, MAX_BUDGET))


@strict_keywords
def plan_moves(world: World, start, goal=None, *, step: float = STEP,
               max_expansions: int | None = None, merge: float = MERGE,
               target=None, **misspelt) -> Flight:
    """The fewest moves from ``start`` to a position strictly closer than ``step`` to
    ``goal`` (A* over positions reachable by steps; positions in one ``merge``-wide
    lattice cell are one state, which on the ILP map gives the same move counts as
    merging 2.5x finer, see docs/benchmarks.md).

    h = max(0, ceil(d / step - 1)) where d is a lower bound on the obstacle-avoiding
    distance to the goal (:class:`DistanceBound`): admissible, since each move covers
    at most ``step`` and the flight may stop within ``step`` of the goal. Ties go to
    the deeper node. No path is a status, not an exception, and so is running out of
    ``max_expansions`` (None: enough to finish the search, capped to protect memory:
    :func:`default_budget`, every state of a bounded world such as the ILP area, where
    a fixed 200,000 ran out on a legal pair that needs 215,220, capped at
    :data:`MAX_BUDGET`, 2,000,000; without a boundary :data:`UNBOUNDED_BUDGET`, 200,000;
    a number beyond an int64 is no budget, as for every planner). The whole search is
    one compiled call (:mod:`skyroute.motion.move_search`), which Ctrl-C interrupts.
    """
    if misspelt:
        raise unknown_keywords(plan_moves, misspelt)
    _check_world(world)
    goal = renamed("goal", goal, "target", target)
    if goal is None:
        raise OptionError("plan_moves needs a goal", param="goal")
    step = real("step", step, low=0.0, strict=True)
    merge = real("merge", merge, low=0.0, strict=True)
    max_expansions = default_budget(world, merge) if max_expansions is None else \
        budget(max_expansions)
    t0 = time.perf_counter()
    s = world.check_point(start, "start")
    t = world.to_plane(goal, "goal")
    if len(t) != 1:
        raise QueryError(f"goal must be one point (lon, lat), got {len(t)}")
    t = t[0]
    rad = np.radians(ANGLES)
    deltas = step * np.c_[np.cos(rad), np.sin(rad)]
    bound = _bound(world, t)
    sees0 = bool(world.segments_free([s], [t])[0])
    status, end, expanded, x, y, parent, move = interrupt.run(
        move_search.search, s[0], s[1], t[0], t[1], sees0, deltas, *_zones(world),
        bound.cols, bound.dist, step, merge, max_expansions, 1e-12)
    seconds = time.perf_counter() - t0
    if status != FOUND:
        return _empty(s, STATUS_OF_CODE[status], expanded, seconds)
    chain = []
    i = end
    while parent[i] >= 0:
        chain.append(i)
        i = parent[i]
    chain = np.array(chain[::-1], dtype=np.int64)
    pos = np.c_[x, y]
    return Flight(pos[parent[chain]].reshape(-1, 2), ANGLES[move[chain]].astype(int),
                  pos[chain].reshape(-1, 2), Status.FOUND, expanded, seconds,
                  start=s.copy())


def _empty(s, status, expanded, seconds) -> Flight:
    e = np.empty((0, 2))
    return Flight(e, np.empty(0, int), e.copy(), status, expanded, seconds, start=s.copy())


def follow(world: World, path, *, step: float = STEP, max_moves: int = 1500) -> Flight:
    """Fly the polyline ``path`` (lon/lat) waypoint by waypoint: each move takes the
    heading to the current waypoint rounded to 10 degrees, or the nearest legal one to
    it; a waypoint counts as reached when the drone is closer than ``step``."""
    _check_world(world)
    step = real("step", step, low=0.0, strict=True)
    max_moves = whole("max_moves", max_moves, low=0)
    t0 = time.perf_counter()
    pts = world.to_plane(path, "path") if np.size(path) else np.empty((0, 2))
    if len(pts) == 0:
        raise QueryError("path must hold at least one (lon, lat) point")
    p = pts[0].copy()
    frm, ang, to = [], [], []
    target = 1
    rad = np.radians(ANGLES)
    deltas = step * np.c_[np.cos(rad), np.sin(rad)]
    visited = {_coarse(p, step)}
    stuck = False
    while target < len(pts) and len(ang) < max_moves:
        if math.hypot(*(pts[target] - p)) < step:
            target += 1
            continue
        want = math.degrees(math.atan2(*(pts[target] - p)[::-1])) % 360
        ok = legal(world, p, step)
        diff = np.abs((ANGLES - want + 180) % 360 - 180)
        order = np.argsort(diff, kind="stable")
        # nearest legal heading that does not return to a spot already flown through
        k = next((int(k) for k in order
                  if ok[k] and _coarse(p + deltas[k], step) not in visited), None)
        if k is None:
            stuck = True
            break
        q = p + deltas[k]
        frm.append(p)
        ang.append(int(ANGLES[k]))
        to.append(q)
        p = q
        visited.add(_coarse(p, step))
    status = Status.FOUND if target >= len(pts) else \
        Status.NO_PATH if stuck else Status.BUDGET_EXHAUSTED
    return Flight(np.array(frm).reshape(-1, 2), np.array(ang, dtype=int),
                  np.array(to).reshape(-1, 2), status, len(ang), time.perf_counter() - t0,
                  start=pts[0].copy())
