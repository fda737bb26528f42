"""Dubins paths: the shortest way between two poses for a vehicle that only drives
forward and turns no tighter than a radius r (Dubins 1957).

Poses are (x, y, heading) with heading in radians from the x axis, anticlockwise. The
shortest path is one of six words of left (L), straight (S) and right (R) pieces:
LSL, RSR, LSR, RSL, RLR, LRL; their lengths have closed forms (Shkel & Lumelsky 2001,
as in A. Walker's reference implementation). :func:`lengths` evaluates all six for N
queries at once with numpy.

>>> p = shortest_path((0, 0, 0), (10, 0, 0), 1.0)
>>> p.word, round(p.length, 12)
('LSL', 10.0)
>>> q = shortest_path((0, 0, math.pi / 2), (1, 0, -math.pi / 2), 1.0)
>>> q.word, round(q.length, 6)
('LRL', 6.03253)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from skyroute.errors import OptionError, QueryError, flag, real, whole
from skyroute.keywords import strict_keywords, unknown_keywords
from skyroute.motion import dubins_kernel
from skyroute.motion.dubins_batch import lengths_kernel
from skyroute.motion.dubins_kernel import WORDS, ZERO
from skyroute.motion.pieces import MAX_SAMPLES, check_samples
from skyroute.motion.tour import TourResult, tour  # noqa: F401  (skyroute.motion.dubins.tour)
from skyroute.result import Status
from skyroute.world.points import as_points

TWO_PI = 2 * math.pi


def _mod2pi(a):
    """Angle in [0, 2 pi), with float noise around 0 and 2 pi (within 1e-12) snapped to 0:
    a piece of -1e-17 is no turn, not a full circle. OMPL snaps within 5e-7, which also
    erases real turns of that size; 1e-12 only absorbs rounding."""
    m = np.mod(a, TWO_PI)
    return np.where((TWO_PI - m < 1e-12) | ((a < 0) & (a > -1e-12)), 0.0, m)


def _check_radius(radius) -> float:
    """``radius`` as a float > 0, else an OptionError naming it."""
    try:
        return real("radius", radius, low=0.0, strict=True)
    except OptionError:
        raise OptionError(f"radius={radius!r} must be a positive number",
                          param="radius") from None


def _poses(poses, what: str) -> np.ndarray:
    """(x, y, heading) numbers or an (N, 3) array of them, finite, as float (N, 3)."""
    return np.ascontiguousarray(as_points(poses, what, dims=3))


def _words(starts: np.ndarray, goals: np.ndarray, radius: float) -> np.ndarray:
    """(N, 6, 3) normalised segment lengths (t, p, q) of every word; NaN where a word
    does not exist."""
    s = np.asarray(starts, dtype=float).reshape(-1, 3)
    g = np.asarray(goals, dtype=float).reshape(-1, 3)
    dx, dy = g[:, 0] - s[:, 0], g[:, 1] - s[:, 1]
    d = np.hypot(dx, dy) / radius
    phi = np.arctan2(dy, dx)
    a = _mod2pi(s[:, 2] - phi)
    b = _mod2pi(g[:, 2] - phi)
    sa, ca, sb, cb = np.sin(a), np.cos(a), np.sin(b), np.cos(b)
    cab = np.cos(a - b)
    tol = ZERO * (4.0 + d * d)  # rounding: see dubins_kernel.ZERO
    out = np.full((len(s), 6, 3), np.nan)
    with np.errstate(invalid="ignore"):
        # LSL (always exists; one circle, one arc when the centres coincide: see ZERO)
        arc = ZERO * (2.0 + d)
        p = np.hypot(d + sa - sb, cb - ca)
        one = p <= arc
        tmp = np.where(one, a, np.arctan2(cb - ca, d + sa - sb))
        out[:, 0] = np.c_[_mod2pi(-a + tmp), np.where(one, 0.0, p), _mod2pi(b - tmp)]
        # RSR
        p = np.hypot(d - sa + sb, ca - cb)
        one = p <= arc
        tmp = np.where(one, a, np.arctan2(ca - cb, d - sa + sb))
        out[:, 1] = np.c_[_mod2pi(a - tmp), np.where(one, 0.0, p), _mod2pi(-b + tmp)]
        # LSR
        p2 = d * d + 2 * (cab - 1) + 2 * d * (sa + sb)
        p = np.sqrt(np.maximum(p2, 0.0))
        tmp = np.arctan2(-ca - cb, d + sa + sb) - np.arctan2(-2.0, p)
        ok = p2 >= -tol
        out[ok, 2] = np.c_[_mod2pi(-a + tmp), p, _mod2pi(-_mod2pi(b) + tmp)][ok]
        # RSL
        p2 = d * d + 2 * (cab - 1) - 2 * d * (sa + sb)
        p = np.sqrt(np.maximum(p2, 0.0))
        tmp = np.arctan2(ca + cb, d - sa - sb) - np.arctan2(2.0, p)
        ok = p2 >= -tol
        out[ok, 3] = np.c_[_mod2pi(a - tmp), p, _mod2pi(b - tmp)][ok]
        # RLR
        c = (6.0 - d * d + 2 * cab + 2 * d * (sa - sb)) / 8.0
        ok = np.abs(c) <= 1 + ZERO
        p = _mod2pi(TWO_PI - np.arccos(np.clip(c, -1, 1)))
        t = _mod2pi(a - np.arctan2(ca - cb, d - sa + sb) + p / 2)
        out[ok, 4] = np.c_[t, p, _mod2pi(a - b - t + p)][ok]
        # LRL
        c = (6.0 - d * d + 2 * cab + 2 * d * (sb - sa)) / 8.0
        ok = np.abs(c) <= 1 + ZERO
        p = _mod2pi(TWO_PI - np.arccos(np.clip(c, -1, 1)))
        t = _mod2pi(-a - np.arctan2(ca - cb, d + sa - sb) + p / 2)
        out[ok, 5] = np.c_[t, p, _mod2pi(_mod2pi(b) - a - t + p)][ok]
    return out


@strict_keywords
def lengths(starts, goals, radius: float, **misspelt) -> np.ndarray:
    """Shortest Dubins lengths for (N, 3) arrays of start and goal poses (compiled).

    Raises QueryError for poses that are not (N, 3) finite numbers or not as many,
    OptionError for a radius that is not a number > 0."""
    if misspelt:
        raise unknown_keywords(lengths, misspelt)
    r = _check_radius(radius)
    s = _poses(starts, "starts") if np.size(starts) else np.empty((0, 3))
    g = _poses(goals, "goals") if np.size(goals) else np.empty((0, 3))
    if s.shape != g.shape:
        raise QueryError(f"starts {s.shape} and goals {g.shape} must have the same shape")
    return lengths_kernel(s, g, r)


@dataclass(frozen=True)
class DubinsPath:
    """One shortest path: its word, the lengths of its three pieces (metres), and poses."""

    start: tuple[float, float, float]
    goal: tuple[float, float, float]
    radius: float
    word: str
    segments: tuple[float, float, float]

    @property
    def length(self) -> float:
        """Total length."""
        return float(sum(self.segments))

    @property
    def status(self) -> Status:
        """Always found: without obstacles a Dubins path joins any two poses."""
        return Status.FOUND

    @property
    def found(self) -> bool:
        """Always True (see :attr:`status`), as every result's ``found``."""
        return True

    def pose_at(self, s: float) -> np.ndarray:
        """(x, y, heading) after travelling ``s`` along the path (0 <= s <= length)."""
        return self.sample_at(np.array([real("s", s)]))[0]

    def sample_at(self, s: np.ndarray) -> np.ndarray:
        """(K, 3) poses at arc lengths ``s`` (clipped to [0, length]; a 1-D array)."""
        try:
            s = np.asarray(s, dtype=float)
        except (TypeError, ValueError):
            raise QueryError(f"s={s!r} must be arc lengths (numbers)") from None
        if s.ndim != 1 or not np.isfinite(s).all():
            raise QueryError(f"s must be a 1-D array of finite arc lengths, got shape "
                             f"{s.shape}")
        s = np.clip(s, 0.0, self.length)
        out = np.empty((len(s), 3))
        x, y, th = self.start
        r = self.radius
        done = np.zeros(len(s))
        cur = np.tile([x, y, th], (len(s), 1))
        for kind, seg in zip(self.word, self.segments, strict=True):
            step = np.clip(s - done, 0.0, seg)
            cur = _advance(cur, kind, step, r)
            done = done + seg
        out[:] = cur
        out[:, 2] = _mod2pi(out[:, 2])
        return out

    def sample(self, step: float) -> np.ndarray:
        """Poses every ``step`` metres; the first sample is exactly the start and the last
        exactly the goal. More than :data:`MAX_SAMPLES` poses is an OptionError."""
        step = real("step", step, low=0.0, strict=True)
        check_samples(self.length, step)
        n = math.floor(self.length / step + 1e-12)
        s = np.arange(n + 1) * step
        if s[-1] < self.length - 1e-12 or (len(s) == 1 and self.start != self.goal):
            s = np.append(s, self.length)
        poses = self.sample_at(s)
        poses[0] = [self.start[0], self.start[1], self.start[2] % TWO_PI]
        poses[-1] = [self.goal[0], self.goal[1], self.goal[2] % TWO_PI]
        return poses


