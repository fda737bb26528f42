"""Shortcutting a path of arcs and straights with Dubins connections.

As OMPL's path simplifier does (``PathSimplifier::shortcutPath``), pairs of poses along
the path are joined by the shortest Dubins path between them, which replaces the part in
between when it is shorter and free. Every new piece is checked by the exact arc test
(:mod:`skyroute.motion.arc_kernels`), so the path stays exactly free. The pairs are the
joints between pieces first (from each joint, the farthest later joint that gives a
shortcut), then random pairs from a seeded generator until ``patience`` tries in a row
fail.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from skyroute.motion.dubins_kernel import TURNS, words
from skyroute.motion.pieces import Piece, chain


def length(pieces: list[Piece]) -> float:
    """Total length."""
    return float(sum(p.length for p in pieces))


def split(pieces: list[Piece], s: float) -> tuple[list[Piece], list[Piece]]:
    """The chain cut ``s`` metres from its start into (before, after)."""
    before: list[Piece] = []
    for i, p in enumerate(pieces):
        if s >= p.length:
            before.append(p)
            s -= p.length
            continue
        after = list(pieces[i + 1:])
        if s > 0:
            before.append(Piece(p.kind, p.start, s, p.radius, p.reverse))
            mid = tuple(float(v) for v in p.poses(np.array([s]))[0])
            after.insert(0, Piece(p.kind, mid, p.length - s, p.radius, p.reverse))
        else:
            after.insert(0, p)
        return before, after
    return before, []


def pose_at(pieces: list[Piece], s: float, start) -> tuple[float, float, float]:
    """The pose ``s`` metres along the chain that begins at ``start``."""
    for p in pieces:
        if s <= p.length:
            return tuple(float(v) for v in p.poses(np.array([s]))[0])
        s -= p.length
    return pieces[-1].end if pieces else tuple(start)


def dubins_pieces(a, b, radius: float) -> list[Piece]:
    """The shortest Dubins path from pose ``a`` to pose ``b`` as pieces."""
    segs, total = words(*a, *b, radius)
    w = int(np.argmin(total))
    return chain(a, TURNS[w], segs[w], radius)


def shortcut(pieces: list[Piece], start, radius: float, free: Callable[[list[Piece]], bool],
             rng: np.random.Generator, *, patience: int = 40,
             max_tries: int = 400) -> tuple[list[Piece], int]:
    """The path with Dubins shortcuts applied (never longer); also the number of tries."""
    tries = 0
    path = list(pieces)
    # joints: from each, the farthest later joint that a shorter free Dubins path reaches
    i = 0
    while i < len(path) - 1:
        done = False
        for j in range(len(path), i + 1, -1):
            a = path[i].start
            b = path[j].start if j < len(path) else path[-1].end
            old = length(path[i:j])
            tries += 1
            new = dubins_pieces(a, b, radius)
            if length(new) < old - 1e-9 and free(new):
                path = path[:i] + new + path[j:]
                done = True
                break
        i = i + 1 if not done else i + max(1, len(new))
    # random pairs, until ``patience`` fail in a row
    fails = 0
    while fails < patience and tries < max_tries and path:
        total = length(path)
        s1, s2 = np.sort(rng.uniform(0.0, total, 2))
        if s2 - s1 < 1e-9 * max(1.0, total):
            fails += 1
            continue
        tries += 1
        a, b = pose_at(path, s1, start), pose_at(path, s2, start)
        new = dubins_pieces(a, b, radius)
        if length(new) < (s2 - s1) - 1e-9 and free(new):
            head, rest = split(path, s1)
            _, tail = split(rest, s2 - s1)
            path = head + new + tail
            fails = 0
        else:
            fails += 1
    return path, tries
