"""The compiled searches' view of a Grid: a padded flat array, move masks, workspace.

The grid is copied once into a flat ``uint8`` array with a one-cell blocked border, so
kernels never test bounds. Cell (x, y) sits at flat index ``(y + 1) * Wp + (x + 1)``
with ``Wp = width + 2``. Built once per grid and cached (plan once, query many):

- a move mask per move rule: bit k of ``mask[c]`` is set when move k is legal from c;
- per-cell search arrays, reused between queries; each search clears only the cells it
  touched.
"""

from __future__ import annotations

import math
import weakref

import numpy as np

from skyroute.caches import register
from skyroute.search import heap
from skyroute.search.jps import jump_tables
from skyroute.search.moves import MDX, MDY
from skyroute.world.grid import Grid, check_cell


class SearchSpace:
    """Padded occupancy, move masks and reusable workspace for one Grid."""

    def __init__(self, grid: Grid) -> None:
        self.width, self.height = grid.width, grid.height
        self.Wp = grid.width + 2
        padded = np.ones((grid.height + 2, grid.width + 2), dtype=np.uint8)
        padded[1:-1, 1:-1] = grid.blocked
        self.blocked = padded.ravel()
        self._blocked_bytes = self.blocked.tobytes()  # flat_pair's test: no numpy scalars
        self.n = self.blocked.size
        self.offsets = MDY * self.Wp + MDX
        self._masks: dict[tuple[int, bool], np.ndarray] = {}
        self._jumps: np.ndarray | None = None
        self._ws: tuple | None = None
        self._free: int | None = None
        self._fs: dict[tuple[float, bool], float] = {}  # f_scale's answers
        # per option set, keyed by id: (the set, kept alive so its id stays its own, and
        # its query call; see grid_plan)
        self.runners: dict[int, tuple] = {}
        self._grid = weakref.ref(grid)

    def index(self, cell: tuple[int, int]) -> int:
        """Flat index of cell (x, y)."""
        return (int(cell[1]) + 1) * self.Wp + int(cell[0]) + 1

    def flat_pair(self, start, goal) -> tuple[int, int]:
        """Flat indices of a query's free cells ``start`` and ``goal``, both (x, y); a
        QueryError naming the bad one otherwise.

        Two pairs of plain ints on free cells, the common case, are checked inline: on a
        small map each microsecond is a tenth of a query. Anything else goes through
        :func:`~skyroute.world.grid.check_cell` for its message. Only sequences match
        the patterns: a mapping or a set, unpacked, gave its keys or members as (x, y) in
        no order. Each coordinate's class must be ``int`` itself, so a bool (an int to
        Python: ``(True, 76)`` planned from (1, 76)) goes to check_cell, which refuses
        it, as every option reader refuses a bool for a number. ``__class__`` is read
        rather than ``type()`` called: the four tests cost at most about 40 ns more than
        the two on the flat indices they replaced, no difference a whole ``plan()`` call
        shows
        (docs/benchmarks.md, section 11)."""
        w, h, Wp, blk = self.width, self.height, self.Wp, self._blocked_bytes
        match start:
            case (x, y):
                match goal:
                    case (u, v):
                        if x.__class__ is int and y.__class__ is int and u.__class__ is int \
                                and v.__class__ is int and 0 <= x < w and 0 <= y < h \
                                and 0 <= u < w and 0 <= v < h:
                            s, t = (y + 1) * Wp + x + 1, (v + 1) * Wp + u + 1
                            if not blk[s] and not blk[t]:
                                return s, t
        grid = self._grid()
        return self.index(check_cell(grid, start, "start")), \
            self.index(check_cell(grid, goal, "goal"))

    def move_mask(self, connectivity: int, corner_cutting: bool) -> np.ndarray:
        """Per-cell legal-move bits for a move rule (built on first use, then cached).

        Corner rule: without corner cutting a diagonal needs both side cells free
        (MovingAI); with it, one free side suffices (never a squeeze between two).
        """
        key = (connectivity, corner_cutting)
        mask = self._masks.get(key)
        if mask is None:
            free = self.blocked == 0
            mask = np.zeros(self.n, np.uint8)
            inner = slice(self.Wp + 1, self.n - self.Wp - 1)  # border cells never move
            for k in range(connectivity):
                ok = free[inner] & np.roll(free, -self.offsets[k])[inner]
                if k >= 4:
                    a = np.roll(free, -MDX[k])[inner]
                    b = np.roll(free, -MDY[k] * self.Wp)[inner]
                    ok &= (a | b) if corner_cutting else (a & b)
                mask[inner] |= ok.astype(np.uint8) << k
            mask.setflags(write=False)
            self._masks[key] = mask
        return mask

    def jump_table(self) -> np.ndarray:
        """JPS's straight-scan table, built on first use (see ``search.jps``); int16
        where every jump fits, since half the bytes keep more of it in cache (about 7%
        faster on random 512x512 maps)."""
        if self._jumps is None:
            table = jump_tables(self.blocked, self.Wp)
            if max(self.width, self.height) < 32000:
                table = table.astype(np.int16)
            self._jumps = table
        return self._jumps

    def f_bound(self, weight: float = 1.0, *, pivots: bool = False) -> float:
        """An upper bound on every f = g + weight * h a grid search on this grid meets.

        g: an expanded cell's g is the cost of a path of distinct free cells (steps of
        at most sqrt 2; Theta*'s shortcuts are no longer), a generated cell's one step
        more, and for JPS one jump (at most width + height cells) more. h: the octile,
        Euclidean or Manhattan distance is at most width + height; a pivot's bound
        (``pivots``) at most the true distance, so at most g's bound.
        """
        if self._free is None:
            self._free = int(np.count_nonzero(self.blocked == 0))
        g = (self._free + self.width + self.height) * math.sqrt(2.0)
        return g + weight * (g if pivots else float(self.width + self.height))

    def f_scale(self, weight: float = 1.0, *, pivots: bool = False) -> float:
        """The heap keys' unit of f for a search here (:func:`heap.f_scale` of
        :meth:`f_bound`): 2**20 unless the grid is huge or ``weight`` large; 0.0 when its
        keys cannot hold every f. Kept per (weight, pivots): a query on a small map takes a
        few microseconds, and working the unit out again took 0.3 of them."""
        key = (weight, pivots)
        fs = self._fs.get(key)
        if fs is None:
            fs = self._fs[key] = heap.f_scale(self.f_bound(weight, pivots=pivots))
        return fs

    def workspace(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(floats, ints, keys), allocated once: F rows g, h (float64); I rows parent, state,
        touched, heap cell, entering move, equal-f stack (int32); K heap keys (int64). Few
        arrays, because numba's dispatch costs about a microsecond per array argument.

        ``state`` (``ints[1]``) is all zeros between queries: every kernel clears the cells
        it touched (listed in ``ints[2]``) before it returns, so no query pays for the grid.
        """
        if self._ws is None:
            self._ws = workspace(self.n)
        return self._ws


def workspace(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A fresh (floats, ints, keys) search workspace for n padded cells (see
    :meth:`SearchSpace.workspace`), its ``state`` row zero."""
    ints = np.empty((6, n), np.int32)
    ints[1] = 0
    return np.empty((2, n)), ints, np.empty(n, np.int64)


# by id(grid), each entry dropped by a finalizer when its grid goes (so an id is never
# reused while its entry stands): a plain dict lookup, where a WeakKeyDictionary's cost
# 0.2-0.8 us of a 9 us query on a 32x32 map
_SPACES: dict[int, SearchSpace] = {}
register(_SPACES.clear)
_WATCHED: weakref.WeakSet = weakref.WeakSet()  # grids with their finalizer (one each)


def space_of(grid: Grid) -> SearchSpace:
    """The cached SearchSpace of ``grid`` (built on first use, freed with the grid)."""
    space = _SPACES.get(id(grid))
    if space is None:
        space = _SPACES[id(grid)] = SearchSpace(grid)
        if grid not in _WATCHED:  # not again after clear_caches()
            weakref.finalize(grid, _SPACES.pop, id(grid), None)
            _WATCHED.add(grid)
    return space
