"""Paths of circular arcs and straights, as data: what a turning-radius vehicle flies.

A :class:`Piece` starts at a pose (x, y, heading; heading in radians anticlockwise from
+x) and runs ``length`` metres: a left ("L", anticlockwise) or right ("R") arc of
``radius``, or a straight ("S"); ``reverse`` pieces are driven backwards (the heading
still names where the vehicle's nose points). :func:`sample` walks a chain of pieces.

>>> p = Piece("L", (0.0, 0.0, 0.0), math.pi / 2, 1.0)
>>> [round(v, 12) for v in p.end]
[1.0, 1.0, 1.570796326795]
>>> p.centre, p.turn == math.pi / 2
((0.0, 1.0), True)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from skyroute.errors import OptionError

TWO_PI = 2 * math.pi
KINDS = {"L": 1, "S": 0, "R": -1}
MAX_SAMPLES = 10**7  # poses one sampling returns (240 MB); more is an OptionError


def check_samples(length: float, step: float) -> None:
    """An OptionError naming ``step`` when a path ``length`` long sampled every ``step``
    would come out more than :data:`MAX_SAMPLES` poses (a step of 1e-7 along 250 m
    asked for 2.5 billion, and ended in a MemoryError after gigabytes)."""
    if length / step > MAX_SAMPLES:
        raise OptionError(f"step={step:g} along a path {length:g} long makes more than "
                          f"{MAX_SAMPLES:,} poses; take a step >= {length / MAX_SAMPLES:.3g}",
                          param="step")


@dataclass(frozen=True)
class Piece:
    """One arc or straight of a path."""

    kind: str
    start: tuple[float, float, float]
    length: float
    radius: float
    reverse: bool = False

    @property
    def k(self) -> int:
        """+1 left, 0 straight, -1 right."""
        return KINDS[self.kind]

    @property
    def signed_length(self) -> float:
        """The length, negative when driven in reverse."""
        return -self.length if self.reverse else self.length

    @property
    def turn(self) -> float:
        """Signed heading change in radians (0 for a straight)."""
        return self.k * self.signed_length / self.radius

    @property
    def centre(self) -> tuple[float, float] | None:
        """Centre of an arc's circle; None for a straight."""
        if self.k == 0:
            return None
        x, y, th = self.start
        return (x - self.k * self.radius * math.sin(th), y + self.k * self.radius * math.cos(th))

    @property
    def start_angle(self) -> float | None:
        """Angle of the start point seen from the centre; None for a straight."""
        c = self.centre
        if c is None:
            return None
        return math.atan2(self.start[1] - c[1], self.start[0] - c[0])

    @property
    def end(self) -> tuple[float, float, float]:
        """The pose where the piece ends."""
        return tuple(float(v) for v in self.poses(np.array([self.length]))[0])

    def poses(self, s: np.ndarray) -> np.ndarray:
        """(K, 3) poses after ``s`` metres along the piece (0 <= s <= length)."""
        s = np.asarray(s, dtype=float)
        u = -s if self.reverse else s
        x, y, th = self.start
        if self.k == 0:
            return np.c_[x + u * math.cos(th), y + u * math.sin(th), np.full(len(s), th)]
        kr = self.k * self.radius
        h = th + self.k * u / self.radius
        return np.c_[x + kr * (np.sin(h) - math.sin(th)), y - kr * (np.cos(h) - math.cos(th)),
                     h]


def chain(start, turns, lengths, radius: float, reverse=None) -> list[Piece]:
    """Pieces laid end to end from pose ``start``; zero-length pieces are dropped.
    ``turns`` +1/0/-1, ``lengths`` >= 0 (``reverse`` flags, default all forward)."""
    out = []
    pose = tuple(float(v) for v in start)
    rev = [False] * len(turns) if reverse is None else list(reverse)
    for k, length, back in zip(turns, lengths, rev, strict=True):
        if length <= 0:
            continue
        p = Piece("LSR"[1 - int(k)], pose, float(length), float(radius), bool(back))
        out.append(p)
        pose = p.end
    return out


_SWAP = {"L": "R", "R": "L", "S": "S"}


def turned_round(pieces: list[Piece]) -> list[Piece]:
    """The same curves driven the other way round: a vehicle whose nose points the other
    way (heading + pi) covers each piece in the same direction of travel with the
    reverse flag toggled, and a left turn of one is a right turn of the other."""
    return [Piece(_SWAP[p.kind], (p.start[0], p.start[1], p.start[2] + math.pi), p.length,
                  p.radius, not p.reverse) for p in pieces]


def time_reversed(pieces: list[Piece]) -> list[Piece]:
    """The chain run backwards in time: last piece first, each from its end to its start
    with the nose kept (so forward pieces become reverse ones, and the other way)."""
    return [Piece(p.kind, p.end, p.length, p.radius, not p.reverse) for p in reversed(pieces)]


def merge(pieces: list[Piece]) -> list[Piece]:
    """Consecutive pieces of one kind and direction fused into one (the pose at the join
    is recomputed from the first piece's start, so the chain stays continuous)."""
    out: list[Piece] = []
    for p in pieces:
        if out and out[-1].kind == p.kind and out[-1].reverse == p.reverse and \
                out[-1].radius == p.radius:
            q = out[-1]
            out[-1] = Piece(q.kind, q.start, q.length + p.length, q.radius, q.reverse)
        else:
            out.append(p)
    return out


def drop_slivers(pieces: list[Piece], tol: float) -> list[Piece]:
    """The chain without its pieces shorter than ``tol`` (slivers such as the 1e-15 m
    arc a Dubins word ends with when rounding leaves it): sampled, a sliver repeats the
    pose it starts at. The chain stays continuous to within the slivers' total length;
    pieces that come to meet end to end are fused (:func:`merge`)."""
    return merge([p for p in pieces if p.length >= tol])


def sample(pieces: list[Piece], step: float, start, goal=None) -> np.ndarray:
    """(K, 3) poses every ``step`` metres along the chain (and at every joint); the first
    row is exactly ``start``, the last exactly ``goal`` when given. Headings in [0, 2 pi).
    More than :data:`MAX_SAMPLES` poses is an OptionError naming ``step``."""
    check_samples(sum(p.length for p in pieces), step)
    rows = [np.array([start], dtype=float)]
    for p in pieces:
        n = max(1, math.ceil(p.length / step - 1e-12))
        rows.append(p.poses(np.linspace(0.0, p.length, n + 1)[1:]))
    if goal is not None and not pieces and tuple(goal) != tuple(start):
        rows.append(np.array([goal], dtype=float))  # start and goal within rounding
    out = np.vstack(rows)
    out[0] = start
    if goal is not None:
        out[-1] = goal
    out[:, 2] = np.mod(out[:, 2], TWO_PI)
    out[:, 2][out[:, 2] >= TWO_PI] = 0.0
    return out
