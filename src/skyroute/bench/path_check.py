"""The bench's own reading of an answer: is it a legal path for the query, and how long.

``bench grid`` counts a line as matched only when the answer is a legal path in
MovingAI's problem (8-connected moves between free cells, no corner cutting; an
any-angle runner's straight segments need line of sight) from the query's start to
its goal, and the length of that path, re-measured here, equals the optimum. A
runner's own ``cost`` is not trusted: a kernel whose path and cost disagree, or a peer
that cuts corners, is not counted as optimal.
"""

from __future__ import annotations

from collections.abc import Callable
from itertools import pairwise

import numpy as np

from skyroute.search.los import line_of_sight
from skyroute.search.space import space_of
from skyroute.world.grid import Grid

# (path, start, goal, any_angle) -> its length when legal, else None
Checker = Callable[[np.ndarray, tuple, tuple, bool], float | None]


def path_length(path) -> float:
    """Euclidean length of a chain of points: the octile cost for single moves."""
    d = np.diff(np.asarray(path, dtype=float), axis=0)
    return float(np.hypot(d[:, 0], d[:, 1]).sum())


def legal_length(grid: Grid) -> Checker:
    """A checker for ``grid``: the length of a path that answers (start, goal) legally,
    None otherwise. The line-of-sight test reads the grid's cached search space (the
    padded flat array the planners use)."""
    h, w = grid.blocked.shape
    space = space_of(grid)
    flat, wp = space.blocked, space.Wp

    def check(path, start, goal, any_angle: bool = False) -> float | None:
        p = np.asarray(path, dtype=float)
        if p.ndim != 2 or p.shape[1:] != (2,) or len(p) == 0 or \
                not np.array_equal(p, np.round(p)):
            return None
        c = p.astype(np.int64)
        x, y = c[:, 0], c[:, 1]
        if tuple(c[0].tolist()) != tuple(start) or tuple(c[-1].tolist()) != tuple(goal):
            return None
        if ((x < 0) | (x >= w) | (y < 0) | (y >= h)).any() or grid.blocked[y, x].any():
            return None
        d = np.diff(c, axis=0)
        if any_angle:
            cells = (y + 1) * wp + x + 1
            if not all(line_of_sight(flat, wp, a, b)
                       for a, b in pairwise(cells.tolist())):
                return None
        else:
            if (np.abs(d).max(axis=1) != 1).any():
                return None  # a jump, or a step that stays put: not one move
            diag = (d[:, 0] != 0) & (d[:, 1] != 0)
            (x0, y0), (x1, y1) = c[:-1][diag].T, c[1:][diag].T
            if (grid.blocked[y0, x1] | grid.blocked[y1, x0]).any():
                return None  # a diagonal past a blocked cell cuts its corner
        return path_length(c)

    return check
