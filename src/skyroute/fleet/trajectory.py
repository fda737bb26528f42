"""Airborne trajectories of a whole fleet as flat arrays, one row per piece.

A drone's airborne trajectory is a time-ordered run of pieces, each valid over the closed
interval ``[t0, t1]`` (seconds). Two kinds:

``line`` (``LINE = 0``)
    start position ``(north, east, alt)`` at ``t0`` and constant velocity
    ``(v_north, v_east, v_alt)``: cruise, straight climbs and descents, a take-off or a
    roll-out approximated as straight, holding still when the velocity is zero.
``arc`` (``ARC = 1``)
    a horizontal circle: centre ``(north, east)``, ``radius > 0``, the ``angle`` at ``t0``
    and a signed angular ``rate``; altitude ``alt`` at ``t0`` and constant ``v_alt`` (so a
    loiter, a helix or a climbing turn).

Frame and units: the fleet's local frame, metres north, east and up (altitude) from its
home; time in seconds; angles in radians.

Arc angles are measured at the centre **clockwise from north**, like a NED heading: the
point at angle ``a`` is ``(north + r cos a, east + r sin a)``, i.e.
``a = atan2(east_p - east_c, north_p - north_c)``. ``rate > 0`` means the angle grows:
clockwise seen from above, a right turn for the drone flying it (its heading is
``a + pi/2``); ``rate < 0`` is anticlockwise, a left turn (heading ``a - pi/2``).

The columns of :class:`Pieces` (struct of arrays) are what compiled code reads; the
unused parameters of a row are 0 (a line's ``radius``, ``angle``, ``rate``; an arc's
``v_north``, ``v_east``). Pieces of one drone must not overlap in time; two pieces where
one ends at the very time the next starts meet there (see :func:`jumps`), and a gap in
time means the drone is on the ground (parked or taxiing: ground separation is the
airports' business, not this module's).

>>> path = (Trajectory(7, 0.0, (0.0, 0.0, 0.0))
...         .line(10.0, (20.0, 0.0, 5.0))           # take-off climb, due north
...         .arc(10.0 + math.pi / 0.1, (200.0, 100.0), 0.1)  # half a right turn
...         .pieces())
>>> len(path), path.kind.tolist()
(2, [0, 1])
>>> position(path, [10.0, 10.0 + math.pi / 0.1], drone=7).round(9).tolist()
[[200.0, 0.0, 50.0], [200.0, 200.0, 50.0]]
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, fields
from typing import NamedTuple

import numpy as np

from skyroute.errors import QueryError

LINE = 0
ARC = 1
KINDS = {"line": LINE, "arc": ARC}

# the float columns, in the order of Pieces.table() (the compiled checker's layout)
COLUMNS = ("t0", "t1", "north", "east", "alt", "v_north", "v_east", "v_alt",
           "radius", "angle", "rate")


class Piece(NamedTuple):
    """One row of :class:`Pieces` (see the module docstring for the meaning per kind)."""

    drone: int
    kind: int
    t0: float
    t1: float
    north: float
    east: float
    alt: float
    v_north: float = 0.0
    v_east: float = 0.0
    v_alt: float = 0.0
    radius: float = 0.0
    angle: float = 0.0
    rate: float = 0.0


def line_piece(drone: int, t0: float, t1: float, start, velocity) -> Piece:
    """A straight piece from ``start = (north, east, alt)`` at ``t0`` with constant
    ``velocity = (v_north, v_east, v_alt)`` (m/s) until ``t1``."""
    n, e, z = _triple("start", start)
    vn, ve, vz = _triple("velocity", velocity)
    return Piece(int(drone), LINE, float(t0), float(t1), n, e, z, vn, ve, vz)


def arc_piece(drone: int, t0: float, t1: float, centre, radius: float, angle: float,
              rate: float, alt: float, *, v_alt: float = 0.0) -> Piece:
    """A horizontal circle arc about ``centre = (north, east)``: at ``t0`` the drone is at
    ``angle`` (radians clockwise from north, seen from the centre) and altitude ``alt``;
    the angle changes at ``rate`` rad/s (> 0 clockwise) and the altitude at ``v_alt``."""
    c = np.asarray(centre, dtype=float)
    if c.shape != (2,):
        raise QueryError(f"centre={centre!r} must be (north, east)", param="centre")
    return Piece(int(drone), ARC, float(t0), float(t1), float(c[0]), float(c[1]), float(alt),
                 0.0, 0.0, float(v_alt), float(radius), float(angle), float(rate))


def _triple(name: str, value) -> tuple[float, float, float]:
    v = np.asarray(value, dtype=float)
    if v.shape != (3,):
        raise QueryError(f"{name}={value!r} must be (north, east, alt)", param=name)
    return float(v[0]), float(v[1]), float(v[2])


def _not_number(value, raw: np.ndarray) -> tuple[int, object] | None:
    """(index, element) of the first element of column ``value`` (read as the 1-d
    ``raw``) that is not a real number (a string or a bool is not, as for
    :func:`skyroute.errors.real`), or None."""
    if raw.dtype.kind in "iuf":
        return None
    # element by element, as given: [100.0, "100"] is one array of strings to numpy
    items = np.array(value, dtype=object, ndmin=1).tolist() if raw.dtype.kind != "O" \
        else list(raw)
    for i, x in enumerate(items):
        if isinstance(x, bool | np.bool_) or not isinstance(x, numbers.Real):
            return i, x.item() if isinstance(x, np.generic) else x
    return None


@dataclass(frozen=True, eq=False)
class Pieces:
    """A fleet's airborne pieces as read-only columns (one row per piece).

    ``drone`` (int64) and ``kind`` (int8: ``LINE`` or ``ARC``) and the float64 columns
    ``t0 ... rate`` of :data:`COLUMNS`. Built from rows with :meth:`from_rows`, from a
    :class:`Trajectory`, or directly from columns; the constructor copies and checks them:
    equal lengths, finite numbers, ``t1 >= t0``, known kinds, ``radius > 0`` on arcs and
    no two pieces of one drone overlapping in time. A bad value is a
    :class:`~skyroute.errors.QueryError` whose ``param`` names the column.
    """

    drone: np.ndarray
    kind: np.ndarray
    t0: np.ndarray
    t1: np.ndarray
    north: np.ndarray
    east: np.ndarray
    alt: np.ndarray
    v_north: np.ndarray
    v_east: np.ndarray
    v_alt: np.ndarray
    radius: np.ndarray
    angle: np.ndarray
    rate: np.ndarray

    def __post_init__(self) -> None:
        cols = {f.name: getattr(self, f.name) for f in fields(self)}
        n = None
        for name, value in cols.items():
            try:
                raw = np.array(value, ndmin=1, copy=None)
            except (TypeError, ValueError):
                raise QueryError(f"{name} must be an array of numbers", param=name) from None
            if raw.ndim != 1:
                raise QueryError(f"{name} must be one-dimensional, not shape {raw.shape}",
                                 param=name)
            bad = _not_number(value, raw)
            if bad is not None:  # float() reads "5" and True as numbers; they are not
                raise QueryError(f"{name}[{bad[0]}]={bad[1]!r} must be a number", param=name)
            integer = name in ("drone", "kind") and raw.dtype.kind in "iu"
            try:  # a copy: never share (or let anyone change) the caller's array
                a = np.array(raw, dtype=np.int64 if integer else float)
            except (TypeError, ValueError, OverflowError):
                raise QueryError(f"{name} must be an array of numbers", param=name) from None
            if n is None:
                n = len(a)
            elif len(a) != n:
                raise QueryError(f"{name} has {len(a)} rows, drone has {n}", param=name)
            bad = np.flatnonzero(~np.isfinite(a)) if a.dtype.kind == "f" else []
            if len(bad):
                raise QueryError(f"{name}[{bad[0]}]={a[bad[0]]} must be a finite number",
                                 param=name)
            if name in ("drone", "kind"):
                whole = np.flatnonzero(a != np.round(a))
                if len(whole):
                    raise QueryError(f"{name}[{whole[0]}]={a[whole[0]]} must be an integer",
                                     param=name)
                a = a.astype(np.int64 if name == "drone" else np.int8)
            a.setflags(write=False)
            object.__setattr__(self, name, a)
        bad = np.flatnonzero((self.kind != LINE) & (self.kind != ARC))
        if len(bad):
            raise QueryError(f"kind[{bad[0]}]={self.kind[bad[0]]} is not valid; choose "
                             f"{LINE} (line) or {ARC} (arc)", param="kind")
        bad = np.flatnonzero(self.t1 < self.t0)
        if len(bad):
            i = bad[0]
            raise QueryError(f"t1[{i}]={self.t1[i]} is before t0[{i}]={self.t0[i]}",
                             param="t1")
        bad = np.flatnonzero((self.kind == ARC) & ~(self.radius > 0))
        if len(bad):
            raise QueryError(f"radius[{bad[0]}]={self.radius[bad[0]]} of an arc must be > 0",
                             param="radius")
        order = self.order()
        d, s, e = self.drone[order], self.t0[order], self.t1[order]
        clash = np.flatnonzero((d[1:] == d[:-1]) & (s[1:] < e[:-1]))
        if len(clash):
            a, b = order[clash[0]], order[clash[0] + 1]
            raise QueryError(f"t0[{b}]={self.t0[b]}: drone {self.drone[b]}'s piece starts "
                             f"before its piece {a} ends at t1={self.t1[a]}; a drone's "
                             "pieces must not overlap in time", param="t0")

    def __len__(self) -> int:
        return len(self.t0)

    @classmethod
    def from_rows(cls, rows: Iterable[Piece]) -> Pieces:
        """Stack :class:`Piece` rows (from :func:`line_piece`, :func:`arc_piece`)."""
        rows = [Piece(*r) for r in rows]
        names = Piece._fields
        if not rows:
            return cls(**{k: np.empty(0) for k in names})
        return cls(**{k: np.array([r[i] for r in rows]) for i, k in enumerate(names)})

    @classmethod
    def from_columns(cls, columns: Mapping[str, object]) -> Pieces:
        """From a mapping of column name to array; missing parameter columns are 0."""
        unknown = sorted(set(columns) - set(Piece._fields))
        if unknown:
            valid = ", ".join(Piece._fields)
            raise QueryError(f"unknown column {unknown[0]!r}; the columns are {valid}",
                             param=unknown[0])
        need = ("drone", "kind", "t0", "t1")
        for k in need:
            if k not in columns:
                raise QueryError(f"column {k!r} is missing", param=k)
        n = len(np.atleast_1d(columns["t0"]))
        return cls(**{k: columns.get(k, np.zeros(n)) for k in Piece._fields})

    @staticmethod
    def concat(parts: Iterable[Pieces]) -> Pieces:
        """One table of several (say, one :class:`Trajectory` per drone)."""
        parts = list(parts)
        names = Piece._fields
        if not parts:
            return Pieces.from_rows([])
        return Pieces(**{k: np.concatenate([getattr(p, k) for p in parts]) for k in names})

    def table(self) -> np.ndarray:
        """(N, 11) float64 array of the :data:`COLUMNS`, C-contiguous: the checker's input."""
        return np.ascontiguousarray(np.stack([getattr(self, c) for c in COLUMNS], axis=1))

    def order(self) -> np.ndarray:
        """Row indices sorted by drone, then start time (stable)."""
        return np.lexsort((self.t0, self.drone))

    @property
    def drones(self) -> np.ndarray:
        """The drone ids present, sorted."""
        return np.unique(self.drone)

    def rows(self, drone: int) -> np.ndarray:
        """Row indices of one drone's pieces in time order."""
        r = np.flatnonzero(self.drone == drone)
        return r[np.argsort(self.t0[r], kind="stable")]

    def at(self, rows, t) -> np.ndarray:
        """Positions (..., 3) of pieces ``rows`` at times ``t`` (broadcast together),
        by the piece's formula whether or not ``t`` lies in its interval."""
        rows = np.asarray(rows, dtype=np.int64)
        t = np.asarray(t, dtype=float)
        rows, t = np.broadcast_arrays(rows, t)
        tau = t - self.t0[rows]
        arc = self.kind[rows] == ARC
        th = self.angle[rows] + self.rate[rows] * tau
        r = self.radius[rows]
        n = np.where(arc, self.north[rows] + r * np.cos(th),
                     self.north[rows] + self.v_north[rows] * tau)
        e = np.where(arc, self.east[rows] + r * np.sin(th),
                     self.east[rows] + self.v_east[rows] * tau)
        z = self.alt[rows] + self.v_alt[rows] * tau
        return np.stack([n, e, z], axis=-1)

    def start(self) -> np.ndarray:
        """(N, 3) position of every piece at its ``t0``."""
        return self.at(np.arange(len(self)), self.t0)

    def end(self) -> np.ndarray:
        """(N, 3) position of every piece at its ``t1``."""
        return self.at(np.arange(len(self)), self.t1)


