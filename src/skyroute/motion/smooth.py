"""Shortcutting a path of arcs and straights with Dubins connections, compiled.

As OMPL's path simplifier does (``PathSimplifier::shortcutPath``), pairs of poses along
the path are joined by the shortest Dubins path between them, which replaces the part in
between when it costs less and is free. Every new piece is checked by the exact arc test
(:mod:`skyroute.motion.arc_kernels`), so the path stays exactly free. The pairs are the
joints between pieces first (from each joint, the farthest later joint that gives a
shortcut), then random pairs (numba's generator, seeded) until ``patience`` tries in a
row fail or ``max_tries`` is reached.

With ``reverse``, the path may hold pieces driven backwards; a shortcut may then also be
a Dubins path driven wholly in reverse (the forward one of the vehicle turned round),
and costs count reverse length times ``back_cost`` plus ``switch_cost`` per change of
direction, the planner's costs, so a shortcut never adds a cusp that does not pay.

A path is arrays: each piece's start pose (x, y, heading), turn (+1, 0, -1), length and
direction (+1 forward, -1 reverse); pieces after a shortcut keep their own start poses,
so no rounding drifts down the path.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from skyroute.errors import check_seed
from skyroute.motion.arc_kernels import advance, chain_free, chain_reaches
from skyroute.motion.dubins_kernel import TURNS, words
from skyroute.motion.pieces import Piece, chain, turned_round

# numba caches these kernels with dubins_kernel's code compiled in, keyed by this
# file's date alone: edit this file when dubins_kernel changes (as for ZERO, its
# rounding rule), or a checkout keeps running the old words from the cache.


@njit(cache=True)
def _locate(pl, n, s):
    """(piece index, offset in it) of arc length ``s`` along the path."""
    for i in range(n):
        if s <= pl[i] or i == n - 1:
            return i, min(max(s, 0.0), pl[i])
        s -= pl[i]
    return n - 1, pl[n - 1]


@njit(cache=True)
def _splice(px, py, pth, pk, pl, pd, n, i1, t1, i2, t2, ax, ay, ath, dk, dl, dd, bx, by,
            bth, r):
    """The path with [piece i1 at offset t1, piece i2 at offset t2] replaced by the
    pieces (dk, dl) driven in direction dd that run from pose a to pose b."""
    m = n + 5
    qx, qy, qth = np.empty(m), np.empty(m), np.empty(m)
    qk, ql, qd = np.empty(m, np.int64), np.empty(m), np.empty(m)
    c = 0
    for i in range(i1):
        qx[c], qy[c], qth[c], qk[c], ql[c], qd[c] = px[i], py[i], pth[i], pk[i], pl[i], pd[i]
        c += 1
    if t1 > 0:
        qx[c], qy[c], qth[c], qk[c], ql[c], qd[c] = px[i1], py[i1], pth[i1], pk[i1], t1, \
            pd[i1]
        c += 1
    x, y, th = ax, ay, ath
    for p in range(dk.shape[0]):
        if dl[p] > 0:
            qx[c], qy[c], qth[c], qk[c], ql[c], qd[c] = x, y, th, dk[p], dl[p], dd
            c += 1
            x, y, th = advance(x, y, th, dk[p], dd * dl[p], r)
    if pl[i2] - t2 > 0:
        qx[c], qy[c], qth[c], qk[c], ql[c], qd[c] = bx, by, bth, pk[i2], pl[i2] - t2, pd[i2]
        c += 1
    for i in range(i2 + 1, n):
        qx[c], qy[c], qth[c], qk[c], ql[c], qd[c] = px[i], py[i], pth[i], pk[i], pl[i], pd[i]
        c += 1
    return qx, qy, qth, qk, ql, qd, c


@njit(cache=True)
def _cost(pl, pd, n, i1, t1, i2, t2, back_cost, switch_cost):
    """Cost of the part between (i1, t1) and (i2, t2), the direction changes at its two
    ends included; and the directions just before and just after it (0: none)."""
    before = pd[i1] if t1 > 0 else (pd[i1 - 1] if i1 > 0 else 0.0)
    after = pd[i2] if pl[i2] - t2 > 0 else (pd[i2 + 1] if i2 + 1 < n else 0.0)
    cost = 0.0
    last = before
    for i in range(i1, i2 + 1):
        a = t1 if i == i1 else 0.0
        b = t2 if i == i2 else pl[i]
        if b - a <= 0:
            continue
        cost += (b - a) * (back_cost if pd[i] < 0 else 1.0)
        if last * pd[i] < 0:
            cost += switch_cost
        last = pd[i]
    if last * after < 0:
        cost += switch_cost
    return cost, before, after


@njit(cache=True)
def _attempt(px, py, pth, pk, pl, pd, n, s1, s2, r, reverse, back_cost, switch_cost, ed, st,
             it, x0, y0, cell, nx, ny, eps, clear, stamp, tick):
    """Shortcut between arc lengths s1 < s2 if a cheaper free Dubins path (forward, or
    with ``reverse`` also backward) joins them: (changed, new arrays)."""
    i1, t1 = _locate(pl, n, s1)
    i2, t2 = _locate(pl, n, s2)
    ax, ay, ath = advance(px[i1], py[i1], pth[i1], pk[i1], pd[i1] * t1, r)
    bx, by, bth = advance(px[i2], py[i2], pth[i2], pk[i2], pd[i2] * t2, r)
    old, before, after = _cost(pl, pd, n, i1, t1, i2, t2, back_cost, switch_cost)
    best, best_dir, best_w = old - 1e-9, 0.0, -1
    best_segs = np.empty((6, 3))
    for dirn in (1.0, -1.0):
        if dirn < 0 and not reverse:
            break
        flip = 0.0 if dirn > 0 else math.pi  # backwards: the vehicle turned round
        segs, total = words(ax, ay, ath + flip, bx, by, bth + flip, r)
        w = np.argmin(total)
        c = total[w] * (1.0 if dirn > 0 else back_cost)
        if before * dirn < 0:
            c += switch_cost
        if after * dirn < 0:
            c += switch_cost
        if c < best:
            best, best_dir, best_w = c, dirn, w
            best_segs[:] = segs
    if best_w < 0:
        return False, px, py, pth, pk, pl, pd, n
    flip = 0.0 if best_dir > 0 else math.pi
    dk = TURNS[best_w].copy()
    dl = best_segs[best_w].copy()
    if not (chain_reaches(ax, ay, ath + flip, dk, dl, r, bx, by, bth + flip, 1e-3 * eps) and
            chain_free(ax, ay, ath + flip, dk, dl, r, ed, st, it, x0, y0, cell, nx, ny, eps,
                       clear, stamp, tick)):
        return False, px, py, pth, pk, pl, pd, n
    if best_dir < 0:  # as pieces of the vehicle as it is: reverse, turns swapped
        dk = -dk
    qx, qy, qth, qk, ql, qd, c = _splice(px, py, pth, pk, pl, pd, n, i1, t1, i2, t2, ax,
                                         ay, ath, dk, dl, best_dir, bx, by, bth, r)
    return True, qx, qy, qth, qk, ql, qd, c


@njit(cache=True)
def shortcut_kernel(px, py, pth, pk, pl, pd, r, reverse, back_cost, switch_cost, ed, st, it,
                    x0, y0, cell, nx, ny, eps, clear, seed, patience, max_tries):
    """The shortcut path's arrays and their count, and the tries made."""
    n = px.shape[0]
    stamp = np.zeros(ed.shape[0], np.int64)
    tick = np.zeros(1, np.int64)
    tries = 0
    i = 0
    while i < n - 1:
        done = False
        for j in range(n, i + 1, -1):
            s1 = 0.0
            for q in range(i):
                s1 += pl[q]
            s2 = s1
            for q in range(i, j):
                s2 += pl[q]
            tries += 1
            old_n = n
            ok, px, py, pth, pk, pl, pd, n = _attempt(
                px, py, pth, pk, pl, pd, n, s1, s2, r, reverse, back_cost, switch_cost, ed,
                st, it, x0, y0, cell, nx, ny, eps, clear, stamp, tick)
            if ok:
                i += max(1, n - old_n + (j - i))  # past the new pieces
                done = True
                break
        if not done:
            i += 1
    np.random.seed(seed)
    fails = 0
    while fails < patience and tries < max_tries and n > 0:
        total = 0.0
        for q in range(n):
            total += pl[q]
        a, b = np.random.uniform(0.0, total), np.random.uniform(0.0, total)
        tries += 1
        ok, px, py, pth, pk, pl, pd, n = _attempt(
            px, py, pth, pk, pl, pd, n, min(a, b), max(a, b), r, reverse, back_cost,
            switch_cost, ed, st, it, x0, y0, cell, nx, ny, eps, clear, stamp, tick)
        fails = 0 if ok else fails + 1
    return px[:n], py[:n], pth[:n], pk[:n], pl[:n], pd[:n], tries


