"""The order (and arrival headings) of a tour through targets, from a table of leg costs:
exact dynamic programming over subsets (Held-Karp) for a few targets, local search for
more, and the greedy nearest-first baseline. Compiled; plain arrays in and out.

Targets are visited with one of ``H`` arrival headings each, so a "place" is a
(target, heading) pair, index ``k * H + h``. ``c0[p]`` is the cost from the start pose
to place p; ``C[p, q]`` from place p to place q. Exact means exact over that heading
set: the continuous optimum is at most one heading bin's worth of turning away.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def held_karp(c0, C, n, H):
    """Exact shortest tour from the start through all ``n`` targets (no return), over
    H headings per target; O(2^n n^2 H^2). Returns (cost, places in visiting order)."""
    full = (1 << n) - 1
    P = n * H
    dp = np.full((1 << n, P), np.inf)
    back = np.full((1 << n, P), -1, np.int64)
    for p in range(P):
        dp[1 << (p // H), p] = c0[p]
    for S in range(1, full + 1):
        for p in range(P):
            d = dp[S, p]
            if d == np.inf:
                continue
            for k in range(n):
                if S & (1 << k):
                    continue
                T = S | (1 << k)
                for h in range(H):
                    q = k * H + h
                    v = d + C[p, q]
                    if v < dp[T, q]:
                        dp[T, q] = v
                        back[T, q] = p
    best, end = np.inf, -1
    for p in range(P):
        if dp[full, p] < best:
            best, end = dp[full, p], p
    order = np.empty(n, np.int64)
    S, p = full, end
    for i in range(n - 1, -1, -1):
        order[i] = p
        q = back[S, p]
        S ^= 1 << (p // H)
        p = q
    return best, order


@njit(cache=True)
def best_headings(targets, c0, C, H):
    """For a fixed visiting order of targets: the arrival headings that minimise the
    total (a chain DP, O(n H^2)). Returns (cost, places)."""
    n = len(targets)
    cost = np.empty((n, H))
    back = np.zeros((n, H), np.int64)
    for h in range(H):
        cost[0, h] = c0[targets[0] * H + h]
    for i in range(1, n):
        for h in range(H):
            q = targets[i] * H + h
            best, arg = np.inf, 0
            for g in range(H):
                v = cost[i - 1, g] + C[targets[i - 1] * H + g, q]
                if v < best:
                    best, arg = v, g
            cost[i, h] = best
            back[i, h] = arg
    h = int(np.argmin(cost[n - 1]))
    total = cost[n - 1, h]
    places = np.empty(n, np.int64)
    for i in range(n - 1, -1, -1):
        places[i] = targets[i] * H + h
        h = back[i, h]
    return total, places


@njit(cache=True)
def improve(order, c0, C, H, max_rounds):
    """Local search from a visiting order of targets: 2-opt reversals and moving one
    target elsewhere (or-opt), each candidate scored with its best headings; first
    improvement, until none helps or ``max_rounds`` sweeps. Returns (cost, places)."""
    order = order.copy()
    best, places = best_headings(order, c0, C, H)
    n = len(order)
    for _ in range(max_rounds):
        better = False
        for i in range(n - 1):
            for j in range(i + 1, n):
                cand = order.copy()
                cand[i:j + 1] = order[i:j + 1][::-1]
                v, pl = best_headings(cand, c0, C, H)
                if v < best - 1e-9:
                    order, best, places, better = cand, v, pl, True
        for i in range(n):
            for j in range(n):
                if i == j:
                    continue
                rest = np.concatenate((order[:i], order[i + 1:]))
                cand = np.concatenate((rest[:j], order[i:i + 1], rest[j:]))
                v, pl = best_headings(cand, c0, C, H)
                if v < best - 1e-9:
                    order, best, places, better = cand, v, pl, True
        if not better:
            break
    return best, places


@njit(cache=True)
def nearest_first(c0, C, dist0, D, n, H):
    """The greedy baseline: go to the nearest unvisited target by straight-line distance
    (``dist0`` from the start, ``D`` between targets), arriving with the heading that
    makes that leg shortest from the pose the drone is in. Returns (cost, places)."""
    seen = np.zeros(n, np.bool_)
    places = np.empty(n, np.int64)
    total = 0.0
    p = -1
    for i in range(n):
        k, best = -1, np.inf
        for j in range(n):
            d = dist0[j] if p < 0 else D[p // H, j]
            if not seen[j] and d < best:
                k, best = j, d
        seen[k] = True
        leg, arg = np.inf, 0
        for h in range(H):
            v = c0[k * H + h] if p < 0 else C[p, k * H + h]
            if v < leg:
                leg, arg = v, h
        p = k * H + arg
        places[i] = p
        total += leg
    return total, places