def _advance(pose: np.ndarray, kind: str, s: np.ndarray, r: float) -> np.ndarray:
    x, y, th = pose[:, 0], pose[:, 1], pose[:, 2]
    if kind == "S":
        return np.c_[x + s * np.cos(th), y + s * np.sin(th), th]
    turn = s / r if kind == "L" else -s / r
    sign = 1.0 if kind == "L" else -1.0
    nx = x + sign * r * (np.sin(th + turn) - np.sin(th))
    ny = y - sign * r * (np.cos(th + turn) - np.cos(th))
    return np.c_[nx, ny, th + turn]


@strict_keywords
def shortest_path(start, goal, radius: float, **misspelt) -> DubinsPath:
    """The shortest Dubins path from pose ``start`` to pose ``goal`` (x, y, heading) with
    turning ``radius`` > 0. Raises QueryError for a pose that is not three finite
    numbers, OptionError for a bad radius."""
    if misspelt:
        raise unknown_keywords(shortest_path, misspelt)
    r = _check_radius(radius)
    s, g = (_one_pose(p, what) for p, what in ((start, "start"), (goal, "goal")))
    seg, total = dubins_kernel.words(*s, *g, r)  # compiled: one query
    k = int(np.argmin(total))
    return DubinsPath(s, g, r, WORDS[k], tuple(float(v) for v in seg[k]))


