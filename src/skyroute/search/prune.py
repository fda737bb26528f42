"""Waypoint pruning that never makes a path illegal or longer.

``collinear`` drops points where the path goes straight on (a zero determinant); the
merged segment covers exactly the cells of the steps it replaces. ``los`` shortcuts
greedily: from each kept point it goes on while it sees the next point, and keeps the
last one it saw (not the farthest visible point beyond a hidden one); by the triangle
inequality the result is never longer.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from skyroute.search.los import line_of_sight

PRUNE_MODES = ("none", "collinear", "los")


@njit(cache=True)
def prune_collinear(points, Wp):
    """Keep the first, last and every turning point of a chain of flat cells."""
    n = len(points)
    if n < 3:
        return points.copy()
    keep = np.zeros(n, np.bool_)
    keep[0] = True
    keep[n - 1] = True
    last = 0
    for i in range(1, n - 1):
        a, b, c = points[last], points[i], points[i + 1]
        ux, uy = b % Wp - a % Wp, b // Wp - a // Wp
        vx, vy = c % Wp - b % Wp, c // Wp - b // Wp
        if ux * vy - uy * vx != 0 or ux * vx + uy * vy <= 0:
            keep[i] = True
            last = i
    return points[keep]


@njit(cache=True)
def prune_los(blk, Wp, points):
    """Greedy line-of-sight shortcutting; return (points, los_checks)."""
    n = len(points)
    if n < 3:
        return points.copy(), 0
    out = np.empty(n, np.int64)
    out[0] = points[0]
    k = 1
    checks = 0
    anchor = 0
    j = 1
    while j < n - 1:
        checks += 1
        if line_of_sight(blk, Wp, points[anchor], points[j + 1]):
            j += 1
        else:
            out[k] = points[j]
            k += 1
            anchor = j
            j = anchor + 1
    out[k] = points[n - 1]
    return out[: k + 1], checks
