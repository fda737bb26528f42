"""Dubins words for one query, compiled: what a search calls per node.

:mod:`skyroute.motion.dubins` evaluates the six words in numpy for many queries and
:func:`~skyroute.motion.dubins.lengths` compiles only the shortest length
(:mod:`.dubins_batch`, branch-free so that its loops vectorise). A search that
tries analytic expansions needs the words themselves (which word, its three piece
lengths) for one query at a time without leaving compiled code: :func:`words` gives all
six, the same closed forms and the same angle snapping as :func:`dubins._words` (tested
equal), and :func:`free_heading_bound` a lower bound on the shortest path to a point
when the arrival heading is free.

Word k's letters are ``WORDS[k]``; as numbers, ``TURNS[k]`` holds +1 (left), 0
(straight), -1 (right) per piece.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

TWO_PI = 2 * math.pi
WORDS = ("LSL", "RSR", "LSR", "RSL", "RLR", "LRL")
# Rounding at degenerate poses (d in radii). LSL's and RSR's straight p is the distance
# between the two left (right) turning circles' centres, taken as the hypot of its
# components, never the difference of terms of size 4 + d^2 that rounded to p^2 < 0 and
# dropped the word when the goal sat exactly on the start's turning circle. There the
# centres coincide, p and the tangent's angle are rounding noise and the path is one
# arc, b - a: with p <= ZERO x (2 + d) it is taken as that arc (the noisy angle added a
# full circle half the time: a 45-degree turn of r = 1 came out 7.07 long, not 0.79).
# LSR's and RSL's p^2 (centres 2 apart: circles touching) and the CCC words' |cos| <= 1
# are differences too: words within ZERO x (4 + d^2) and ZERO of existing are taken
# with p = 0 (clipped cos). For LSR and RSL that moves the poses by ~1e-12 radii, the
# size of the angle snap; for the CCC words by up to ~1e-6 radii, since acos near 1
# turns a 1e-12 change of its argument into a ~1.4e-6 change of the angle.
# LSR's and RSL's p^2 is summed as d^2 + 2 (cos(a - b) - 1) +- ...: formed as (d^2 - 2) +
# 2 cos(a - b), the first sum dropped d^2's digits below 2e-16, and a goal 1e-6 r
# ahead, off the heading by rounding, got an S-curve angle a hair below 0: a full turn.
ZERO = 1e-12


@njit(cache=True)
def _m2p(a):
    """:func:`_mod2pi` for one angle. Angles in [-4 pi, 4 pi) (all but a caller's own
    headings far from 0) are wrapped by adds instead of a division and a floor: the same
    value to an ulp (a - 2 pi floor(a / 2 pi) is a + 4 pi, a + 2 pi, a or a - 2 pi)."""
    if a < 0:
        if a > -1e-12:
            return 0.0
        if a >= -2 * TWO_PI:
            a += TWO_PI
            if a < 0:
                a += TWO_PI
        else:
            a -= TWO_PI * math.floor(a / TWO_PI)
    elif a >= TWO_PI:
        if a < 2 * TWO_PI:
            a -= TWO_PI
        else:
            a -= TWO_PI * math.floor(a / TWO_PI)
    return 0.0 if TWO_PI - a < 1e-12 else a


TURNS = np.array([[1 if c == "L" else -1 if c == "R" else 0 for c in w] for w in WORDS],
                 dtype=np.int64)


@njit(cache=True)
def words(sx, sy, sth, gx, gy, gth, r):
    """(6, 3) piece lengths in metres of the six words from (sx, sy, sth) to
    (gx, gy, gth), NaN rows where a word does not exist, and (6,) their totals (inf)."""
    out = np.full((6, 3), np.nan)
    total = np.full(6, np.inf)
    dx, dy = gx - sx, gy - sy
    d = math.sqrt(dx * dx + dy * dy) / r
    phi = math.atan2(dy, dx)
    a = _m2p(sth - phi)
    b = _m2p(gth - phi)
    sa, ca, sb, cb = math.sin(a), math.cos(a), math.sin(b), math.cos(b)
    cab = math.cos(a - b)
    dd = d * d
    tol = ZERO * (4.0 + dd)
    arc = ZERO * (2.0 + d)
    x, y = d + sa - sb, cb - ca  # LSL: from the start's left centre to the goal's
    p = math.sqrt(x * x + y * y)
    tmp = a if p <= arc else math.atan2(y, x)  # one circle: no tangent, one arc
    out[0, 0], out[0, 1], out[0, 2] = _m2p(-a + tmp), 0.0 if p <= arc else p, _m2p(b - tmp)
    x, y = d - sa + sb, ca - cb  # RSR
    p = math.sqrt(x * x + y * y)
    tmp = a if p <= arc else math.atan2(y, x)
    out[1, 0], out[1, 1], out[1, 2] = _m2p(a - tmp), 0.0 if p <= arc else p, _m2p(-b + tmp)
    p2 = dd + 2 * (cab - 1.0) + 2 * d * (sa + sb)  # LSR
    if p2 >= -tol:
        p = math.sqrt(max(p2, 0.0))
        tmp = math.atan2(-ca - cb, d + sa + sb) - math.atan2(-2.0, p)
        out[2, 0], out[2, 1], out[2, 2] = _m2p(-a + tmp), p, _m2p(-_m2p(b) + tmp)
    p2 = dd + 2 * (cab - 1.0) - 2 * d * (sa + sb)  # RSL
    if p2 >= -tol:
        p = math.sqrt(max(p2, 0.0))
        tmp = math.atan2(ca + cb, d - sa - sb) - math.atan2(2.0, p)
        out[3, 0], out[3, 1], out[3, 2] = _m2p(a - tmp), p, _m2p(b - tmp)
    c = (6.0 - dd + 2 * cab + 2 * d * (sa - sb)) / 8.0  # RLR
    if abs(c) <= 1 + ZERO:
        p = _m2p(TWO_PI - math.acos(min(max(c, -1.0), 1.0)))
        t = _m2p(a - math.atan2(ca - cb, d - sa + sb) + p / 2)
        out[4, 0], out[4, 1], out[4, 2] = t, p, _m2p(a - b - t + p)
    c = (6.0 - dd + 2 * cab + 2 * d * (sb - sa)) / 8.0  # LRL
    if abs(c) <= 1 + ZERO:
        p = _m2p(TWO_PI - math.acos(min(max(c, -1.0), 1.0)))
        t = _m2p(-a - math.atan2(ca - cb, d + sa - sb) + p / 2)
        out[5, 0], out[5, 1], out[5, 2] = t, p, _m2p(_m2p(b) - a - t + p)
    for k in range(6):
        if not math.isnan(out[k, 0]):
            for j in range(3):
                out[k, j] *= r
            total[k] = out[k, 0] + out[k, 1] + out[k, 2]
    return out, total


@njit(cache=True, inline="always")
def shortest_length(sx, sy, sth, gx, gy, gth, r):
    """Length of the shortest Dubins path (metres): :func:`words` without its arrays
    (the search calls this for every node it generates).

    The same closed forms with less trigonometry: cos(a - b) from the sines and cosines
    at hand (as OMPL does), the two atan2 of LSR and RSL as one atan2 of their angle
    difference (only its value modulo 2 pi matters), LSL's and RSR's tangent angles
    shared with the CCC words. Equal to the six words of :func:`words` to ~1e-14 (tests).
    Branches skip the words that do not exist: one query at a time this is faster than
    :mod:`.dubins_batch`, which runs a loop of queries 4 at a time.
    """
    dx, dy = gx - sx, gy - sy
    d = math.sqrt(dx * dx + dy * dy) / r
    phi = math.atan2(dy, dx)
    a = _m2p(sth - phi)
    b = _m2p(gth - phi)
    if d == 0.0 and _m2p(a - b) < 1e-12:
        # the goal is the start pose: cab below would round to 1 - ulp and drop the
        # zero-length LSR word, leaving only full circles (OMPL special-cases it too)
        return 0.0
    sa, ca, sb, cb = math.sin(a), math.cos(a), math.sin(b), math.cos(b)
    # cos(a - b) rounds to 1 exactly for |a - b| < 1e-8, as the numpy words' cos does;
    # the sum of products may round to 1 - ulp, which drops a vanishing LSR or RSL word
    # when the goal lies a rounding error from the start (d ~ 1e-45): full circles
    cab = 1.0 if abs(a - b) < 1e-8 else ca * cb + sa * sb
    dd = d * d
    tol = ZERO * (4.0 + dd)
    arc = ZERO * (2.0 + d)
    t_lsl = math.atan2(cb - ca, d + sa - sb)
    t_rsr = math.atan2(ca - cb, d - sa + sb)
    p = math.hypot(d + sa - sb, cb - ca)  # LSL (see words: one circle, one arc)
    best = _m2p(b - a) if p <= arc else _m2p(t_lsl - a) + p + _m2p(b - t_lsl)
    p = math.hypot(d - sa + sb, ca - cb)  # RSR
    best = min(best, _m2p(a - b) if p <= arc else _m2p(a - t_rsr) + p + _m2p(t_rsr - b))
    p2 = dd + 2 * (cab - 1.0) + 2 * d * (sa + sb)  # LSR
    if p2 >= -tol:
        p = math.sqrt(max(p2, 0.0))
        # atan2(y, x) - atan2(-2, p), as one atan2 (angle difference, modulo 2 pi)
        y, x = -ca - cb, d + sa + sb
        tmp = math.atan2(y * p + 2 * x, x * p - 2 * y)
        best = min(best, _m2p(tmp - a) + p + _m2p(tmp - b))
    p2 = dd + 2 * (cab - 1.0) - 2 * d * (sa + sb)  # RSL
    if p2 >= -tol:
        p = math.sqrt(max(p2, 0.0))
        y, x = ca + cb, d - sa - sb  # atan2(y, x) - atan2(2, p)
        tmp = math.atan2(y * p - 2 * x, x * p + 2 * y)
        best = min(best, _m2p(a - tmp) + p + _m2p(b - tmp))
    c = (6.0 - dd + 2 * cab + 2 * d * (sa - sb)) / 8.0  # RLR
    if abs(c) <= 1 + ZERO:
        p = _m2p(TWO_PI - math.acos(min(max(c, -1.0), 1.0)))
        t = _m2p(a - t_rsr + p / 2)
        best = min(best, t + p + _m2p(a - b - t + p))
    c = (6.0 - dd + 2 * cab + 2 * d * (sb - sa)) / 8.0  # LRL
    if abs(c) <= 1 + ZERO:
        p = _m2p(TWO_PI - math.acos(min(max(c, -1.0), 1.0)))
        t = _m2p(-a + t_lsl + p / 2)
        best = min(best, t + p + _m2p(_m2p(b) - a - t + p))
    return best * r


@njit(cache=True)
def tangent_heading(sx, sy, sth, gx, gy, r, side):
    """Arrival heading at point g of the path that turns ``side`` (+1 left, -1 right) on
    its start circle, then leaves it on the tangent through g; NaN when g lies strictly
    inside that circle."""
    cx = sx - side * r * math.sin(sth)
    cy = sy + side * r * math.cos(sth)
    dx, dy = gx - cx, gy - cy
    d = math.hypot(dx, dy)
    if d < r:
        return math.nan
    phi = math.atan2(dy, dx)
    alpha = math.acos(min(1.0, r / d))
    return phi - side * alpha + side * math.pi / 2


@njit(cache=True)
def tangent_length(sx, sy, sth, gx, gy, r, side):
    """Length of the turn-then-straight path of :func:`tangent_heading` (inf when g lies
    strictly inside the circle)."""
    cx = sx - side * r * math.sin(sth)
    cy = sy + side * r * math.cos(sth)
    dx, dy = gx - cx, gy - cy
    d = math.hypot(dx, dy)
    if d < r:
        return math.inf
    h = tangent_heading(sx, sy, sth, gx, gy, r, side)
    turn = _m2p(side * (h - sth))  # anticlockwise for a left turn
    return turn * r + math.sqrt(max(0.0, d * d - r * r))


@njit(cache=True)
def free_heading_bound(sx, sy, sth, gx, gy, r):
    """A lower bound on the shortest path from pose s to point g, any arrival heading.

    When g lies outside both turning circles the shortest such path turns on one of them
    and leaves on the tangent through g (Bui, Soueres, Boissonnat & Laumond 1994): the
    smaller of the two tangent paths, exactly. Inside a circle: the straight distance.
    """
    e = math.hypot(gx - sx, gy - sy)
    left = tangent_length(sx, sy, sth, gx, gy, r, 1)
    right = tangent_length(sx, sy, sth, gx, gy, r, -1)
    if math.isinf(left) or math.isinf(right):
        return e
    return max(e, min(left, right))
