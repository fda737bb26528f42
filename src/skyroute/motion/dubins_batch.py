"""The shortest Dubins length of many queries at once, compiled to run 4 per AVX2 lane.

The same closed forms and sharing as :func:`skyroute.motion.dubins_kernel.shortest_length`
(cos(a - b) from the sines and cosines, LSR's and RSL's two atan2 as one, LSL's and
RSR's tangent angles shared with the CCC words), but with no branches and no libm calls
(:mod:`.trig`): all six words are evaluated and a missing one is inf, so that a loop of
queries vectorises.

The queries run in blocks of :data:`BLOCK`, the blocks across cores. Within a block the
work goes in stages, each a plain loop over the block: the bearing angle of every query,
then the sines and cosines, then the six other angles of every query (the tangent
angles and the two arccosines, as atan2), in one loop of 6 x BLOCK atan2, then the
lengths. So each polynomial is compiled into one loop only: written as one function per
query, numba inlined atan2 seven times and the batch took 100 s to compile (3 s now),
for the same vector code.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from skyroute.motion import trig
from skyroute.motion.dubins_kernel import ZERO

TWO_PI = 2 * math.pi
BLOCK = 512  # queries per block: its scratch (14 x BLOCK doubles) stays in L1 and L2


@njit(cache=True, error_model="numpy")
def _wrap(a):
    """:func:`~skyroute.motion.dubins_kernel._m2p` without branches (selects, so that a
    loop of it vectorises): the same value for every a (both of its ways are computed,
    one is kept)."""
    u = a + (TWO_PI if a < 0.0 else 0.0) - (TWO_PI if a >= TWO_PI else 0.0)
    u = u + (TWO_PI if u < 0.0 else 0.0)
    w = a - TWO_PI * np.floor(a / TWO_PI)
    u = u if (a >= -2 * TWO_PI) & (a < 2 * TWO_PI) else w
    u = 0.0 if (a < 0.0) & (a > -1e-12) else u
    return 0.0 if TWO_PI - u < 1e-12 else u


@njit(cache=True, error_model="numpy")
def _wrap_near(a):
    """:func:`_wrap` for a in [-4 pi, 4 pi) (sums of angles already wrapped): adds only."""
    u = a + (TWO_PI if a < 0.0 else 0.0) - (TWO_PI if a >= TWO_PI else 0.0)
    u = u + (TWO_PI if u < 0.0 else 0.0)
    u = 0.0 if (a < 0.0) & (a > -1e-12) else u
    return 0.0 if TWO_PI - u < 1e-12 else u


@njit(cache=True, error_model="numpy")
def _atan2_all(y, x, out, k):
    """out[:k] = atan2(y[:k], x[:k]): the one loop :func:`trig.atan2` is compiled into."""
    for i in range(k):
        out[i] = trig.atan2(y[i], x[i])


@njit(cache=True, error_model="numpy")
def _block(sf, gf, r, out, lo, hi):
    """out[lo:hi]: the shortest lengths of queries lo..hi-1 (flat (N * 3) poses)."""
    m = hi - lo
    d = np.empty(m)
    ang = np.empty(2 * m)  # a, then b
    sn = np.empty(2 * m)
    cs = np.empty(2 * m)
    y = np.empty(6 * m)
    x = np.empty(6 * m)
    t = np.empty(6 * m)
    for i in range(m):  # the bearing from start to goal
        j = 3 * (lo + i)
        dx, dy = gf[j] - sf[j], gf[j + 1] - sf[j + 1]
        d[i] = math.sqrt(dx * dx + dy * dy) / r
        y[i], x[i] = dy, dx
    _atan2_all(y, x, t, m)
    for i in range(m):  # headings relative to the bearing
        j = 3 * (lo + i)
        ang[i] = _wrap(sf[j + 2] - t[i])
        ang[m + i] = _wrap(gf[j + 2] - t[i])
    for i in range(2 * m):
        sn[i], cs[i] = trig.sincos(ang[i])
    for i in range(m):  # the six angles as atan2 arguments: slot k at k * m + i
        a, b = ang[i], ang[m + i]
        sa, ca, sb, cb = sn[i], cs[i], sn[m + i], cs[m + i]
        dd, di = d[i] * d[i], d[i]
        cab = 1.0 if abs(a - b) < 1e-8 else ca * cb + sa * sb
        y[i], x[i] = cb - ca, di + sa - sb  # LSL's tangent angle (and LRL's)
        y[m + i], x[m + i] = ca - cb, di - sa + sb  # RSR's (and RLR's)
        p = math.sqrt(max(dd + 2 * (cab - 1.0) + 2 * di * (sa + sb), 0.0))
        yy, xx = -ca - cb, di + sa + sb  # LSR: atan2(yy, xx) - atan2(-2, p) as one atan2
        y[2 * m + i], x[2 * m + i] = yy * p + 2 * xx, xx * p - 2 * yy
        p = math.sqrt(max(dd + 2 * (cab - 1.0) - 2 * di * (sa + sb), 0.0))
        yy, xx = ca + cb, di - sa - sb  # RSL: atan2(yy, xx) - atan2(2, p)
        y[3 * m + i], x[3 * m + i] = yy * p - 2 * xx, xx * p + 2 * yy
        # RLR and LRL: acos(c) as trig.acos does it, atan2(sqrt((1 - c)(1 + c)), c)
        c = min(max((6.0 - dd + 2 * cab + 2 * di * (sa - sb)) / 8.0, -1.0), 1.0)
        y[4 * m + i], x[4 * m + i] = math.sqrt((1.0 - c) * (1.0 + c)), c
        c = min(max((6.0 - dd + 2 * cab + 2 * di * (sb - sa)) / 8.0, -1.0), 1.0)
        y[5 * m + i], x[5 * m + i] = math.sqrt((1.0 - c) * (1.0 + c)), c
    _atan2_all(y, x, t, 6 * m)
    inf = math.inf
    for i in range(m):  # the six words' lengths; the shortest
        a, b = ang[i], ang[m + i]
        sa, ca, sb, cb = sn[i], cs[i], sn[m + i], cs[m + i]
        dd, di = d[i] * d[i], d[i]
        cab = 1.0 if abs(a - b) < 1e-8 else ca * cb + sa * sb
        t_lsl, t_rsr = t[i], t[m + i]
        tol = -ZERO * (4.0 + dd)  # rounding: a word this close to existing exists
        arc = ZERO * (2.0 + di)  # LSL and RSR: one arc when the centres coincide
        x, y = di + sa - sb, cb - ca  # LSL
        p = math.sqrt(x * x + y * y)
        w = _wrap_near(t_lsl - a) + p + _wrap_near(b - t_lsl)
        best = _wrap_near(b - a) if p <= arc else w
        x, y = di - sa + sb, ca - cb  # RSR
        p = math.sqrt(x * x + y * y)
        w = _wrap_near(a - t_rsr) + p + _wrap_near(t_rsr - b)
        best = min(best, _wrap_near(a - b) if p <= arc else w)
        p2 = dd + 2 * (cab - 1.0) + 2 * di * (sa + sb)  # LSR
        tmp = t[2 * m + i]
        w = _wrap_near(tmp - a) + math.sqrt(max(p2, 0.0)) + _wrap_near(tmp - b)
        best = min(best, w if p2 >= tol else inf)
        p2 = dd + 2 * (cab - 1.0) - 2 * di * (sa + sb)  # RSL
        tmp = t[3 * m + i]
        w = _wrap_near(a - tmp) + math.sqrt(max(p2, 0.0)) + _wrap_near(b - tmp)
        best = min(best, w if p2 >= tol else inf)
        c = (6.0 - dd + 2 * cab + 2 * di * (sa - sb)) / 8.0  # RLR
        p = _wrap_near(TWO_PI - t[4 * m + i])
        u = _wrap_near(a - t_rsr + p / 2)
        w = u + p + _wrap_near(a - b - u + p)
        best = min(best, w if abs(c) <= 1 + ZERO else inf)
        c = (6.0 - dd + 2 * cab + 2 * di * (sb - sa)) / 8.0  # LRL
        p = _wrap_near(TWO_PI - t[5 * m + i])
        u = _wrap_near(-a + t_lsl + p / 2)
        w = u + p + _wrap_near(b - a - u + p)
        best = min(best, w if abs(c) <= 1 + ZERO else inf)
        # the goal is the start pose: cab above rounds to 1 - ulp and drops the
        # zero-length LSR word, leaving only full circles (OMPL special-cases it too)
        same = (di == 0.0) & (_wrap_near(a - b) < 1e-12)
        out[lo + i] = 0.0 if same else best * r


@njit(cache=True, parallel=True, error_model="numpy")
def lengths_kernel(s, g, r):
    """Shortest lengths for (N, 3) C-contiguous start and goal poses, blocks across
    cores."""
    n = s.shape[0]
    sf, gf = s.reshape(-1), g.reshape(-1)
    out = np.empty(n)
    for k in prange((n + BLOCK - 1) // BLOCK):
        _block(sf, gf, r, out, k * BLOCK, min(n, (k + 1) * BLOCK))
    return out
