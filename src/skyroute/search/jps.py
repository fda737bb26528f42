"""Jump Point Search, 8-connected, without corner cutting (MovingAI's move rule).

Harabor & Grastien's pruning for the no-corner-cutting model ("Improving Jump Point
Search", ICAPS 2014): a diagonal move has no forced neighbours and stops where one of
its two straight scans finds a jump point; a straight move stops at the goal or where
a side cell is free while the cell behind it is blocked, which forces the perpendicular
step and the diagonal beside it. Costs are octile, equal to A*'s; the path returned is
every cell, as for A*.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from skyroute.search import heap
from skyroute.search.astar import heuristic
from skyroute.search.result import BUDGET_EXHAUSTED, FOUND, NO_PATH


@njit(cache=True)
def _jump_straight(blk, c, d, side, goal):
    """Scan from c in step d; return the first jump point or -1."""
    while True:
        n = c + d
        if blk[n]:
            return -1
        c = n
        if c == goal:
            return c
        if (blk[c + side] == 0 and blk[c - d + side] != 0) or \
                (blk[c - side] == 0 and blk[c - d - side] != 0):
            return c


@njit(cache=True)
def _jump_diagonal(blk, c, dx, dy, Wp, goal):
    """Scan from c diagonally by (dx, dy) = (+-1, +-Wp); return a jump point or -1."""
    while True:
        if blk[c + dx] or blk[c + dy] or blk[c + dx + dy]:
            return -1
        c = c + dx + dy
        if c == goal:
            return c
        if _jump_straight(blk, c, dx, Wp, goal) >= 0 or \
                _jump_straight(blk, c, dy, 1, goal) >= 0:
            return c


@njit(cache=True)
def _relax(n, c, Wp, goal, stamp, g, h, parent, mark, pos, hc, hk, size):
    closed = stamp + 1
    m = mark[n]
    if m == closed:
        return size
    dx = abs(n % Wp - c % Wp)
    dy = abs(n // Wp - c // Wp)
    gn = g[c] + max(dx, dy) + 0.41421356237309515 * min(dx, dy)
    if m != stamp:
        mark[n] = stamp
        pos[n] = -1
        h[n] = heuristic(1, n, goal, Wp)
    elif gn >= g[n]:
        return size
    g[n] = gn
    parent[n] = c
    return heap.push(hc, hk, pos, size, n, heap.key(gn + h[n], gn))


@njit(cache=True)
def _sign(v):
    return (v > 0) - (v < 0)


@njit(cache=True)
def jps_kernel(blk, Wp, start, goal, max_expansions,
               stamp, g, h, parent, mark, pos, hc, hk):
    """Search from flat ``start`` to ``goal``; return (status, expanded, max_frontier).

    ``parent`` links jump points; :func:`fill` expands them to every cell.
    """
    mark[start] = stamp
    g[start] = 0.0
    h[start] = heuristic(1, start, goal, Wp)
    parent[start] = start
    pos[start] = -1
    size = heap.push(hc, hk, pos, 0, start, heap.key(h[start], 0.0))
    expanded = 0
    max_frontier = 1
    while size > 0:
        c, size = heap.pop(hc, hk, pos, size)
        if c == goal:
            return FOUND, expanded, max_frontier
        if expanded >= max_expansions:
            return BUDGET_EXHAUSTED, expanded, max_frontier
        mark[c] = stamp + 1
        expanded += 1
        p = parent[c]
        sx = _sign(c % Wp - p % Wp)
        sy = _sign(c // Wp - p // Wp) * Wp
        if p == c:  # the start: every direction
            for d, side in ((1, Wp), (-1, Wp), (Wp, 1), (-Wp, 1)):
                j = _jump_straight(blk, c, d, side, goal)
                if j >= 0:
                    size = _relax(j, c, Wp, goal, stamp, g, h, parent, mark, pos, hc, hk, size)
            for dx in (1, -1):
                for dy in (Wp, -Wp):
                    j = _jump_diagonal(blk, c, dx, dy, Wp, goal)
                    if j >= 0:
                        size = _relax(j, c, Wp, goal, stamp, g, h, parent, mark, pos, hc, hk,
                                      size)
        elif sx != 0 and sy != 0:
            j = _jump_straight(blk, c, sx, Wp, goal)
            if j >= 0:
                size = _relax(j, c, Wp, goal, stamp, g, h, parent, mark, pos, hc, hk, size)
            j = _jump_straight(blk, c, sy, 1, goal)
            if j >= 0:
                size = _relax(j, c, Wp, goal, stamp, g, h, parent, mark, pos, hc, hk, size)
            j = _jump_diagonal(blk, c, sx, sy, Wp, goal)
            if j >= 0:
                size = _relax(j, c, Wp, goal, stamp, g, h, parent, mark, pos, hc, hk, size)
        else:
            d = sx + sy
            side = 1 if sx == 0 else Wp
            j = _jump_straight(blk, c, d, side, goal)
            if j >= 0:
                size = _relax(j, c, Wp, goal, stamp, g, h, parent, mark, pos, hc, hk, size)
            for s in (side, -side):
                if blk[c + s] == 0 and blk[c - d + s] != 0:  # forced
                    j = _jump_straight(blk, c, s, abs(d), goal)
                    if j >= 0:
                        size = _relax(j, c, Wp, goal, stamp, g, h, parent, mark, pos, hc, hk,
                                      size)
                    if d == 1 or d == -1:
                        j = _jump_diagonal(blk, c, d, s, Wp, goal)
                    else:
                        j = _jump_diagonal(blk, c, s, d, Wp, goal)
                    if j >= 0:
                        size = _relax(j, c, Wp, goal, stamp, g, h, parent, mark, pos, hc, hk,
                                      size)
        if size > max_frontier:
            max_frontier = size
    return NO_PATH, expanded, max_frontier


@njit(cache=True)
def fill(points, Wp):
    """Expand a chain of jump points (straight or diagonal runs) into every cell."""
    total = 1
    for i in range(1, len(points)):
        a, b = points[i - 1], points[i]
        total += max(abs(b % Wp - a % Wp), abs(b // Wp - a // Wp))
    out = np.empty(total, np.int64)
    out[0] = points[0]
    k = 1
    for i in range(1, len(points)):
        a, b = points[i - 1], points[i]
        step = _sign(b % Wp - a % Wp) + _sign(b // Wp - a // Wp) * Wp
        c = a
        while c != b:
            c += step
            out[k] = c
            k += 1
    return out