def position(pieces: Pieces, t, *, drone: int | None = None) -> np.ndarray:
    """Where drones are at times ``t`` (vectorised): ``t.shape + (3,)`` for one ``drone``,
    else ``(len(pieces.drones),) + t.shape + (3,)`` in the order of ``pieces.drones``.

    NaN where the drone has no airborne piece (on the ground). At a time where one piece
    ends and the next begins the later piece is used (they meet there).
    """
    t = np.asarray(t, dtype=float)
    if drone is None:
        return np.stack([position(pieces, t, drone=d) for d in pieces.drones])
    rows = pieces.rows(drone)
    if len(rows) == 0:
        raise QueryError(f"drone={drone!r} has no pieces", param="drone")
    k = np.searchsorted(pieces.t0[rows], t, side="right") - 1
    row = rows[np.clip(k, 0, len(rows) - 1)]
    out = pieces.at(row, t)
    out[(k < 0) | (t > pieces.t1[row])] = np.nan
    return out


class Jump(NamedTuple):
    """Where one piece of a drone ends at the time the next starts, and how far apart."""

    drone: int
    before: int
    after: int
    t: float
    distance: float


def jumps(pieces: Pieces) -> list[Jump]:
    """Every junction of a drone's consecutive pieces (the next starts exactly when the
    previous ends) with the distance between the two ends; a gap in time is a stay on
    the ground, not a junction."""
    order = pieces.order()
    prev, nxt = order[:-1], order[1:]
    meet = (pieces.drone[prev] == pieces.drone[nxt]) & (pieces.t0[nxt] == pieces.t1[prev])
    prev, nxt = prev[meet], nxt[meet]
    a = pieces.at(prev, pieces.t1[prev])
    b = pieces.at(nxt, pieces.t0[nxt])
    dist = np.linalg.norm(a - b, axis=-1)
    return [Jump(int(pieces.drone[p]), int(p), int(q), float(pieces.t0[q]), float(d))
            for p, q, d in zip(prev, nxt, dist, strict=True)]


