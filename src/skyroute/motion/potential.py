"""Potential-field robots: attraction to the goal, repulsion from what a sensor sees.

Each move senses ``sensor_rays`` rays out to ``sensor_range``, sums a conic attraction
(unit vector to the goal) and the classic repulsion ``k (1/d - 1/range) / d^2`` from each
hit (Khatib 1986), and steps ``step`` along the resulting direction (steepest descent).
The plain field stalls in local minima: a C-shaped obstacle opening towards the robot
traps it. The escape follows a navigation function instead: the wavefront distance to
the goal over the rasterised free space (scipy Dijkstra on the 8-connected free cells),
which has no local minima (Barraquand & Latombe 1991), until the robot is clear, then
hands back to the field. It takes over whenever the field cannot move on (stalled, no
force, or its move blocked), and runs twice as long each time the field has fallen
back into a trap. A run that stops short says why (:attr:`FieldRun.why`).

Two ways to move (``mode``): ``step`` jumps ``step`` along the force; ``arc`` gives the
robot a heading it cannot change by more than ``max_turn`` per move, drives a circular
arc that turns towards the force, and makes fractional progress: the arc is ``step``
long scaled by cos(heading error) (at least a quarter step), so the robot slows into
sharp turns and speeds up when aligned, as a wheeled robot does.

Distances are plane units (degrees in the "degrees" frame); the defaults are metres
(:data:`DEFAULTS`) taken into them, so they fit a world in any frame.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np
import shapely

from skyroute.caches import register
from skyroute.errors import OptionError, check_choice, check_instance, flag, real, whole
from skyroute.keywords import strict_keywords, unknown_keywords
from skyroute.result import Status
from skyroute.world.world import World

COURSES = ("easy", "medium", "hard")
MODES = ("step", "arc")
#: :func:`run_field`'s distance defaults in metres (``repulse`` in cubic metres), taken
#: into a world's plane units when left out (degrees in the "degrees" frame)
DEFAULTS = {"step": 0.5, "sensor_range": 6.0, "tolerance": 0.5, "repulse": 60.0}
ARC_SAMPLES = 4  # points per arc, for collision checks and the drawn trace
#: how far (cells) the escape looks for a cell of the navigation function when none of
#: the robot's own neighbours has a way to the goal (the robot is in the clearance that
#: the raster takes off round the obstacles)
ESCAPE_REACH = 4
#: the most cells the escape's raster may have: its wavefront is a scipy Dijkstra over a
#: sparse graph of the cells, about 235 bytes a cell at its peak (2,000 x 2,000 cells:
#: 0.95 GB, 2.5 s), where the grid planners' compiled searches take MAX_CELLS
ESCAPE_MAX_CELLS = 1 << 22


@dataclass(frozen=True)
class FieldRun:
    """A run: poses (K, 2), how it ended (``status``: found when the goal was reached,
    budget_exhausted after ``max_moves``, stuck when no move led on), how, and ``why``
    it did not reach the goal (one sentence; empty when it did)."""

    path: np.ndarray  # in the world's frame
    status: Status
    escaped: int  # moves taken on the navigation function
    trace: np.ndarray | None = None  # arc mode: the arcs sampled (world's frame), for plots
    distance: float = 0.0  # length flown, plane units (along the arcs in arc mode)
    smoothness: float = 0.0  # mean absolute heading change per move, radians
    why: str = ""  # why the goal was not reached; empty when it was

    def __repr__(self) -> str:
        """A summary, not the poses."""
        why = f": {self.why}" if self.why else ""
        return (f"<FieldRun {self.status.value}, {self.moves} moves, length "
                f"{self.distance:.6g}, {self.escaped} escape moves{why}>")

    @property
    def reached(self) -> bool:
        """True when the goal was reached."""
        return self.status is Status.FOUND

    @property
    def found(self) -> bool:
        """:attr:`reached`, under the name every other result uses."""
        return self.reached

    @property
    def moves(self) -> int:
        return max(0, len(self.path) - 1)


    def metrics(self) -> dict:
        """Length, moves, smoothness, reached, status, escape moves; and ``why`` when the
        goal was not reached."""
        out = {"length": self.distance, "moves": self.moves,
               "smoothness": self.smoothness, "reached": self.reached,
               "status": self.status.value, "escape_moves": self.escaped}
        if self.why:
            out["why"] = self.why
        return out


def course(name: str) -> tuple[World, np.ndarray, np.ndarray]:
    """A built-in course: (world, start, goal) in a 60 x 60 m box."""
    check_choice("course", name, COURSES)
    if name == "easy":
        boxes = [shapely.box(25, 22, 33, 30)]
    elif name == "medium":
        # boxes alternating above and below the straight line: a slalom, no trap
        boxes = [shapely.box(x, y, x + 5, y + 5) for x, y in
                 ((12, 32), (20, 23), (28, 33), (36, 22), (44, 32))]
    else:  # a C opening towards the start, the goal behind it
        boxes = [shapely.box(30, 15, 34, 45), shapely.box(18, 41, 34, 45),
                 shapely.box(18, 15, 34, 19)]
    n = len(boxes)
    world = World(np.array(boxes, dtype=object), np.full(n, -np.inf), np.full(n, np.inf),
                  (), shapely.box(0, 0, 60, 60), "enu", name=f"{name} course")
    return world, np.array([5.0, 30.0]), np.array([52.0, 30.0])


def _sense(world: World, p: np.ndarray, sensor_range: float, rays: int) -> np.ndarray:
    """(K, 2) nearest hit point along each ray that meets an obstacle within range."""
    ang = np.arange(rays) * 2 * math.pi / rays
    ends = p + sensor_range * np.c_[np.cos(ang), np.sin(ang)]
    lines = shapely.linestrings(np.stack([np.broadcast_to(p, ends.shape), ends], axis=1))
    near = _near_edges(world, p, sensor_range)
    if len(near) == 0:
        return np.empty((0, 2))
    # each ray against each outline in range, the nearest hit kept: the same points as
    # against the union of every outline, which cost 50 ms a sense in the FCND city
    hit = shapely.intersection(lines[:, None], near[None, :])
    d = shapely.distance(shapely.Point(p), hit)
    d = np.where(shapely.is_empty(hit) | ~np.isfinite(d), np.inf, d).min(axis=1)
    ok = np.isfinite(d)
    return p + (d[ok] / sensor_range)[:, None] * (ends[ok] - p)


_OUTLINE_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
register(_OUTLINE_CACHE.clear)


def _near_edges(world: World, p: np.ndarray, reach: float) -> np.ndarray:
    """The outlines (obstacles' boundaries and the boundary's exterior) whose boxes come
    within ``reach`` of ``p`` (the obstacles' STRtree; outlines cached per world)."""
    if world not in _OUTLINE_CACHE:
        rings = shapely.boundary(world.obstacles) if len(world.obstacles) else \
            np.empty(0, dtype=object)
        outer = None if world.boundary is None else shapely.Polygon(world.boundary).exterior
        _OUTLINE_CACHE[world] = (np.asarray(rings, dtype=object), outer)
    rings, outer = _OUTLINE_CACHE[world]
    near = rings[world.tree.query(shapely.box(*(p - reach), *(p + reach)))] if len(rings) \
        else rings
    return near if outer is None else np.append(near, outer)


_EDGE_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
register(_EDGE_CACHE.clear)


def _edges(world: World):
    """Obstacle and boundary edges as one prepared geometry (cached per world)."""
    if world not in _EDGE_CACHE:
        geoms = list(world.obstacles)
        if world.boundary is not None:
            geoms.append(shapely.Polygon(world.boundary).exterior)
        e = shapely.unary_union([shapely.boundary(g) if g.geom_type != "LinearRing" else g
                                 for g in geoms])
        shapely.prepare(e)
        _EDGE_CACHE[world] = e
    return _EDGE_CACHE[world]


def _escape_box(world: World, goal: np.ndarray, r: float, points: np.ndarray) -> tuple:
    """The escape raster's bounds (see :func:`_navigation`); an OptionError naming
    ``step`` when it would pass :data:`ESCAPE_MAX_CELLS` cells of side ``r``."""
    box = _raster_box(world, goal, r, points)
    if not _fits(box, r):
        over = ("the boundary" if world.boundary is not None else
                "the obstacles, the start, the robot and the goal")
        # its cells are a step wide: the caller has no resolution to change
        raise OptionError(f"step={r:g} makes the escape's raster (cells a step wide over "
                          f"{over}, {box[2] - box[0]:.6g} x {box[3] - box[1]:.6g} across) "
                          f"more than {ESCAPE_MAX_CELLS:,} cells; use a larger step, or "
                          "turn the escape off", param="step")
    return box


def _raster_box(world: World, goal: np.ndarray, r: float, points: np.ndarray) -> tuple:
    """The escape raster's bounds, unchecked (:func:`_escape_box`)."""
    box = world.extent_with(np.vstack([points, goal]), margin=4 * r)
    if world.boundary is None:
        box = (box[0] - 4 * r, box[1] - 4 * r, box[2] + 4 * r, box[3] + 4 * r)
    return box


def _fits(box: tuple, r: float) -> bool:
    """Whether a raster over ``box`` with cells of side ``r`` has at most
    :data:`ESCAPE_MAX_CELLS` cells."""
    cells = (box[2] - box[0]) / r * ((box[3] - box[1]) / r)
    return math.isfinite(cells) and cells <= ESCAPE_MAX_CELLS


def _navigation(world: World, goal: np.ndarray, resolution: float, points: np.ndarray):
    """Wavefront distance to the goal per free cell (inf where unreachable), and the grid.

    The raster covers the world's boundary or, without one, the obstacles, ``goal`` and
    ``points`` (where the robot is and was) with 8 cells round them all, as the grid
    planners' rasters do (:func:`~skyroute.roadmap.raster.raster_box`): over the
    obstacles' bounds alone, a goal beyond them fell outside the grid (an IndexError, or
    a negative index that silently wrapped to the far side). The goal itself is the
    wavefront's source, joined to the free cells round it whose centres it sees (the
    eight neighbours of its cell, or further out up to :data:`ESCAPE_REACH` cells when
    none does), so a goal in a cell the clearance blocks is still reached."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    r = resolution
    box = _escape_box(world, goal, r, points)
    grid = world.merged().rasterize(r, safety=r / math.sqrt(2), bounds=box)
    free = ~grid.blocked
    h, w = free.shape
    idx = np.arange(h * w).reshape(h, w)
    rows, cols, lens = [], [], []
    for dx, dy in ((1, 0), (0, 1), (1, 1), (1, -1)):
        a = free[max(0, -dy):h - max(0, dy), :w - dx]
        b = free[max(0, dy):h - max(0, -dy) or None, dx:]
        ok = a & b
        if dx and dy:  # no corner cutting
            ok &= free[max(0, -dy):h - max(0, dy), dx:] & free[max(0, dy):h - max(0, -dy)
                                                                  or None, :w - dx]
        ia = idx[max(0, -dy):h - max(0, dy), :w - dx][ok]
        ib = idx[max(0, dy):h - max(0, -dy) or None, dx:][ok]
        rows.append(ia)
        cols.append(ib)
        lens.append(np.full(len(ia), math.hypot(dx, dy) * r))
    gx, gy = grid.to_cell([goal])[0]
    for k in range(1, ESCAPE_REACH + 1):  # wider while no free cell round it sees it
        near = np.array([(x, y) for y in range(gy - k, gy + k + 1)
                         for x in range(gx - k, gx + k + 1)
                         if 0 <= x < w and 0 <= y < h and free[y, x]],
                        dtype=np.int64).reshape(-1, 2)
        centres = grid.to_world(near)
        sees = world.segments_free(np.broadcast_to(goal, centres.shape), centres)
        if sees.any():
            break
    rows.append(idx[near[sees, 1], near[sees, 0]])
    cols.append(np.full(int(sees.sum()), h * w))  # the goal: one node past the cells
    lens.append(np.hypot(*(centres[sees] - goal).T))
    g = coo_matrix((np.concatenate(lens) + 1e-300,
                    (np.concatenate(rows), np.concatenate(cols))),
                   shape=(h * w + 1, h * w + 1)).tocsr()
    dist = dijkstra(g, directed=False, indices=h * w)[:h * w].reshape(h, w)
    return grid, dist


@strict_keywords
def run_field(world: World, start, goal, *, step: float | None = None,
              attract: float = 1.0, repulse: float | None = None,
              sensor_range: float | None = None, sensor_rays: int = 36,
              tolerance: float | None = None, max_moves: int = 2000, escape: bool = True,
              window: int = 40, mode: str = "step", max_turn: float = math.pi / 4,
              heading: float | None = None, **misspelt) -> FieldRun:
    """Descend the field from ``start``; with ``escape``, follow the navigation function
    instead whenever the field cannot move on: when the last ``window`` moves made less
    than two steps of net progress (a local minimum, or circling), when the force
    vanishes, or when its move (and the move half as long) is blocked. Each time the
    escape takes over again, it runs twice as long as the last time, so a trap
    the field keeps falling back into is left for good. In ``arc`` mode the robot starts
    on ``heading`` (radians in the world's frame's convention; default towards the
    goal). Points come in and the run's path goes out in the world's frame. A run that
    does not reach the goal says why in :attr:`FieldRun.why`.

    Distances (``step``, ``sensor_range``, ``tolerance``) are plane units, as every
    distance of a World: metres, or degrees in the "degrees" frame, where the robot
    flies the flat lon/lat plane as it is (a step is as many degrees east as north).
    ``repulse`` multiplies ``(1/d - 1/sensor_range) / d**2`` against an attraction of
    ``attract`` (no unit), so it is plane units cubed. Left out (None), each is its
    default in metres (:data:`DEFAULTS`) taken into the plane's units
    (:meth:`World.metres_in_plane`: in "degrees", over the metres per degree of
    latitude at the world's home), ``repulse`` by the cube of that scale: the defaults
    fit a world in any frame. Before, they were plane units in "degrees" too: a 0.5
    step and tolerance were half a degree (55 km), and every goal of a city was
    "reached" at the start, in 0 moves.
    """
    if misspelt:
        raise unknown_keywords(run_field, misspelt)
    check_instance("world", world, World, "a skyroute World")
    check_choice("mode", mode, MODES)
    p = world.check_point(start, "start")
    t = world.check_point(goal, "goal")
    unit = world.metres_in_plane(1.0, near=p)  # one metre in plane units
    step, sensor_range, tolerance = (DEFAULTS[name] * unit if value is None else value
                                     for name, value in (("step", step),
                                                         ("sensor_range", sensor_range),
                                                         ("tolerance", tolerance)))
    repulse = DEFAULTS["repulse"] * unit ** 3 if repulse is None else repulse
    step, sensor_range, tolerance = (real(name, value, low=0.0, strict=True, need="> 0")
                                     for name, value in (("step", step),
                                                         ("sensor_range", sensor_range),
                                                         ("tolerance", tolerance)))
    attract, repulse = (real(name, value, low=0.0, need=">= 0") for name, value in
                        (("attract", attract), ("repulse", repulse)))
    max_turn = real("max_turn", max_turn, low=0.0, strict=True, high=math.pi,
                    need="in (0, pi] radians")
    sensor_rays = whole("sensor_rays", sensor_rays, low=4, need=">= 4")
    max_moves = whole("max_moves", max_moves, low=0)
    window = whole("window", window, low=1)
    escape = flag("escape", escape)
    heading = None if heading is None else real("heading", heading)
    if escape:  # refused now, not after the moves flown before a first stall
        _escape_box(world, t, step, p[None, :])
    theta = math.atan2(*(t - p)[::-1]) if heading is None else \
        float(world.heading_to_plane(heading))
    path = [p.copy()]
    trace = [p.copy()]
    nav = None
    escaped = 0
    on_nav = 0  # escape moves still to make before the field takes over again
    escapes = 0  # times the escape took over: each next one runs twice as long
    blocked = ""  # why the field could not make its last move ("" when it could)
    why = ""
    while len(path) <= max_moves:
        if math.dist(p, t) < tolerance:
            break
        stalled = len(path) > window and math.dist(path[-1], path[-window]) < 2 * step
        if escape and (stalled or on_nav > 0 or blocked):
            if nav is None or not _holds(nav[0], p):  # made anew where the robot is
                seen = np.array([path[0], p])
                if not _fits(box := _raster_box(world, t, step, seen), step):
                    why = _too_far(world, p, t, step, box)  # (a run's end, not misuse)
                    break
                nav = _navigation(world, t, step, seen)
            q, why = _descend(world, nav, p, t, step)
            if q is None:
                break
            if on_nav == 0:  # taking over from the field
                on_nav = max(1, int(4 * sensor_range / step)) << min(escapes, 20)
                escapes += 1
            on_nav -= 1
            blocked = ""
            if mode == "arc":  # turn-limited here too: steer an arc towards the cell
                arc, theta = _arc(world, p, theta, step, (q - p) / math.dist(p, q),
                                  max_turn, t, tolerance, escape=True,
                                  reach=math.dist(p, q))
                if arc is None:
                    why = ("in arc mode the escape's arc towards the navigation "
                           "function's next cell is blocked however short: the robot "
                           "touches an obstacle")
                    break
                q = arc[-1]
            else:
                theta = math.atan2(*(q - p)[::-1])
                arc = np.array([q])
            escaped += 1
        else:
            if stalled:
                why = (f"the field stalled (less than two steps of progress in the last "
                       f"{window} moves) and the escape is off")
                break
            force = _force(world, p, t, attract, repulse, sensor_range, sensor_rays)
            if force is None:
                arc, blocked = None, "attraction and repulsion cancel"
            elif mode == "step":
                arc = _straight(world, p, t, step, force)
                blocked = "" if arc is not None else "the move along the field and " \
                                                     "its half are blocked"
            else:
                arc, theta = _arc(world, p, theta, step, force, max_turn, t, tolerance)
                blocked = "" if arc is not None else "the arc along the field and " \
                                                     "its half are blocked"
            if arc is None:
                if escape:
                    continue  # the escape takes the next move
                why = f"{blocked} and the escape is off"
                break
            q = arc[-1]
        path.append(q)
        trace.extend(arc)
        p = q
    status = Status.FOUND if math.dist(p, t) < tolerance else \
        Status.BUDGET_EXHAUSTED if len(path) > max_moves else Status.STUCK
    if status is Status.FOUND:
        why = ""
    elif status is Status.BUDGET_EXHAUSTED:
        why = _out_of_moves(path, t, max_moves, escaped, tolerance, window,
                            step if mode == "arc" else None)
    path, trace = np.array(path), np.array(trace)
    flown = trace if mode == "arc" else path
    return FieldRun(world.from_plane(path), status, escaped,
                    world.from_plane(trace) if mode == "arc" else None,
                    float(np.hypot(*np.diff(flown, axis=0).T).sum()), _smoothness(path),
                    why)


def _too_far(world: World, p: np.ndarray, t: np.ndarray, step: float, box: tuple) -> str:
    """Why the escape cannot take over where the robot is now: a raster holding the
    robot, the start and the goal (``box``) would pass :data:`ESCAPE_MAX_CELLS` cells.
    (The check before the first move sees the start only; an OptionError here lost the
    run's moves and told to use a larger step.)"""
    return (f"the robot flew to {world._fmt(p)}, {math.dist(p, t):.6g} from the goal, "
            f"outside the escape's raster, and one holding it (cells of step={step:g} "
            f"over {box[2] - box[0]:.6g} x {box[3] - box[1]:.6g}) would have more than "
            f"{ESCAPE_MAX_CELLS:,} cells; a larger step makes fewer")


def _out_of_moves(path, t, max_moves, escaped, tolerance, window, step) -> str:
    """Why a run that used up its moves did not arrive: where it ended, and in arc mode,
    when its last ``window`` moves kept passing the goal closer than a move, that."""
    why = (f"max_moves={max_moves} moves made, ending {math.dist(path[-1], t):.6g} from "
           f"the goal ({escaped} on the escape)")
    nearest = float(np.hypot(*(np.array(path[-window:]) - t).T).min())
    if step is not None and nearest < step:
        why += (f"; it kept passing the goal, within {nearest:.3g} of it but never within "
                f"tolerance={tolerance:g}, as turns of at most max_turn per move (over a "
                "quarter move at least) allow: give a larger tolerance or max_turn, or a "
                "shorter step")
    return why


def _smoothness(path: np.ndarray) -> float:
    """Mean absolute heading change per move, radians (0 = dead straight)."""
    d = np.diff(path, axis=0)
    if len(d) < 2:
        return 0.0
    a = np.arctan2(d[:, 1], d[:, 0])
    return float(np.abs((np.diff(a) + math.pi) % (2 * math.pi) - math.pi).mean())


def _force(world, p, t, attract, repulse, sensor_range, sensor_rays) -> np.ndarray | None:
    """Unit direction of attraction plus the sensed repulsion, or None where they cancel."""
    to_goal = t - p
    force = attract * to_goal / np.linalg.norm(to_goal)
    hits = _sense(world, p, sensor_range, sensor_rays)
    if len(hits):
        away = p - hits
        d = np.maximum(np.hypot(*away.T), 1e-9)
        mag = repulse * (1 / d - 1 / sensor_range) / d ** 2 / sensor_rays
        force = force + (mag[:, None] * away / d[:, None]).sum(axis=0)
    norm = np.linalg.norm(force)
    return None if norm < 1e-12 else force / norm


def _straight(world, p, t, step, u) -> np.ndarray | None:
    """A full step along u (landing on the goal when within a step), else half of one."""
    q = p + step * u
    if math.dist(q, t) < step:
        q = t.copy()
    if not world.segment_free(p, q):
        q = p + 0.5 * step * u
        if not world.segment_free(p, q):
            return None
    return q[None, :]


def _arc(world, p, theta, step, u, max_turn, goal, tolerance, *, escape: bool = False,
         reach: float = math.inf):
    """Turn towards u by at most ``max_turn`` along a circular arc whose length is
    ``step`` x max(cos(heading error), 1/4) (at most ``reach``); halve it once if
    blocked. Returns the sampled arc (ARC_SAMPLES, 2) and the new heading, or
    (None, theta).

    Near the goal, four rules keep the robot from circling it for good. An arc is no
    longer than the goal is far (down to a quarter move). Within a move of the goal,
    and no more than ``max_turn`` / 2 off its bearing, the arc ends on the goal (as a
    step does in step mode). An arc that passes within ``tolerance`` of the goal stops
    at its point nearest the goal (the robot has arrived). A goal inside the circle the
    arc turns on (on the side it turns to) cannot be reached by turning on that circle:
    the robot slows to a quarter move, its tightest circle, and when the goal is inside
    even that one, first drives straight on until it is not. With ``escape``, when the
    half arc is blocked too, the arc is cut to half the robot's clearance (its distance
    to the nearest obstacle or boundary edge): an arc shorter than that meets no edge,
    so a robot whose nose nearly touches a wall still turns away from it, a little at a
    time."""
    err = (math.atan2(u[1], u[0]) - theta + math.pi) % (2 * math.pi) - math.pi
    turn = max(-max_turn, min(max_turn, err))
    d = math.dist(p, goal)  # no further than the goal, when it is more than a quarter move
    length = min(step * max(math.cos(err), 0.25), reach, max(d, 0.25 * step))
    tries = []  # (turn, length, lands on the goal)
    bearing = (math.atan2(goal[1] - p[1], goal[0] - p[0]) - theta + math.pi) % \
        (2 * math.pi) - math.pi
    on = d if abs(bearing) < 1e-12 else d * bearing / math.sin(bearing)  # the arc's length
    if on <= step and 2 * abs(bearing) <= max_turn:  # the arc through the goal
        tries.append((2 * bearing, on, True))
    if abs(err) > max_turn:  # it would turn further if it could
        normal = math.copysign(1.0, turn) * np.array([-math.sin(theta), math.cos(theta)])
        tight = 0.25 * step
        if math.dist(p + normal * length / max_turn, goal) < length / max_turn:
            if math.dist(p + normal * tight / max_turn, goal) < tight / max_turn:
                tries += [(0.0, tight, False), (0.0, 0.5 * tight, False)]
            else:
                tries += [(turn, tight, False), (turn, 0.5 * tight, False)]
    tries += [(turn, length, False), (turn, 0.5 * length, False)]
    if escape:
        clearance = float(shapely.distance(shapely.Point(p), _edges(world)))
        if 0 < 0.5 * clearance < 0.5 * length:
            tries.append((turn, 0.5 * clearance, False))
    for turn, length, lands in tries:
        pts = _arc_points(p, theta, length, turn)
        if lands:
            pts[-1] = goal  # on it, not within rounding of it
        if _free(world, p, pts):
            s = _nearest(p, theta, length, turn, goal)
            if not lands and s < length:  # stop where it arrives, when it does
                part = _arc_points(p, theta, s, turn * s / length)
                if math.dist(part[-1], goal) < tolerance and _free(world, p, part):
                    return part, theta + turn * s / length
            return pts, theta + turn
    return None, theta


def _free(world, p, pts) -> bool:
    """The chords from ``p`` through ``pts`` are free."""
    return world.segment_free(p, pts[0]) and all(
        world.segment_free(pts[i], pts[i + 1]) for i in range(len(pts) - 1))


def _nearest(p, theta, length, turn, goal) -> float:
    """How far along the arc (from ``p`` on heading ``theta``, turning ``turn`` over
    ``length``) its point nearest ``goal`` lies: where the radius through the goal
    meets it, or its end."""
    if abs(turn) < 1e-9:
        along = float(np.dot(goal - p, (math.cos(theta), math.sin(theta))))
        return min(max(along, 0.0), length)
    r = length / turn  # signed, as in _arc_points
    c = p + r * np.array([-math.sin(theta), math.cos(theta)])
    heading = math.atan2(goal[1] - c[1], goal[0] - c[0]) + math.copysign(math.pi / 2, turn)
    swept = ((heading - theta) * math.copysign(1.0, turn)) % (2 * math.pi)
    return min(swept / abs(turn) * length, length)


def _arc_points(p, theta, length, turn) -> np.ndarray:
    """(ARC_SAMPLES, 2) points along the arc from ``p`` on heading ``theta`` that turns
    ``turn`` radians over ``length``."""
    s = np.linspace(length / ARC_SAMPLES, length, ARC_SAMPLES)
    if abs(turn) < 1e-9:
        return p + s[:, None] * np.array([math.cos(theta), math.sin(theta)])
    r = length / turn  # signed radius: positive turns left
    a = theta + turn * s / length
    return p + r * np.c_[np.sin(a) - math.sin(theta), math.cos(theta) - np.cos(a)]


def _holds(grid, p: np.ndarray) -> bool:
    """Whether plane point ``p`` lies in a cell of ``grid``."""
    x, y = grid.to_cell([p])[0]
    return 0 <= x < grid.width and 0 <= y < grid.height


def _descend(world: World, nav, p: np.ndarray, t: np.ndarray,
             step: float) -> tuple[np.ndarray | None, str]:
    """Where the escape goes next, and "" (or None and why it cannot go on): the
    neighbouring free cell centre with the lowest wavefront value that the robot sees,
    or onto the goal ``t`` when it is in sight within a diagonal cell (near a wall the
    goal's own cell may be blocked: the cells round it would take turns forever). A
    robot in the raster's clearance round an obstacle may have no such neighbour: it
    heads for the nearest cell it sees within :data:`ESCAPE_REACH` cells that has a way
    to the goal (at most ``step`` towards it)."""
    grid, dist = nav
    if math.dist(p, t) <= grid.resolution * math.sqrt(2) and world.segment_free(p, t):
        return t.copy(), ""
    cx, cy = grid.to_cell([p])[0]
    seen_free = False
    for reach in range(1, ESCAPE_REACH + 1):
        ring = [(cx + dx, cy + dy) for dx in range(-reach, reach + 1)
                for dy in range(-reach, reach + 1) if max(abs(dx), abs(dy)) == reach]
        cells = np.array([(x, y) for x, y in ring
                          if 0 <= x < grid.width and 0 <= y < grid.height
                          and not grid.blocked[y, x]]).reshape(-1, 2)
        if not len(cells):
            continue
        value = dist[cells[:, 1], cells[:, 0]]
        centres = grid.to_world(cells)
        sees = world.segments_free(np.broadcast_to(p, centres.shape), centres)
        seen_free |= bool(sees.any())
        ok = sees & np.isfinite(value)
        if not ok.any():
            continue
        if reach == 1:  # the lowest neighbour: steepest descent
            q = centres[ok][np.argmin(value[ok])]
            return q, ""
        # further out: the nearest, then the lowest; no more than a move towards it
        gap = np.hypot(*(centres[ok] - p).T)
        q = centres[ok][np.lexsort((value[ok], gap))[0]]
        d = math.dist(p, q)
        return (q if d <= step else p + (q - p) * (step / d)), ""
    if seen_free:
        return None, ("the goal is not reachable from here on the navigation function's "
                      f"raster (cells of step={step:g}, obstacles grown by half a cell's "
                      "diagonal): no free cell in sight has a way to the goal (a "
                      "shorter step makes the cells finer)")
    return None, (f"the escape sees no free cell of its raster (cells of step={step:g}, "
                  f"obstacles grown by half a cell's diagonal) within {ESCAPE_REACH} cells")
