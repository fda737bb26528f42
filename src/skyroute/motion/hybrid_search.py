"""Hybrid A*'s search, compiled whole: plain arrays in, a parent tree out.

Nodes keep their continuous pose (x, y, heading); a state is the closed-set key
(cell x, cell y, heading bin), and a node reaching a state that is open with a larger g
takes it over (its pose becomes the new one), as in Dolgov et al. Each expansion applies
the primitives (turn k, signed length u, cost c) that :func:`piece_free` passes.

Heuristic: h = max(Dubins length to the goal ignoring obstacles (to the goal pose, or
to the goal point with any heading), the obstacle-avoiding 2D distance). Both are lower
bounds of the remaining length; ``weight`` > 1 turns the search into weighted A*
(default 1). The 2D term (:func:`corner_distance.lower_bound`, from a per-goal corner
table) costs a scan of the corners and sight tests (through the edge grid of
:mod:`skyroute.motion.edge_grid`, as the goal sight test), so a new node first gets
the cheap bound max(|q - goal|, d2(parent) - |u|) (the 2D distance is 1-Lipschitz and
a primitive moves at most |u|) and the exact one when it reaches the top of the heap;
if that raises its f it goes back in.

Analytic expansion: the popped node tries a Dubins path to the goal (the shortest words
first; for a free goal heading, the two turn-then-tangent paths, and every heading bin
when the goal is inside a turning circle) when it sees the goal or every ``every``
expansions. A free one is a solution candidate of cost g + its length; the search goes
on while some open node could still beat the best candidate (f < best), so the answer is
the best path this lattice and these expansions can give, not the first one met.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, types
from numba.typed import Dict

from skyroute.motion.arc_kernels import advance, chain_free, chain_reaches, piece_free
from skyroute.motion.corner_distance import lower_bound
from skyroute.motion.dubins_kernel import (
    TURNS,
    free_heading_bound,
    shortest_length,
    tangent_heading,
    words,
)
from skyroute.motion.zone_kernels import sight
from skyroute.result import BUDGET_EXHAUSTED, FOUND, NO_PATH
from skyroute.search import heap, interrupt

# numba caches these kernels with dubins_kernel's code compiled in (and
# corner_distance's bound, zone_kernels' sight, edge_grid's bucket walk and interrupt's
# poll), keyed by this file's date alone: edit this file when one of those changes (as
# for ZERO, the words' rounding rule), or a checkout keeps running the old code from
# the cache.

TWO_PI = 2 * math.pi


@njit(cache=True)
def dubins_bound(x, y, th, gx, gy, gth, has_heading, r, reverse):
    """The obstacle-free Dubins length to the goal pose, or a lower bound on it to the
    goal point with any heading. With ``reverse`` (Reeds-Shepp motion) a weaker bound:
    the path covers the straight distance and turns at least the heading change, at a
    radius of at least r."""
    if reverse:
        d = math.hypot(gx - x, gy - y)
        if has_heading:
            turn = abs((gth - th + math.pi) % TWO_PI - math.pi)
            return max(d, r * turn)
        return d
    if has_heading:
        return shortest_length(x, y, th, gx, gy, gth, r)
    return free_heading_bound(x, y, th, gx, gy, r)


@njit(cache=True)
def _analytic(x, y, th, g, scale, best, gx, gy, gth, has_heading, r, ref, dth, H,
              max_words, ed, st, it, x0, y0, cell, nx, ny, eps, clear, stamp, tick):
    """The shortest free Dubins connection from pose (x, y, th) whose cost, g + ``scale``
    times its length, beats ``best``: (that cost or inf, goal heading, word index)."""
    n = 1 if has_heading else 2 + H
    heads = np.empty(n)
    if has_heading:
        heads[0] = gth
    else:
        heads[0] = tangent_heading(x, y, th, gx, gy, r, 1)
        heads[1] = tangent_heading(x, y, th, gx, gy, r, -1)
        if math.isnan(heads[0]) or math.isnan(heads[1]):
            for b in range(H):
                heads[2 + b] = ref + b * dth
        else:
            n = 2
    cand_len = np.empty(6 * n)
    cand_head = np.empty(6 * n)
    cand_word = np.empty(6 * n, np.int64)
    m = 0
    for j in range(n):
        h = heads[j]
        if math.isnan(h):
            continue
        segs, total = words(x, y, th, gx, gy, h, r)
        order = np.argsort(total)
        for q in range(max_words if has_heading else 1):
            w = order[q]
            if g + scale * total[w] < best and not math.isinf(total[w]):
                cand_len[m] = total[w]
                cand_head[m] = h
                cand_word[m] = w
                m += 1
    if m == 0:
        return math.inf, 0.0, -1
    order = np.argsort(cand_len[:m])
    turns = np.empty(3, np.int64)
    lens = np.empty(3)
    for q in range(min(m, max_words)):
        c = order[q]
        segs, _ = words(x, y, th, gx, gy, cand_head[c], r)
        w = cand_word[c]
        for p in range(3):
            turns[p] = TURNS[w, p]
            lens[p] = segs[w, p]
        if chain_reaches(x, y, th, turns, lens, r, gx, gy, cand_head[c], 1e-3 * eps) and \
                chain_free(x, y, th, turns, lens, r, ed, st, it, x0, y0, cell, nx, ny, eps,
                           clear, stamp, tick):
            return g + scale * cand_len[c], cand_head[c], w
    return math.inf, 0.0, -1


@njit(cache=True)
def search(seeds, gx, gy, gth, has_heading, r, prim_k, prim_u, prim_c, ref, dth, H, cell,
           region, ed, st, it, x0, y0, bcell, nx, ny, eps, clear, corners, cdist,
           sight_edges, smeta, sstart, sids, sight_tests, weight, max_expansions, every,
           max_words, reverse, back_cost, switch_cost):
    """Hybrid A* from the poses ``seeds`` (S, 3) to the goal.

    ``region`` (xmin, ymin, xmax, ymax): nodes outside it are dropped (states are keyed
    relative to its corner). With ``reverse``, primitives with u < 0 drive backwards
    (their costs in ``prim_c``), each change of direction costs ``switch_cost``, and the
    analytic expansion also tries Dubins paths driven wholly in reverse (length times
    ``back_cost``): the forward Dubins path of the vehicle turned round. Returns (status,
    end node, goal heading, word, analytic path driven backwards, best cost, expanded,
    analytic tries, x, y, th, parent, primitive); status
    :data:`skyroute.search.interrupt.INTERRUPTED` when its poll saw a SIGINT (Ctrl-C).
    """
    cap = 4096
    x = np.empty(cap)
    y = np.empty(cap)
    th = np.empty(cap)
    g = np.empty(cap)
    hd = np.empty(cap)  # Dubins bound
    d2 = np.empty(cap)  # 2D distance bound (exact once ``exact``)
    fq = np.empty(cap)  # f of the node's latest heap entry
    parent = np.empty(cap, np.int64)
    prim = np.empty(cap, np.int64)
    closed = np.zeros(cap, np.bool_)
    exact = np.zeros(cap, np.bool_)
    hf = np.empty(cap)
    hn = np.empty(cap, np.int64)
    seen = Dict.empty(key_type=types.int64, value_type=types.int64)
    stamp = np.zeros(ed.shape[0], np.int64)
    tick = np.zeros(1, np.int64)
    scratch = np.empty(corners.shape[0])
    picks = np.empty(corners.shape[0], np.int64)
    cols = np.ascontiguousarray(corners.T)  # (2, N): the bound's first pass vectorised
    ny_cells = np.int64(math.floor((region[3] - region[1]) / cell)) + 1
    n = 0
    size = 0
    for s in range(seeds.shape[0]):
        sx, sy, sth = seeds[s, 0], seeds[s, 1], seeds[s, 2]
        b = np.int64(round((sth - ref) / dth)) % H
        key = ((np.int64(math.floor((sx - region[0]) / cell)) * ny_cells +
                np.int64(math.floor((sy - region[1]) / cell))) * H + b)
        if key in seen:
            continue
        seen[key] = n
        x[n], y[n], th[n], g[n] = sx, sy, sth, 0.0
        parent[n], prim[n] = -1, -1
        hd[n] = dubins_bound(sx, sy, sth, gx, gy, gth, has_heading, r, reverse)
        d2[n] = math.hypot(gx - sx, gy - sy)
        fq[n] = weight * max(hd[n], d2[n])
        heap.push_plain(hf, hn, size, fq[n], n)
        size += 1
        n += 1
    best = math.inf
    end, end_head, end_word, end_back = -1, 0.0, -1, False
    expanded = 0
    tries = 0
    stopped = False
    while size > 0:
        f = hf[0]
        i = heap.pop_plain(hf, hn, size)
        size -= 1
        if closed[i] or f != fq[i]:
            continue  # stale entry
        if f >= best * (1.0 - 1e-12):
            break
        sees = False
        if not exact[i]:
            exact[i] = True
            sees = sight(x[i], y[i], gx, gy, sight_edges, smeta, sstart, sids)
            d2[i] = max(d2[i], lower_bound(x[i], y[i], gx, gy, sees, cols, cdist,
                                           sight_edges, smeta, sstart, sids, scratch,
                                           picks, sight_tests))
            f2 = g[i] + weight * max(hd[i], d2[i])
            if f2 > f:
                if size + 1 > hf.shape[0]:
                    hf, hn = heap.grow(hf, size + 1), heap.grow(hn, size + 1)
                fq[i] = f2
                heap.push_plain(hf, hn, size, f2, i)
                size += 1
                continue
        else:
            sees = sight(x[i], y[i], gx, gy, sight_edges, smeta, sstart, sids)
        if interrupt.stop(expanded):  # nothing of the tree kept (see interrupt)
            e, none = np.empty(0), np.empty(0, np.int64)
            return (interrupt.INTERRUPTED, -1, 0.0, -1, False, math.inf, expanded, tries, e,
                    e, e, none, none)
        if expanded >= max_expansions:
            stopped = True
            break
        closed[i] = True
        expanded += 1
        came = 0.0 if prim[i] < 0 else prim_u[prim[i]]  # > 0 forward, < 0 backward
        if (sees or expanded % every == 1 or every == 1) and g[i] + hd[i] < best:
            tries += 1
            extra = switch_cost if came < 0 else 0.0
            c, h, w = _analytic(x[i], y[i], th[i], g[i] + extra, 1.0, best, gx, gy, gth,
                                has_heading, r, ref, dth, H, max_words, ed, st, it, x0, y0,
                                bcell, nx, ny, eps, clear, stamp, tick)
            if c < best:
                best, end, end_head, end_word, end_back = c, i, h, w, False
            if reverse:
                extra = switch_cost if came > 0 else 0.0
                c, h, w = _analytic(x[i], y[i], th[i] + math.pi, g[i] + extra, back_cost,
                                    best, gx, gy, gth + math.pi, has_heading, r,
                                    ref + math.pi, dth, H, max_words, ed, st, it, x0, y0,
                                    bcell, nx, ny, eps, clear, stamp, tick)
                if c < best:
                    best, end, end_head, end_word, end_back = c, i, h, w, True
        for p in range(prim_k.shape[0]):
            k, u = prim_k[p], prim_u[p]
            if not piece_free(x[i], y[i], th[i], k, u, r, ed, st, it, x0, y0, bcell, nx,
                              ny, eps, clear, stamp, tick):
                continue
            qx, qy, qth = advance(x[i], y[i], th[i], k, u, r)
            if not (region[0] <= qx <= region[2] and region[1] <= qy <= region[3]):
                continue
            qth = qth % TWO_PI
            gq = g[i] + prim_c[p]
            if came * u < 0:
                gq += switch_cost
            b = np.int64(round((qth - ref) / dth)) % H
            key = ((np.int64(math.floor((qx - region[0]) / cell)) * ny_cells +
                    np.int64(math.floor((qy - region[1]) / cell))) * H + b)
            j = -1
            if key in seen:
                j = seen[key]
                if closed[j] or g[j] <= gq:
                    continue
            else:
                j = n
                n += 1
                if n > x.shape[0]:
                    x, y = heap.grow(x, n), heap.grow(y, n)
                    th, g = heap.grow(th, n), heap.grow(g, n)
                    hd, d2, fq = heap.grow(hd, n), heap.grow(d2, n), heap.grow(fq, n)
                    parent, prim = heap.grow(parent, n), heap.grow(prim, n)
                    closed = heap.grow_zeroed(closed, x.shape[0])
                    exact = heap.grow_zeroed(exact, x.shape[0])
                seen[key] = j
            x[j], y[j], th[j], g[j] = qx, qy, qth, gq
            parent[j], prim[j] = i, p
            hd[j] = dubins_bound(qx, qy, qth, gx, gy, gth, has_heading, r, reverse)
            d2[j] = max(math.hypot(gx - qx, gy - qy), d2[i] - abs(u))
            exact[j] = False
            fq[j] = gq + weight * max(hd[j], d2[j])
            if fq[j] >= best:
                continue
            if size + 1 > hf.shape[0]:
                hf, hn = heap.grow(hf, size + 1), heap.grow(hn, size + 1)
            heap.push_plain(hf, hn, size, fq[j], j)
            size += 1
    if end >= 0:
        status = FOUND
    elif stopped:
        status = BUDGET_EXHAUSTED
    else:
        status = NO_PATH
    return (status, end, end_head, end_word, end_back, best, expanded, tries, x[:n], y[:n],
            th[:n], parent[:n], prim[:n])