def shortcut(pieces: list[Piece], radius: float, index, *, seed: int = 0,
             reverse: bool = False, back_cost: float = 1.0, switch_cost: float = 0.0,
             patience: int = 200, max_tries: int = 2000) -> tuple[list[Piece], int]:
    """The path with Dubins shortcuts applied (never costlier), and the tries made.
    ``index``: the world's :class:`~skyroute.motion.arc_kernels.EdgeIndex`."""
    if not pieces:
        return [], 0
    st = np.array([p.start for p in pieces], dtype=float)
    k = np.array([p.k for p in pieces], np.int64)
    ln = np.array([p.length for p in pieces], dtype=float)
    d = np.array([-1.0 if p.reverse else 1.0 for p in pieces])
    px, py, pth, pk, pl, pd, tries = shortcut_kernel(
        st[:, 0].copy(), st[:, 1].copy(), st[:, 2].copy(), k, ln, d, float(radius),
        bool(reverse), float(back_cost), float(switch_cost), *index.args(),
        check_seed(seed), patience, max_tries)
    out = [Piece("LSR"[1 - int(pk[i])], (float(px[i]), float(py[i]), float(pth[i])),
                 float(pl[i]), float(radius), bool(pd[i] < 0)) for i in range(len(px))]
    return out, int(tries)


def length(pieces: list[Piece]) -> float:
    """Total length."""
    return float(sum(p.length for p in pieces))


def dubins_pieces(a, b, radius: float, *, backwards: bool = False) -> list[Piece]:
    """The shortest Dubins path from pose ``a`` to pose ``b`` as pieces; ``backwards``:
    driven wholly in reverse (the forward path of the vehicle turned round)."""
    if backwards:
        a = (a[0], a[1], a[2] + math.pi)
        b = (b[0], b[1], b[2] + math.pi)
    segs, total = words(*a, *b, radius)
    w = int(np.argmin(total))
    out = chain(a, TURNS[w], segs[w], radius)
    return turned_round(out) if backwards else out