def _one_pose(pose, what: str) -> tuple[float, float, float]:
    p = _poses(pose, what)
    if len(p) != 1:
        raise QueryError(f"{what} must be one pose (x, y, heading), got {len(p)}")
    return tuple(float(v) for v in p[0])


def through(points, radius: float, *, start_heading: float | None = None,
            end_heading: float | None = None, headings: int = 36) -> list[DubinsPath]:
    """Dubins paths through (x, y) ``points``, choosing each free heading among
    ``headings`` candidates so the total is shortest (dynamic programming over the
    candidates, each stage one vectorised :func:`lengths` call)."""
    _check_radius(radius)
    headings = whole("headings", headings, low=1)
    pts = as_points(points, "points")
    if len(pts) < 2:
        raise QueryError("points: through() needs at least two points")
    start_heading, end_heading = (None if h is None else real(name, h) for name, h in (
        ("start_heading", start_heading), ("end_heading", end_heading)))
    cand = np.arange(headings) * TWO_PI / headings
    options = [np.array([h]) if h is not None else cand
               for h in ([start_heading] + [None] * (len(pts) - 2) + [end_heading])]
    cost = np.zeros(len(options[0]))
    back = []
    for i in range(1, len(pts)):
        prev, cur = options[i - 1], options[i]
        pa = np.repeat(np.c_[np.tile(pts[i - 1], (len(prev), 1)), prev], len(cur), axis=0)
        pb = np.tile(np.c_[np.tile(pts[i], (len(cur), 1)), cur], (len(prev), 1))
        total = cost[:, None] + lengths(pa, pb, radius).reshape(len(prev), len(cur))
        back.append(np.argmin(total, axis=0))
        cost = total.min(axis=0)
    k = int(np.argmin(cost))
    chosen = [k]
    for b in reversed(back):
        chosen.append(int(b[chosen[-1]]))
    chosen.reverse()
    heads = [options[i][c] for i, c in enumerate(chosen)]
    return [shortest_path((*pts[i], heads[i]), (*pts[i + 1], heads[i + 1]), radius)
            for i in range(len(pts) - 1)]


def runway_approach(start, threshold, runway_heading: float, radius: float, *,
                    final: float | None = None) -> list[DubinsPath]:
    """Fly from pose ``start`` onto a straight final approach of length ``final``
    (default 3 r) that crosses the runway ``threshold`` (x, y) on ``runway_heading``."""
    radius = _check_radius(radius)
    runway_heading = real("runway_heading", runway_heading)
    final = 3 * radius if final is None else real("final", final, low=0.0)
    tx, ty = _one_point(threshold, "threshold")
    gate = (tx - final * math.cos(runway_heading), ty - final * math.sin(runway_heading),
            runway_heading)
    legs = [shortest_path(start, gate, radius)]
    if final > 0:
        legs.append(shortest_path(gate, (tx, ty, runway_heading), radius))
    return legs


def loiter(center, radius: float, *, start_angle: float = 0.0, turns: float = 1.0,
           step: float = 1.0, clockwise: bool = False) -> np.ndarray:
    """(K, 3) poses around a holding circle, ``turns`` (> 0) times, every ``step`` (> 0)
    metres."""
    radius = _check_radius(radius)
    start_angle = real("start_angle", start_angle)
    turns = real("turns", turns, low=0.0, strict=True)
    step = real("step", step, low=0.0, strict=True)
    clockwise = flag("clockwise", clockwise)
    if TWO_PI * radius * turns / step > MAX_SAMPLES:
        raise OptionError(f"turns={turns:g} of radius={radius:g} every step={step:g} makes "
                          f"more than {MAX_SAMPLES:,} poses", param="step")
    cx, cy = _one_point(center, "center")
    total = TWO_PI * radius * turns
    s = np.append(np.arange(0.0, total, step), total)
    ang = start_angle + (-1 if clockwise else 1) * s / radius
    heading = ang + (-math.pi / 2 if clockwise else math.pi / 2)
    return np.c_[cx + radius * np.cos(ang), cy + radius * np.sin(ang), _mod2pi(heading)]



def _one_point(point, what: str) -> tuple[float, float]:
    p = as_points(point, what)
    if len(p) != 1:
        raise QueryError(f"{what} must be one point (x, y), got {len(p)}")
    return float(p[0, 0]), float(p[0, 1])
