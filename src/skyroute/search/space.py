"""The compiled searches' view of a Grid: a padded flat array, move tables, workspace.

The grid is copied once into a flat ``uint8`` array with a one-cell blocked border, so
kernels never test bounds. Cell (x, y) sits at flat index ``(y + 1) * Wp + (x + 1)``
with ``Wp = width + 2``. Per-cell search arrays are allocated once per grid and reused:
a query stamp marks which entries belong to the current query, so nothing is reset
between queries (plan once, query many).
"""

from __future__ import annotations

import math
import weakref

import numpy as np

from skyroute.world.grid import Grid

SQRT2 = math.sqrt(2.0)

# Moves: 4 orthogonal first, then 4 diagonal. (dx, dy) in cells.
MOVES = ((1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, 1), (1, -1), (-1, -1))


class SearchSpace:
    """Padded occupancy and reusable workspace for one Grid (see module docstring)."""

    def __init__(self, grid: Grid) -> None:
        self.width, self.height = grid.width, grid.height
        self.Wp = grid.width + 2
        padded = np.ones((grid.height + 2, grid.width + 2), dtype=np.uint8)
        padded[1:-1, 1:-1] = grid.blocked
        self.blocked = padded.ravel()
        self.n = self.blocked.size
        self._ws: tuple | None = None
        self._stamp = 0

    def index(self, cell: tuple[int, int]) -> int:
        """Flat index of cell (x, y)."""
        return (int(cell[1]) + 1) * self.Wp + int(cell[0]) + 1

    def cells(self, flat: np.ndarray) -> np.ndarray:
        """(K, 2) float (x, y) cells of flat indices."""
        flat = np.asarray(flat, dtype=np.int64)
        out = np.empty((len(flat), 2))
        out[:, 0] = flat % self.Wp - 1
        out[:, 1] = flat // self.Wp - 1
        return out

    def moves(self, connectivity: int, corner_cutting: bool) -> tuple:
        """Move tables for the kernels: (count, offsets, costs, side_a, side_b, rule).

        A diagonal move's two orthogonal side cells are at ``here + side_a`` and
        ``here + side_b``. ``rule`` 0: both sides must be free (MovingAI, no corner
        cutting); 1: at least one side free (corners may be cut, but never a squeeze
        between two blocked cells that touch only at a corner).
        """
        count = 4 if connectivity == 4 else 8
        offs = np.array([dy * self.Wp + dx for dx, dy in MOVES], dtype=np.int64)
        costs = np.array([1.0] * 4 + [SQRT2] * 4)
        side_a = np.array([0] * 4 + [dx for dx, _ in MOVES[4:]], dtype=np.int64)
        side_b = np.array([0] * 4 + [dy * self.Wp for _, dy in MOVES[4:]], dtype=np.int64)
        return count, offs, costs, side_a, side_b, 1 if corner_cutting else 0

    def workspace(self) -> tuple:
        """(stamp, g, h, parent, mark, pos, heap_cell, heap_key, heap_g) for one query.

        ``mark[c] == stamp`` means c was seen this query, ``stamp + 1`` that it is closed.
        """
        if self._ws is None:
            n = self.n
            self._ws = (np.empty(n), np.empty(n), np.empty(n, np.int32),
                        np.zeros(n, np.int32), np.full(n, -1, np.int32),
                        np.empty(n, np.int32), np.empty(n, np.int64), np.empty(n))
        self._stamp += 2
        return (self._stamp, *self._ws)


_SPACES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def space_of(grid: Grid) -> SearchSpace:
    """The cached SearchSpace of ``grid`` (built on first use, freed with the grid)."""
    space = _SPACES.get(grid)
    if space is None:
        space = _SPACES[grid] = SearchSpace(grid)
    return space
