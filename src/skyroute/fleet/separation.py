"""An independent separation checker: it reads only the trajectory columns
(:class:`~skyroute.fleet.trajectory.Pieces`) and decides exactly, on the piecewise
trajectories themselves and not at sample times, when two airborne drones came too close.

A **loss of separation** is two drones closer than ``sep_horizontal`` horizontally *and*
closer than ``sep_vertical`` vertically at the same time (both strictly: exactly 10 m
apart vertically is not a loss). :func:`check` returns a :class:`SeparationReport`.

Method
------
Broad phase: the pieces are sorted by start time and swept; a pair of pieces of two
drones goes on only if their time windows overlap (closed intervals: a shared instant
counts) and their bounding boxes come within reach (horizontal boxes within
``sep_horizontal``, altitude ranges within ``sep_vertical``; for the closest-approach
statistics, within the closest approach found so far). The sweep runs in fixed chunks of
pieces across cores (numba ``prange``); chunks are the same for every thread count, so
the report is too.

Narrow phase, on the overlap ``[a, b]`` of two pieces: the vertical offset ``dz(t)`` is
linear, so the times with ``|dz| < sep_vertical`` form one open interval (closed form).
Horizontally let ``D(t)`` be the offset, ``g = |D|^2`` and ``h = |D|``.

- **line-line**: ``D`` is linear, ``g`` a quadratic: its minimum on an interval and the
  interval where ``h < sep_horizontal`` are closed forms (exact up to rounding).
- **any pair with an arc**: ``g`` is not a polynomial; it is bounded instead, on any
  interval ``[s, u]`` of length ``d``, from its values and slopes at the two ends. With
  ``V`` = the sum of the two horizontal speeds (``|v|`` of a line, ``r |w|`` of an arc),
  ``A`` = the sum of the two horizontal accelerations (0, or ``r w^2``), we have
  ``|D'| <= V``, ``|D''| <= A`` and ``|D| <= H = (h(s) + h(u) + V d) / 2`` on the interval,
  so ``g'' = 2|D'|^2 + 2 D.D''`` lies in ``[-m, M]`` with ``m = 2 H A``,
  ``M = 2 V^2 + 2 H A``; the form of ``g`` often gives a tighter bound ``c`` on ``|g''|``
  (two arcs: ``g`` is a constant plus three sinusoids, so ``c = 0`` for two drones on one
  circle at one rate; see ``_curvature``), and then ``min(m, c)``, ``min(M, c)`` serve.
  Then ``g + m/2 (t-s)(t-u)`` is convex and equals ``g`` at the
  ends, so ``g`` lies above both end tangents of that function: a **lower bound**
  (tight to O(d^2)); ``h`` is ``V``-Lipschitz, which gives ``h >= (h(s) + h(u) - V d)/2``
  (better on long intervals); the larger of the two is used. Symmetrically
  ``g - M/2 (t-s)(t-u)`` is concave and gives an **upper bound**.

  *Minimum* (branch and bound): bisect, keeping the best value ``g*`` seen at a sampled
  time; an interval is not split further once ``sqrt(lower) >= sqrt(g*) - tolerance``.
  The answer is the smallest of ``g*`` and the lower bounds of the intervals left, so it
  is **never above the true minimum and at most ``tolerance`` (1e-6 m) below it**: every
  time is in some interval whose lower bound is counted, and each interval was dropped
  with a bound within ``tolerance`` of a value actually reached.

  *Where* ``h < sep_horizontal``: intervals are classified in (upper bound below the
  limit), out (lower bound at or above it) or split; an interval whose bounds are within
  ``(sep_horizontal + tolerance)^2 - sep_horizontal^2`` of each other counts as in. So the
  reported times **contain every time of a loss**, and at every reported time the drones
  were closer than ``sep_horizontal + tolerance``.

Reports are therefore conservative by at most ``tolerance``: a pair whose closest
approach is within 1e-6 m above ``sep_horizontal`` may be flagged; a loss is never
missed and a distance is never overstated. (The arguments hold in exact arithmetic;
float64 rounding is some 1e-11 m for coordinates of a few hundred km. A bisection stops
at depth 60 whatever the bounds say, keeping the lower bound: still safe, only less
tight; it would take a window longer than 1e12 s to get there before the tolerance.)

>>> from skyroute.fleet.trajectory import Pieces, line_piece
>>> fleet = Pieces.from_rows([
...     line_piece(1, 0.0, 100.0, (0.0, -1000.0, 100.0), (0.0, 20.0, 0.0)),
...     line_piece(2, 0.0, 100.0, (-1000.0, 30.0, 100.0), (20.0, 0.0, 0.0))])
>>> report = check(fleet)
>>> [(c.drone_a, c.drone_b, round(c.t_min, 9), round(c.min_horizontal_m, 9))
...  for c in report.conflicts]
[(1, 2, 50.75, 21.213203436)]
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit, prange

from skyroute.errors import QueryError, real
from skyroute.fleet.trajectory import LINE, Pieces

# columns of Pieces.table()
_T0, _T1, _N, _E, _ALT, _VN, _VE, _VALT, _R, _ANG, _W = range(11)
_CHUNK = 64  # pieces per parallel task: fixed, so every thread count gives the same report
_MAXDEPTH = 60  # bisections of one window at most (2^-60 of it)
_MAXCOMP = 4096  # separate stretches within sep_horizontal per piece pair kept apart
_SERIAL_BELOW = 2048  # fewer pieces than this are checked in the calling thread
_PAD = 1e-6  # metres added to every bounding box: rounding never hides a pair


class Conflict(NamedTuple):
    """One loss of separation between two drones (``drone_a < drone_b``): from
    ``t_start`` to ``t_end`` (s), the closest horizontal approach in it (a certified lower
    bound, within the check's tolerance), the vertical distance then, and when."""

    drone_a: int
    drone_b: int
    t_start: float
    t_end: float
    min_horizontal_m: float
    vertical_m_at_min: float
    t_min: float


@dataclass(frozen=True)
class SeparationReport:
    """What :func:`check` found.

    ``conflicts``: every loss of separation, one per drone pair and stretch of time
    (piece-pair stretches of the same two drones that overlap or touch are merged),
    ordered by drones then time. ``min_horizontal_m``: the smallest horizontal distance
    between two drones at a time they were closer than ``sep_vertical`` vertically (the
    closest approach that matters; ``inf`` if never), a lower bound within ``tolerance``.
    ``min_vertical_m``: the smallest vertical distance at a time they were closer than
    ``sep_horizontal`` horizontally (``inf`` if never), taken over the same conservative
    stretches as the conflicts (which may include times up to ``sep_horizontal +
    tolerance`` apart), so never above the truth. ``pairs_checked``: piece pairs that
    passed the broad phase and were examined exactly. The minima and the tolerance used
    are kept as ``sep_horizontal``, ``sep_vertical``, ``tolerance``.
    """

    conflicts: tuple[Conflict, ...]
    min_horizontal_m: float
    min_vertical_m: float
    pairs_checked: int
    sep_horizontal: float
    sep_vertical: float
    tolerance: float

    @property
    def separated(self) -> bool:
        """True when no two drones ever lost separation."""
        return not self.conflicts


def check(pieces: Pieces | Mapping[str, object], *, sep_horizontal: float = 50.0,
          sep_vertical: float = 10.0, tolerance: float = 1e-6) -> SeparationReport:
    """Every loss of separation in a fleet's airborne ``pieces`` (a
    :class:`~skyroute.fleet.trajectory.Pieces` or a mapping of its columns).

    ``sep_horizontal`` and ``sep_vertical`` (metres, >= 0) are the minima; ``tolerance``
    (metres, > 0) is how far below the truth a reported distance may be (see the module
    docstring: the check is exact for straight pieces and certified for arcs). Bad pieces
    raise :class:`~skyroute.errors.QueryError`, bad options
    :class:`~skyroute.errors.OptionError`, each naming the field.
    """
    sh = _option("sep_horizontal", sep_horizontal, positive=False)
    sv = _option("sep_vertical", sep_vertical, positive=False)
    tol = _option("tolerance", tolerance, positive=True)
    if not isinstance(pieces, Pieces):
        if not isinstance(pieces, Mapping):
            raise QueryError(f"pieces must be Pieces or a mapping of columns, not "
                             f"{type(pieces).__name__}", param="pieces")
        pieces = Pieces.from_columns(pieces)
    # a canonical order (start time, then every other column): the same set of pieces
    # gives the same chunks, hence the same report to the last bit, in any row order
    cols = [pieces.t0, pieces.drone, pieces.kind, *(getattr(pieces, c) for c in
                                                    ("t1", "north", "east", "alt", "v_north",
                                                     "v_east", "v_alt", "radius", "angle",
                                                     "rate"))]
    order = np.lexsort(cols[::-1])
    P = pieces.table()[order]
    kind = np.ascontiguousarray(pieces.kind[order])
    drone = np.ascontiguousarray(pieces.drone[order])
    if len(P) == 0:
        return SeparationReport((), math.inf, math.inf, 0, sh, sv, tol)
    box = _boxes(P, kind)
    t0 = np.ascontiguousarray(P[:, _T0])
    serial = len(P) < _SERIAL_BELOW
    scan = _scan_serial if serial else _scan_parallel
    min_h, min_v, checked, counts = scan(P, kind, drone, t0, box, sh, sv, tol)
    events = _events_serial if serial or counts.sum() < _SERIAL_BELOW else _events_parallel
    rows, ev = events(P, kind, drone, t0, box, sh, sv, tol, counts)
    conflicts = _merge(drone[rows], ev)
    return SeparationReport(conflicts, float(min_h.min()), float(min_v.min()),
                            int(checked.sum()), sh, sv, tol)


def _option(name: str, value, *, positive: bool) -> float:
    """A real number (not a string or a bool: float() took "5" and True), as every
    option of skyroute reads one (:func:`skyroute.errors.real`)."""
    return real(name, value, low=0.0, strict=positive,
                need="a number > 0" if positive else "a number >= 0")


def _merge(drones: np.ndarray, ev: np.ndarray) -> tuple[Conflict, ...]:
    """One Conflict per drone pair and overlapping or touching stretch of time."""
    if len(ev) == 0:
        return ()
    a = np.minimum(drones[:, 0], drones[:, 1])
    b = np.maximum(drones[:, 0], drones[:, 1])
    order = np.lexsort((ev[:, 1], ev[:, 0], b, a))
    out: list[Conflict] = []
    cur = None
    for k in order:
        t_start, t_end, mh, vert, tmin = (float(x) for x in ev[k])
        if cur is not None and cur[0] == a[k] and cur[1] == b[k] and t_start <= cur[3]:
            best = (cur[4], cur[5], cur[6]) if cur[4] <= mh else (mh, vert, tmin)
            cur = [cur[0], cur[1], cur[2], max(cur[3], t_end), *best]
            continue
        if cur is not None:
            out.append(Conflict(*cur))
        cur = [int(a[k]), int(b[k]), t_start, t_end, mh, vert, tmin]
    out.append(Conflict(*cur))
    return tuple(out)


# ----------------------------------------------------------------- compiled kernels


@njit(cache=True, inline="always")
def _put(stk, k, s, u, gs, gps, gu, gpu, lo, depth, up):
    """Stack row k: an interval [s, u], g and g' at both ends, its bounds, its depth."""
    stk[k, 0] = s
    stk[k, 1] = u
    stk[k, 2] = gs
    stk[k, 3] = gps
    stk[k, 4] = gu
    stk[k, 5] = gpu
    stk[k, 6] = lo
    stk[k, 7] = depth
    stk[k, 8] = up


@njit(cache=True, inline="always")
def _get(stk, k):
    """Stack row k as (s, u, gs, gps, gu, gpu, lo, depth, up)."""
    return (stk[k, 0], stk[k, 1], stk[k, 2], stk[k, 3], stk[k, 4], stk[k, 5], stk[k, 6],
            stk[k, 7], stk[k, 8])


@njit(cache=True)
def _horizontal(P, kind, i, t):
    """(north, east, v_north, v_east) of piece ``i`` at time ``t``."""
    tau = t - P[i, _T0]
    if kind[i] == LINE:
        return P[i, _N] + P[i, _VN] * tau, P[i, _E] + P[i, _VE] * tau, P[i, _VN], P[i, _VE]
    r = P[i, _R]
    w = P[i, _W]
    th = P[i, _ANG] + w * tau
    c = math.cos(th)
    s = math.sin(th)
    return P[i, _N] + r * c, P[i, _E] + r * s, -r * w * s, r * w * c


@njit(cache=True)
def _rel(P, kind, i, j, t):
    """g = |D|^2 and g' = 2 D.D' of the horizontal offset D of pieces i and j at t."""
    ni, ei, vni, vei = _horizontal(P, kind, i, t)
    nj, ej, vnj, vej = _horizontal(P, kind, j, t)
    dn = ni - nj
    de = ei - ej
    return dn * dn + de * de, 2.0 * (dn * (vni - vnj) + de * (vei - vej))


@njit(cache=True)
def _speed(P, kind, i):
    if kind[i] == LINE:
        return math.hypot(P[i, _VN], P[i, _VE])
    return P[i, _R] * abs(P[i, _W])


@njit(cache=True)
def _accel(P, kind, i):
    if kind[i] == LINE:
        return 0.0
    return P[i, _R] * P[i, _W] * P[i, _W]


@njit(cache=True)
def _curvature(P, kind, i, j, a, b):
    """(V, A, c): speed and acceleration sums of pieces i and j, and a bound c on |g''|
    over [a, b] from the form of g (inf when there is none better than V and A's).

    Two arcs: D = dC + r1 e(th1) - r2 e(th2), so g is a constant plus sinusoids in th1,
    th2 and th1 - th2 with amplitudes 2 r1 |dC|, 2 r2 |dC|, 2 r1 r2: |g''| <= their sum
    weighted by w1^2, w2^2, (w1 - w2)^2 (0 for two drones on one circle at one rate).
    An arc and a line: with q the line's offset from the centre, g = |q|^2 - 2 r q.e + r^2
    and |g''| <= 2|u|^2 + 2 r (2 |w| |u| + w^2 max|q|), max|q| at an end of [a, b]."""
    V = _speed(P, kind, i) + _speed(P, kind, j)
    A = _accel(P, kind, i) + _accel(P, kind, j)
    if kind[i] == LINE and kind[j] == LINE:
        return V, A, math.inf
    if kind[i] != LINE and kind[j] != LINE:
        dc = math.hypot(P[i, _N] - P[j, _N], P[i, _E] - P[j, _E])
        r1 = P[i, _R]
        r2 = P[j, _R]
        w1 = P[i, _W]
        w2 = P[j, _W]
        return V, A, 2.0 * (r1 * dc * w1 * w1 + r2 * dc * w2 * w2 + r1 * r2 * (w1 - w2) ** 2)
    arc = i if kind[i] != LINE else j
    line = j if arc == i else i
    r = P[arc, _R]
    w = abs(P[arc, _W])
    u = _speed(P, kind, line)
    q = 0.0
    for t in (a, b):
        n, e, _, _ = _horizontal(P, kind, line, t)
        q = max(q, math.hypot(n - P[arc, _N], e - P[arc, _E]))
    return V, A, 2.0 * u * u + 2.0 * r * (2.0 * w * u + w * w * q)


@njit(cache=True)
def _bounds(ga, gpa, gb, gpb, d, V, A, c):
    """Lower and upper bounds of g on an interval of length d, from g and g' at its ends
    (the module docstring's argument; ``c`` bounds |g''| from :func:`_curvature`)."""
    ha = math.sqrt(ga)
    hb = math.sqrt(gb)
    H = 0.5 * (ha + hb + V * d)
    m = min(2.0 * H * A, c)
    M = min(2.0 * V * V + 2.0 * H * A, c)
    # g + m/2 (t-a)(t-b) is convex, <= g, = g at the ends: above its end tangents
    sa = gpa - 0.5 * m * d
    sb = gpb + 0.5 * m * d
    if sa >= 0.0:
        lo = ga
    elif sb <= 0.0:
        lo = gb
    else:
        u = min(max((gb - ga - sb * d) / (sa - sb), 0.0), d)
        lo = max(ga + sa * u, gb + sb * (u - d))
    hl = 0.5 * (ha + hb - V * d)
    if hl > 0.0:
        lo = max(lo, hl * hl)
    lo = max(lo, 0.0)
    # g - M/2 (t-a)(t-b) is concave, >= g, = g at the ends: below its end tangents
    sa = gpa + 0.5 * M * d
    sb = gpb - 0.5 * M * d
    if sa <= 0.0:
        up = ga
    elif sb >= 0.0:
        up = gb
    else:
        u = min(max((gb - ga - sb * d) / (sa - sb), 0.0), d)
        up = min(ga + sa * u, gb + sb * (u - d))
    up = min(up, H * H)
    return lo, up


@njit(cache=True)
def _min_g(P, kind, i, j, a, b, tol, cap, stk):
    """(L, t): L <= min of g on [a, b] with sqrt(L) >= sqrt(min) - tol, and the time of the
    smallest g seen. Intervals whose lower bound reaches ``cap`` are not refined (their
    bound still counts, so L >= cap means only that the minimum is >= cap)."""
    if kind[i] == LINE and kind[j] == LINE:
        ni, ei, vni, vei = _horizontal(P, kind, i, a)
        nj, ej, vnj, vej = _horizontal(P, kind, j, a)
        pn = ni - nj
        pe = ei - ej
        un = vni - vnj
        ue = vei - vej
        uu = un * un + ue * ue
        tau = 0.0
        if uu > 0.0:
            tau = min(max(-(pn * un + pe * ue) / uu, 0.0), b - a)
        dn = pn + un * tau
        de = pe + ue * tau
        return dn * dn + de * de, a + tau
    V, A, C = _curvature(P, kind, i, j, a, b)
    ga, gpa = _rel(P, kind, i, j, a)
    gb, gpb = _rel(P, kind, i, j, b)
    best = ga
    tbest = a
    if gb < best:
        best = gb
        tbest = b
    lo, _ = _bounds(ga, gpa, gb, gpb, b - a, V, A, C)
    low = math.inf
    _put(stk, 0, a, b, ga, gpa, gb, gpb, lo, 0.0, math.inf)
    top = 1
    while top > 0:
        top -= 1
        s, u, gs, gps, gu, gpu, lo, depth, _ = _get(stk, top)
        m = 0.5 * (s + u)
        if (lo >= cap or math.sqrt(lo) >= math.sqrt(best) - tol or depth >= _MAXDEPTH
                or not (s < m < u)):
            low = min(low, lo)
            continue
        gm, gpm = _rel(P, kind, i, j, m)
        if gm < best:
            best = gm
            tbest = m
        l1, _ = _bounds(gs, gps, gm, gpm, m - s, V, A, C)
        l2, _ = _bounds(gm, gpm, gu, gpu, u - m, V, A, C)
        l1 = max(l1, lo)
        l2 = max(l2, lo)
        # the half with the lower bound on top: it is refined first
        for k in range(2):
            left = (k == 0) == (l1 > l2)
            if left:
                _put(stk, top, s, m, gs, gps, gm, gpm, l1, depth + 1.0, math.inf)
            else:
                _put(stk, top, m, u, gm, gpm, gu, gpu, l2, depth + 1.0, math.inf)
            top += 1
    return min(best, low), tbest


@njit(cache=True)
def _below(P, kind, i, j, a, b, thr, slack, stk, comps):
    """The stretches of [a, b] where g < thr, in time order, into ``comps``; returns
    how many. A superset: an interval whose bounds are within ``slack`` counts as in."""
    n = 0
    if kind[i] == LINE and kind[j] == LINE:
        ni, ei, vni, vei = _horizontal(P, kind, i, a)
        nj, ej, vnj, vej = _horizontal(P, kind, j, a)
        pn = ni - nj
        pe = ei - ej
        un = vni - vnj
        ue = vei - vej
        uu = un * un + ue * ue
        if uu == 0.0:
            if pn * pn + pe * pe < thr:
                comps[0, 0] = a
                comps[0, 1] = b
                n = 1
            return n
        cross = pn * ue - pe * un  # |cross| / |u| is the miss distance
        disc = uu * thr - cross * cross
        if disc <= 0.0:
            return 0
        pu = pn * un + pe * ue
        sq = math.sqrt(disc)
        c0 = max(a, a + (-pu - sq) / uu)
        c1 = min(b, a + (-pu + sq) / uu)
        if c0 < c1:
            comps[0, 0] = c0
            comps[0, 1] = c1
            n = 1
        return n
    V, A, C = _curvature(P, kind, i, j, a, b)
    ga, gpa = _rel(P, kind, i, j, a)
    gb, gpb = _rel(P, kind, i, j, b)
    _put(stk, 0, a, b, ga, gpa, gb, gpb, 0.0, 0.0, math.inf)
    top = 1
    while top > 0:
        top -= 1
        s, u, gs, gps, gu, gpu, plo, depth, pup = _get(stk, top)
        lo, up = _bounds(gs, gps, gu, gpu, u - s, V, A, C)
        lo = max(lo, plo)
        up = min(up, pup)
        if lo >= thr:
            continue
        m = 0.5 * (s + u)
        if not (up < thr or up - lo <= slack or depth >= _MAXDEPTH or not (s < m < u)):
            gm, gpm = _rel(P, kind, i, j, m)
            # right half first, so the left one is popped first: stretches in time order
            _put(stk, top, m, u, gm, gpm, gu, gpu, lo, depth + 1.0, up)
            top += 1
            _put(stk, top, s, m, gs, gps, gm, gpm, lo, depth + 1.0, up)
            top += 1
            continue
        if n > 0 and comps[n - 1, 1] == s:
            comps[n - 1, 1] = u
        elif n < comps.shape[0]:
            comps[n, 0] = s
            comps[n, 1] = u
            n += 1
        else:  # out of room: widen the last stretch (still a superset)
            comps[n - 1, 1] = u
    return n


@njit(cache=True)
def _window(P, kind, i, j, sv):
    """The overlap [a, b] of pieces i and j, their vertical offset dz = dz0 + sz (t - a)
    on it, and the part (vlo, vhi) of it where |dz| < sv (open; ``vok`` if not empty)."""
    a = max(P[i, _T0], P[j, _T0])
    b = min(P[i, _T1], P[j, _T1])
    dz0 = ((P[i, _ALT] + P[i, _VALT] * (a - P[i, _T0]))
           - (P[j, _ALT] + P[j, _VALT] * (a - P[j, _T0])))
    sz = P[i, _VALT] - P[j, _VALT]
    if a == b:  # one shared instant
        return a, b, dz0, sz, a, b, abs(dz0) < sv
    if sz == 0.0:
        return a, b, dz0, sz, a, b, abs(dz0) < sv
    tA = a + (-sv - dz0) / sz
    tB = a + (sv - dz0) / sz
    vlo = max(a, min(tA, tB))
    vhi = min(b, max(tA, tB))
    return a, b, dz0, sz, vlo, vhi, vlo < vhi


@njit(cache=True)
def _pair_min(P, kind, i, j, sv, tol, cap, stk):
    """The smallest horizontal distance of pieces i and j while |dz| < sv (a certified
    lower bound, see :func:`_min_g`; inf if never)."""
    a, b, _, _, vlo, vhi, vok = _window(P, kind, i, j, sv)
    if not vok:
        return math.inf
    if a == b:
        g, _ = _rel(P, kind, i, j, a)
        return math.sqrt(g)
    g, _ = _min_g(P, kind, i, j, vlo, vhi, tol, cap * cap, stk)
    return math.sqrt(g)


@njit(cache=True)
def _pair_sets(P, kind, i, j, sh, sv, tol, stk, comps, out, k0):
    """(min |dz| while h < sh, or inf; number of conflicting stretches) of pieces i and
    j. The stretches go to ``out[k0:]`` as (t_start, t_end, min_h, |dz| then, t_min)
    where there is room (none in an empty ``out``: then they are only counted)."""
    a, b, dz0, sz, vlo, vhi, vok = _window(P, kind, i, j, sv)
    sh2 = sh * sh
    mv = math.inf
    nev = 0
    if a == b:
        g, _ = _rel(P, kind, i, j, a)
        h = math.sqrt(g)
        if h < sh:
            mv = abs(dz0)
            if vok:
                if k0 < out.shape[0]:
                    out[k0, 0] = a
                    out[k0, 1] = a
                    out[k0, 2] = h
                    out[k0, 3] = abs(dz0)
                    out[k0, 4] = a
                nev = 1
        return mv, nev
    slack = (sh + tol) * (sh + tol) - sh2
    nc = _below(P, kind, i, j, a, b, sh2, slack, stk, comps)
    for c in range(nc):
        c0 = comps[c, 0]
        c1 = comps[c, 1]
        z0 = dz0 + sz * (c0 - a)
        z1 = dz0 + sz * (c1 - a)
        if z0 * z1 <= 0.0:
            mv = 0.0
        else:
            mv = min(mv, abs(z0), abs(z1))
        if not vok:
            continue
        e0 = max(c0, vlo)
        e1 = min(c1, vhi)
        if not e0 < e1:
            continue
        g, tm = _min_g(P, kind, i, j, e0, e1, tol, sh2, stk)
        if g < sh2:
            k = k0 + nev
            if k < out.shape[0]:
                out[k, 0] = e0
                out[k, 1] = e1
                out[k, 2] = math.sqrt(g)
                # at most sv: tm may be where |dz| < sv ends (up to rounding)
                out[k, 3] = min(abs(dz0 + sz * (tm - a)), sv)
                out[k, 4] = tm
            nev += 1
    return mv, nev


@njit(cache=True)
def _boxes(P, kind):
    """(N, 6) boxes north lo/hi, east lo/hi, alt lo/hi of every piece, padded by _PAD."""
    n = P.shape[0]
    box = np.empty((n, 6))
    two_pi = 2.0 * math.pi
    for i in range(n):
        d = P[i, _T1] - P[i, _T0]
        z0 = P[i, _ALT]
        z1 = P[i, _ALT] + P[i, _VALT] * d
        box[i, 4] = min(z0, z1) - _PAD
        box[i, 5] = max(z0, z1) + _PAD
        if kind[i] == LINE:
            n0 = P[i, _N]
            n1 = P[i, _N] + P[i, _VN] * d
            e0 = P[i, _E]
            e1 = P[i, _E] + P[i, _VE] * d
            box[i, 0] = min(n0, n1) - _PAD
            box[i, 1] = max(n0, n1) + _PAD
            box[i, 2] = min(e0, e1) - _PAD
            box[i, 3] = max(e0, e1) + _PAD
            continue
        r = P[i, _R]
        a0 = P[i, _ANG]
        a1 = a0 + P[i, _W] * d
        lo = min(a0, a1)
        hi = max(a0, a1)
        cmin = min(math.cos(a0), math.cos(a1))
        cmax = max(math.cos(a0), math.cos(a1))
        smin = min(math.sin(a0), math.sin(a1))
        smax = max(math.sin(a0), math.sin(a1))
        if hi - lo >= two_pi:
            cmin, cmax, smin, smax = -1.0, 1.0, -1.0, 1.0
        else:
            # the extreme angles 0 (north), pi/2 (east), pi, 3 pi/2 met on the way
            for q in range(4):
                x = q * 0.5 * math.pi
                if x + two_pi * math.ceil((lo - x) / two_pi) <= hi:
                    if q == 0:
                        cmax = 1.0
                    elif q == 1:
                        smax = 1.0
                    elif q == 2:
                        cmin = -1.0
                    else:
                        smin = -1.0
        box[i, 0] = P[i, _N] + r * cmin - _PAD
        box[i, 1] = P[i, _N] + r * cmax + _PAD
        box[i, 2] = P[i, _E] + r * smin - _PAD
        box[i, 3] = P[i, _E] + r * smax + _PAD
    return box


@njit(cache=True)
def _gap2(box, i, j):
    """Squared horizontal distance between the boxes of pieces i and j."""
    dn = max(0.0, box[j, 0] - box[i, 1], box[i, 0] - box[j, 1])
    de = max(0.0, box[j, 2] - box[i, 3], box[i, 2] - box[j, 3])
    return dn * dn + de * de


@njit(cache=True)
def _scan_chunk(P, kind, drone, t0, box, sh, sv, tol, c, counts):
    """Pieces ``c * _CHUNK`` up to the next chunk against every later piece that
    overlaps them in time: (smallest horizontal distance that matters, smallest vertical
    one, pairs examined); ``counts[i]`` gets the conflicting stretches of piece i's pairs.
    The closest approaches found so far in the chunk widen the broad phase's reach."""
    n = P.shape[0]
    stk = np.empty((_MAXDEPTH + 2, 9))
    comps = np.empty((_MAXCOMP, 2))
    out = np.empty((0, 5))  # count the losses, write none
    cap_h = np.inf
    cap_v = np.inf
    seen = 0
    for i in range(c * _CHUNK, min(n, (c + 1) * _CHUNK)):
        t1 = P[i, _T1]
        j = i + 1
        while j < n and t0[j] <= t1:
            if drone[j] != drone[i]:
                zgap = max(0.0, box[j, 4] - box[i, 5], box[i, 4] - box[j, 5])
                near_z = zgap < sv
                want_mv = zgap < cap_v
                if near_z or want_mv:  # else nothing to learn: the usual exit, by layers
                    h2 = _gap2(box, i, j)
                    reach = max(sh, cap_h)
                    do_h = near_z and h2 < reach * reach
                    do_sets = h2 < sh * sh
                    if do_h or do_sets:
                        seen += 1
                    if do_h:
                        cap_h = min(cap_h, _pair_min(P, kind, i, j, sv, tol, cap_h, stk))
                    if do_sets:
                        # the stretches within sh: for min_v, or to count the losses
                        mv, nev = _pair_sets(P, kind, i, j, sh, sv, tol, stk, comps, out,
                                             out.shape[0])
                        cap_v = min(cap_v, mv)
                        counts[i] += nev
            j += 1
    return cap_h, cap_v, seen


@njit(cache=True, parallel=True)
def _scan_parallel(P, kind, drone, t0, box, sh, sv, tol):
    """:func:`_scan_chunk` over all chunks, across cores."""
    n = P.shape[0]
    nc = (n + _CHUNK - 1) // _CHUNK
    min_h = np.full(nc, np.inf)
    min_v = np.full(nc, np.inf)
    checked = np.zeros(nc, np.int64)
    counts = np.zeros(n, np.int64)
    for c in prange(nc):
        # np.int64: prange counts in uint64, and one compiled _scan_chunk serves both
        min_h[c], min_v[c], checked[c] = _scan_chunk(P, kind, drone, t0, box, sh, sv, tol,
                                                     np.int64(c), counts)
    return min_h, min_v, checked, counts


@njit(cache=True)
def _scan_serial(P, kind, drone, t0, box, sh, sv, tol):
    """:func:`_scan_chunk` over all chunks in this thread: the same answer as
    :func:`_scan_parallel`, without waking threads for a small fleet."""
    n = P.shape[0]
    nc = (n + _CHUNK - 1) // _CHUNK
    min_h = np.full(nc, np.inf)
    min_v = np.full(nc, np.inf)
    checked = np.zeros(nc, np.int64)
    counts = np.zeros(n, np.int64)
    for c in range(nc):
        min_h[c], min_v[c], checked[c] = _scan_chunk(P, kind, drone, t0, box, sh, sv, tol,
                                                     c, counts)
    return min_h, min_v, checked, counts


@njit(cache=True)
def _events_of(P, kind, drone, t0, box, sh, sv, tol, i, k, rows, out, stk, comps):
    """The conflicting stretches of piece i's pairs (as :func:`_scan_chunk` counted
    them), into ``rows[k:]`` and ``out[k:]``."""
    n = P.shape[0]
    t1 = P[i, _T1]
    j = i + 1
    while j < n and t0[j] <= t1:
        if drone[j] != drone[i]:
            zgap = max(0.0, box[j, 4] - box[i, 5], box[i, 4] - box[j, 5])
            if zgap < sv and _gap2(box, i, j) < sh * sh:
                _, nev = _pair_sets(P, kind, i, j, sh, sv, tol, stk, comps, out, k)
                for e in range(nev):
                    rows[k + e, 0] = i
                    rows[k + e, 1] = j
                k += nev
        j += 1


@njit(cache=True, parallel=True)
def _events_parallel(P, kind, drone, t0, box, sh, sv, tol, counts):
    """Piece rows (K, 2) and stretches (K, 5) of every conflict, across cores."""
    ends = np.cumsum(counts)
    total = ends[-1]
    rows = np.empty((total, 2), np.int64)
    out = np.empty((total, 5))
    todo = np.flatnonzero(counts)
    for x in prange(len(todo)):
        i = todo[x]
        stk = np.empty((_MAXDEPTH + 2, 9))
        comps = np.empty((_MAXCOMP, 2))
        _events_of(P, kind, drone, t0, box, sh, sv, tol, i, ends[i] - counts[i], rows, out,
                   stk, comps)
    return rows, out


@njit(cache=True)
def _events_serial(P, kind, drone, t0, box, sh, sv, tol, counts):
    """:func:`_events_parallel` in this thread."""
    ends = np.cumsum(counts)
    total = ends[-1]
    rows = np.empty((total, 2), np.int64)
    out = np.empty((total, 5))
    stk = np.empty((_MAXDEPTH + 2, 9))
    comps = np.empty((_MAXCOMP, 2))
    for i in np.flatnonzero(counts):
        _events_of(P, kind, drone, t0, box, sh, sv, tol, i, ends[i] - counts[i], rows, out,
                   stk, comps)
    return rows, out