def check_continuous(pieces: Pieces, *, tolerance: float = 1e-6) -> None:
    """Raise :class:`QueryError` unless consecutive pieces of every drone meet within
    ``tolerance`` metres."""
    if not (math.isfinite(tolerance) and tolerance >= 0):
        raise QueryError(f"tolerance={tolerance!r} must be a number >= 0", param="tolerance")
    bad = [j for j in jumps(pieces) if not j.distance <= tolerance]
    if bad:
        j = max(bad, key=lambda j: j.distance)
        raise QueryError(f"drone {j.drone} jumps {j.distance:.9g} m at t={j.t} (piece "
                         f"{j.before} to {j.after}); {len(bad)} junction(s) exceed "
                         f"tolerance={tolerance}", param="pieces")


class Trajectory:
    """Builds one drone's pieces, each starting where (and when) the last one ended.

    >>> tr = Trajectory(1, 100.0, (0.0, 0.0, 30.0)).line_to(110.0, (0.0, 250.0, 30.0))
    >>> tr.t, tr.position.tolist()
    (110.0, [0.0, 250.0, 30.0])
    """

    def __init__(self, drone: int, t: float, position) -> None:
        self.drone = int(drone)
        self._t = _finite("t", t)
        self._pos = np.array(_triple("position", position))
        self._rows: list[Piece] = []

    @property
    def t(self) -> float:
        """The time the trajectory has been built up to."""
        return self._t

    @property
    def position(self) -> np.ndarray:
        """Where the drone is at :attr:`t` (a copy)."""
        return self._pos.copy()

    def _until(self, t1: float) -> float:
        t1 = _finite("t1", t1)
        if t1 < self._t:
            raise QueryError(f"t1={t1} is before the trajectory's current time {self._t}",
                             param="t1")
        return t1

    def _add(self, piece: Piece) -> Trajectory:
        self._rows.append(piece)
        self._pos = _end(piece)
        self._t = piece.t1
        return self

    def line(self, t1: float, velocity) -> Trajectory:
        """Fly at constant ``velocity = (v_north, v_east, v_alt)`` until ``t1``."""
        t1 = self._until(t1)
        return self._add(line_piece(self.drone, self._t, t1, self._pos, velocity))

    def line_to(self, t1: float, position) -> Trajectory:
        """Fly straight to ``position``, arriving at ``t1`` (> the current time)."""
        t1 = self._until(t1)
        goal = np.array(_triple("position", position))
        if t1 == self._t:
            raise QueryError(f"t1={t1} must be after the current time to move",
                             param="t1")
        v = (goal - self._pos) / (t1 - self._t)
        self._add(line_piece(self.drone, self._t, t1, self._pos, v))
        self._pos = goal  # exactly where asked, not a rounded end
        return self

    def hold(self, t1: float) -> Trajectory:
        """Stay where the drone is (zero velocity) until ``t1``."""
        return self.line(t1, (0.0, 0.0, 0.0))

    def arc(self, t1: float, centre, rate: float, *, v_alt: float = 0.0) -> Trajectory:
        """Circle ``centre = (north, east)`` from the current position at ``rate`` rad/s
        (> 0 clockwise: a right turn) until ``t1``, climbing at ``v_alt``."""
        t1 = self._until(t1)
        c = np.asarray(centre, dtype=float)
        if c.shape != (2,) or not np.all(np.isfinite(c)):
            raise QueryError(f"centre={centre!r} must be (north, east)", param="centre")
        dn, de = self._pos[0] - c[0], self._pos[1] - c[1]
        r = math.hypot(dn, de)
        if not r > 0:
            raise QueryError(f"centre={centre!r} is where the drone is; a circle needs a "
                             "radius > 0", param="centre")
        return self._add(arc_piece(self.drone, self._t, t1, c, r, math.atan2(de, dn),
                                   _finite("rate", rate), self._pos[2], v_alt=v_alt))

    def ground(self, until: float, position) -> Trajectory:
        """Land here (no airborne piece) until ``until``, then go on from ``position``
        (say, after taxiing to the runway of another airport)."""
        self._t = self._until(until)
        self._pos = np.array(_triple("position", position))
        return self

    def pieces(self) -> Pieces:
        """The pieces built so far."""
        return Pieces.from_rows(self._rows)


def _end(p: Piece) -> np.ndarray:
    """Where piece ``p`` ends (the same formulas as :meth:`Pieces.at`)."""
    d = p.t1 - p.t0
    if p.kind == ARC:
        th = p.angle + p.rate * d
        return np.array([p.north + p.radius * np.cos(th), p.east + p.radius * np.sin(th),
                         p.alt + p.v_alt * d])
    return np.array([p.north + p.v_north * d, p.east + p.v_east * d, p.alt + p.v_alt * d])


def _finite(name: str, value) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise QueryError(f"{name}={value!r} must be a number", param=name) from None
    if not math.isfinite(v):
        raise QueryError(f"{name}={value!r} must be a finite number", param=name)
    return v
