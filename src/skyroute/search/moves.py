"""Grid moves and the heuristics over them, shared by every compiled grid search.

Moves are 4 orthogonal first, then 4 diagonal, as (dx, dy) cell offsets; on the padded
flat grid of :mod:`skyroute.search.space` they become flat offsets. Heuristic kinds:
0 none (Dijkstra), 1 octile, 2 Euclidean, 3 Manhattan.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

SQRT2 = math.sqrt(2.0)

MOVES = ((1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, 1), (1, -1), (-1, -1))
MDX = np.array([dx for dx, _ in MOVES], dtype=np.int64)
MDY = np.array([dy for _, dy in MOVES], dtype=np.int64)
COSTS = np.array([1.0] * 4 + [SQRT2] * 4)


@njit(cache=True)
def offsets(Wp):
    """Flat offsets of the 8 moves, in MOVES order."""
    return (1, -1, Wp, -Wp, Wp + 1, Wp - 1, 1 - Wp, -1 - Wp)


HEURISTICS = {"zero": 0, "octile": 1, "euclidean": 2, "manhattan": 3}
SQRT2_M1 = math.sqrt(2.0) - 1.0


@njit(cache=True)
def h_of(kind, dx, dy):
    """Heuristic for absolute offsets (dx, dy) to the goal."""
    if kind == 1:
        return max(dx, dy) + SQRT2_M1 * min(dx, dy)
    if kind == 2:
        return math.sqrt(dx * dx + dy * dy)
    if kind == 3:
        return float(dx + dy)
    return 0.0


@njit(cache=True)
def xy(c, Wp, inv):
    """(x, y) of flat index c on rows of ``Wp`` cells, ``inv`` = 1 / Wp: a float multiply
    instead of two 64-bit integer divisions, which cost more than the rest of an A*
    expansion. Exact: (c + 0.5) / Wp is at least 0.5 / Wp away from an integer, far more
    than the float error for any c below 2**40."""
    y = int((c + 0.5) * inv)
    return c - y * Wp, y


@njit(cache=True)
def heuristic(kind, c, goal, Wp):
    """Heuristic between flat cells ``c`` and ``goal``."""
    return h_of(kind, abs(c % Wp - goal % Wp), abs(c // Wp - goal // Wp))


@njit(cache=True)
def move_ok(mask, c, k):
    """True when move k is legal from cell c."""
    return (mask[c] >> k) & 1
