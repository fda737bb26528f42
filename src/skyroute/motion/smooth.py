"""Shortcutting a path of arcs and straights with Dubins connections, compiled.

As OMPL's path simplifier does (``PathSimplifier::shortcutPath``), pairs of poses along
the path are joined by the shortest Dubins path between them, which replaces the part in
between when it is shorter and free. Every new piece is checked by the exact arc test
(:mod:`skyroute.motion.arc_kernels`), so the path stays exactly free. The pairs are the
joints between pieces first (from each joint, the farthest later joint that gives a
shortcut), then random pairs (numba's generator, seeded) until ``patience`` tries in a
row fail or ``max_tries`` is reached.

A path is arrays: each piece's start pose (x, y, heading), turn (+1, 0, -1) and length;
pieces after a shortcut keep their own start poses, so no rounding drifts down the path.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from skyroute.motion.arc_kernels import advance, chain_free
from skyroute.motion.dubins_kernel import TURNS, words
from skyroute.motion.pieces import Piece


@njit(cache=True)
def _locate(pl, n, s):
    """(piece index, offset in it) of arc length ``s`` along the path."""
    for i in range(n):
        if s <= pl[i] or i == n - 1:
            return i, min(max(s, 0.0), pl[i])
        s -= pl[i]
    return n - 1, pl[n - 1]


@njit(cache=True)
def _splice(px, py, pth, pk, pl, n, i1, t1, i2, t2, ax, ay, ath, dk, dl, bx, by, bth, r):
    """The path with [piece i1 at offset t1, piece i2 at offset t2] replaced by the
    pieces (dk, dl) that run from pose a to pose b."""
    m = n + 5
    qx, qy, qth = np.empty(m), np.empty(m), np.empty(m)
    qk, ql = np.empty(m, np.int64), np.empty(m)
    c = 0
    for i in range(i1):
        qx[c], qy[c], qth[c], qk[c], ql[c] = px[i], py[i], pth[i], pk[i], pl[i]
        c += 1
    if t1 > 0:
        qx[c], qy[c], qth[c], qk[c], ql[c] = px[i1], py[i1], pth[i1], pk[i1], t1
        c += 1
    x, y, th = ax, ay, ath
    for p in range(dk.shape[0]):
        if dl[p] > 0:
            qx[c], qy[c], qth[c], qk[c], ql[c] = x, y, th, dk[p], dl[p]
            c += 1
            x, y, th = advance(x, y, th, dk[p], dl[p], r)
    if pl[i2] - t2 > 0:
        qx[c], qy[c], qth[c], qk[c], ql[c] = bx, by, bth, pk[i2], pl[i2] - t2
        c += 1
    for i in range(i2 + 1, n):
        qx[c], qy[c], qth[c], qk[c], ql[c] = px[i], py[i], pth[i], pk[i], pl[i]
        c += 1
    return qx, qy, qth, qk, ql, c


@njit(cache=True)
def _attempt(px, py, pth, pk, pl, n, s1, s2, r, ed, st, it, x0, y0, cell, nx, ny, eps,
             clear, stamp, tick):
    """Shortcut between arc lengths s1 < s2 if a shorter free Dubins path joins them:
    (changed, new arrays)."""
    i1, t1 = _locate(pl, n, s1)
    i2, t2 = _locate(pl, n, s2)
    ax, ay, ath = advance(px[i1], py[i1], pth[i1], pk[i1], t1, r)
    bx, by, bth = advance(px[i2], py[i2], pth[i2], pk[i2], t2, r)
    segs, total = words(ax, ay, ath, bx, by, bth, r)
    w = np.argmin(total)
    if not total[w] < (s2 - s1) - 1e-9:
        return False, px, py, pth, pk, pl, n
    dk = TURNS[w].copy()
    dl = segs[w].copy()
    if not chain_free(ax, ay, ath, dk, dl, r, ed, st, it, x0, y0, cell, nx, ny, eps, clear,
                      stamp, tick):
        return False, px, py, pth, pk, pl, n
    qx, qy, qth, qk, ql, c = _splice(px, py, pth, pk, pl, n, i1, t1, i2, t2, ax, ay, ath,
                                     dk, dl, bx, by, bth, r)
    return True, qx, qy, qth, qk, ql, c


@njit(cache=True)
def shortcut_kernel(px, py, pth, pk, pl, r, ed, st, it, x0, y0, cell, nx, ny, eps, clear,
                    seed,
                    patience, max_tries):
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
            ok, px, py, pth, pk, pl, n = _attempt(px, py, pth, pk, pl, n, s1, s2, r, ed, st,
                                                  it, x0, y0, cell, nx, ny, eps, clear,
                                                  stamp, tick)
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
        s1, s2 = min(a, b), max(a, b)
        tries += 1
        ok, px, py, pth, pk, pl, n = _attempt(px, py, pth, pk, pl, n, s1, s2, r, ed, st, it,
                                              x0, y0, cell, nx, ny, eps, clear, stamp,
                                              tick)
        fails = 0 if ok else fails + 1
    return px[:n], py[:n], pth[:n], pk[:n], pl[:n], tries


def shortcut(pieces: list[Piece], radius: float, index, *, seed: int = 0,
             patience: int = 200, max_tries: int = 2000) -> tuple[list[Piece], int]:
    """The path with Dubins shortcuts applied (never longer), and the tries made.
    ``index``: the world's :class:`~skyroute.motion.arc_kernels.EdgeIndex`."""
    if not pieces:
        return [], 0
    st = np.array([p.start for p in pieces], dtype=float)
    k = np.array([p.k for p in pieces], np.int64)
    ln = np.array([p.length for p in pieces], dtype=float)
    px, py, pth, pk, pl, tries = shortcut_kernel(
        st[:, 0].copy(), st[:, 1].copy(), st[:, 2].copy(), k, ln, float(radius),
        *index.args(), int(seed) % (2**32), patience, max_tries)
    out = [Piece("LSR"[1 - int(pk[i])], (float(px[i]), float(py[i]), float(pth[i])),
                 float(pl[i]), float(radius)) for i in range(len(px))]
    return out, int(tries)


def length(pieces: list[Piece]) -> float:
    """Total length."""
    return float(sum(p.length for p in pieces))


def dubins_pieces(a, b, radius: float) -> list[Piece]:
    """The shortest Dubins path from pose ``a`` to pose ``b`` as pieces."""
    from skyroute.motion.pieces import chain

    segs, total = words(*a, *b, radius)
    w = int(np.argmin(total))
    return chain(a, TURNS[w], segs[w], radius)
