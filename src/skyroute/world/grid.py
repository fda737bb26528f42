"""The occupancy grid every grid planner searches.

Cells are addressed as (x, y) = (column, row) at every public edge, as MovingAI does;
the array itself is indexed ``blocked[row, column]``. World coordinates are metres:
cell (x, y) covers ``[ox + x*s, ox + (x+1)*s) x [oy + y*s, oy + (y+1)*s)`` for origin
(ox, oy) and cell size s, so world y grows with the row index, as in an image.
"""

from __future__ import annotations

import math
import numbers
import operator
import warnings
from collections.abc import Mapping, Set
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from skyroute.errors import InputFormatError, OptionError, QueryError, real, renamed
from skyroute.world.points import plane_points

NAN_HINT = "use 0 for free and non-zero for blocked"


def occupancy_values(array: object, name: str) -> np.ndarray:
    """``array`` as a numpy array of numbers or booleans (non-zero / True = blocked), else
    an :class:`OptionError` naming ``name``: the readers of arrays (:class:`Grid`,
    ``from_array``) take what a ``.npy`` file may hold. Text was read by its truth value,
    so ``[["0", "1"]]`` or a map's ``"."`` and ``"@"`` characters were all blocked, and
    ``None`` in a list was free; rows of unequal length were numpy's own ValueError.
    NaN is refused by :func:`nan_cell`, its caller's next test."""
    try:
        values = np.asarray(array)
    except (TypeError, ValueError):  # ragged rows ("an inhomogeneous shape")
        raise OptionError(f"{name} must be a 2-D array of numbers or booleans, its rows "
                          f"of equal length", param=name) from None
    if values.dtype.kind == "O":  # a list mixing numbers and other objects
        if values.ndim == 0:  # no array at all (a scipy sparse matrix: use .toarray())
            got = "None" if array is None else type(array).__name__
            raise OptionError(f"{name} must be a 2-D array of numbers or booleans, got "
                              f"{got}", param=name)
        for v in values.flat:
            if not isinstance(v, numbers.Real | np.bool_):
                shown = " ".join(repr(v).split())  # one line: an array's repr has several
                raise OptionError(f"{name} must hold numbers or booleans (non-zero "
                                  f"blocked), got {shown}", param=name)
        return values.astype(np.float64)
    if values.dtype.kind not in "biuf":
        text = ": convert text first, e.g. (array == '@')" if values.dtype.kind in "US" \
            else ""
        raise OptionError(f"{name} must hold numbers or booleans (non-zero blocked), got "
                          f"dtype {values.dtype}{text}", param=name)
    return values


def nan_cell(values: np.ndarray) -> tuple[int, int] | None:
    """The (x, y) cell of the first NaN (row by row) in a 2-D array of numbers, else
    None. NaN says neither free nor blocked, and ``bool(nan)`` would read it as blocked,
    so the array readers refuse it: :class:`Grid`, ``from_array`` and ``.npy`` files."""
    if values.dtype.kind in "fc" and values.ndim == 2:
        bad = np.isnan(values)
        if bad.any():
            row, col = np.argwhere(bad)[0]
            return int(col), int(row)
    return None


@dataclass(frozen=True, eq=False, init=False)
class Grid:
    """Boolean occupancy (True = blocked) with a resolution (cell size) and origin in
    metres.

    ``blocked`` is a 2-D array (or nested lists) of booleans or numbers indexed
    ``[row, column]``, non-zero blocked, any memory layout; NaN, text and other objects
    are an OptionError naming ``blocked``. It is copied into memory that cannot be made
    writeable again (``blocked.setflags(write=True)`` is a ValueError), so a Grid never
    changes after creation: searches cache per Grid. To change cells, make a new Grid
    from a copy (``b = grid.blocked.copy(); b[y, x] = True; Grid(b, ...)``).
    ``cell_size`` is the old name of ``resolution`` (deprecated).

    Examples
    --------
    >>> g = Grid(np.array([[0, 1], [0, 0]], dtype=bool), resolution=0.5)
    >>> g.width, g.height, g.is_free((0, 1)), g.is_free((1, 0))
    (2, 2, True, False)
    >>> g.to_world([(1, 1)]).tolist()
    [[0.75, 0.75]]
    """

    blocked: np.ndarray
    resolution: float = 1.0
    origin: tuple[float, float] = (0.0, 0.0)
    name: str = field(default="grid", compare=False)

    def __init__(self, blocked, resolution: float | None = None,
                 origin: tuple[float, float] = (0.0, 0.0), name: str = "grid", *,
                 cell_size: float | None = None) -> None:
        resolution = renamed("resolution", resolution, "cell_size", cell_size)
        resolution = 1.0 if resolution is None else resolution
        if isinstance(blocked, Grid):  # np.asarray of one is a 0-d object array
            raise OptionError("blocked must be an array, got a Grid: use it as it is, or "
                              "its .blocked", param="blocked")
        values = occupancy_values(blocked, "blocked")
        if (cell := nan_cell(values)) is not None:
            raise OptionError(f"blocked has NaN at cell {cell} (x, y); {NAN_HINT}",
                              param="blocked")
        arr = np.asarray(values, dtype=bool)  # copied by _frozen
        if arr.ndim != 2 or arr.shape[0] < 1 or arr.shape[1] < 1:
            raise OptionError(f"blocked must be a non-empty 2-D array, got shape {arr.shape}",
                              param="blocked")
        if real("resolution", resolution) <= 0:
            raise OptionError(f"resolution={resolution!r} must be a positive number",
                              param="resolution")
        try:
            ox, oy = origin
        except (TypeError, ValueError):
            raise OptionError(f"origin={origin!r} must be two numbers (x, y)",
                              param="origin") from None
        object.__setattr__(self, "blocked", _frozen(arr))
        object.__setattr__(self, "resolution", float(resolution))
        object.__setattr__(self, "origin", (real("origin", ox), real("origin", oy)))
        object.__setattr__(self, "name", name)

    def __reduce__(self) -> tuple:
        """Copied and pickled through the constructor, so the copy's array is read-only
        too (a writable copy could change under the search caches keyed by the grid)."""
        return Grid, (self.blocked, self.resolution, self.origin, self.name)

    def __repr__(self) -> str:
        """A summary, not the array (a 512x512 map printed in a notebook is noise)."""
        return (f"<Grid {self.name!r}: {self.width}x{self.height} cells, "
                f"{int(np.count_nonzero(self.blocked))} blocked, "
                f"resolution {self.resolution:g}, origin {self.origin}>")

    @property
    def cell_size(self) -> float:
        """Deprecated name of :attr:`resolution`."""
        warnings.warn("Grid.cell_size is deprecated; use Grid.resolution",
                      DeprecationWarning, stacklevel=2)
        return self.resolution

    @property
    def width(self) -> int:
        """Number of columns (the x extent in cells)."""
        return int(self.blocked.shape[1])

    @property
    def height(self) -> int:
        """Number of rows (the y extent in cells)."""
        return int(self.blocked.shape[0])

    def in_bounds(self, cell: tuple[int, int]) -> bool:
        """True when cell (x, y) lies on the grid; QueryError unless two integers."""
        x, y = cell_xy(cell, "cell")
        return 0 <= x < self.width and 0 <= y < self.height

    def is_free(self, cell: tuple[int, int]) -> bool:
        """True when cell (x, y) is on the grid and not blocked; QueryError unless two
        integers."""
        x, y = cell_xy(cell, "cell")
        return 0 <= x < self.width and 0 <= y < self.height and not self.blocked[y, x]

    def to_world(self, cells: np.ndarray) -> np.ndarray:
        """Centres in metres of an (N, 2) array of (x, y) cells (float cells allowed)."""
        c = plane_points(cells, "cells")
        return (c + 0.5) * self.resolution + np.asarray(self.origin)

    def to_cell(self, points: np.ndarray) -> np.ndarray:
        """The (x, y) cells containing an (N, 2) array of world points (may be off-grid)."""
        p = plane_points(points)
        return np.floor((p - np.asarray(self.origin)) / self.resolution).astype(np.int64)

    def inflate(self, safety: float | None = None, *, clearance: float | None = None) -> Grid:
        """Block every cell whose centre lies within ``safety`` metres of a blocked cell.

        Distances are Euclidean between cell centres (scipy's exact distance transform),
        so a point robot that keeps to free cell centres keeps that distance from the
        centres of blocked cells. ``safety=0`` returns an equal grid. (``clearance`` is
        the old name, deprecated.)
        """
        safety = renamed("safety", safety, "clearance", clearance)
        safety = 0.0 if safety is None else safety
        if real("safety", safety) < 0:
            raise OptionError(f"safety={safety!r} must be a number >= 0", param="safety")
        if safety == 0 or not self.blocked.any():
            return self
        from scipy import ndimage  # imported here: it costs 0.25 s at start-up

        free = ~self.blocked
        dist = ndimage.distance_transform_edt(free, sampling=self.resolution)
        inflated = dist <= safety + 1e-9 * self.resolution
        return Grid(inflated, self.resolution, self.origin, name=self.name)

    @cached_property
    def free_fraction(self) -> float:
        """Share of free cells, for reports."""
        return float(1.0 - self.blocked.mean())


def _frozen(arr: np.ndarray) -> np.ndarray:
    """``arr`` copied (C order) into an immutable bytes object and viewed as an array.
    ``setflags(write=False)`` alone could be undone: an array that owns its memory may be
    made writeable again (``grid.blocked.flags.writeable = True``, the usual answer to
    numpy's "assignment destination is read-only"), and a search then reused the
    workspace cached for the grid's old cells: a path through the new walls."""
    return np.frombuffer(arr.tobytes(), dtype=bool).reshape(arr.shape)


def cell_xy(cell: object, what: str) -> tuple[int, int]:
    """(x, y) as ints, else QueryError naming ``what``. A mapping or a set is refused
    (unpacking it gives its keys or members, in no (x, y) order), and bytes
    (b"\\x01\\x02" unpacks to two ints); so is a bool, which Python counts as an int
    (``(True, 76)`` planned from (1, 76)), as numpy's bool is (no ``__index__``) and every
    option reader refuses one for a number."""
    if isinstance(cell, Mapping | Set | bytes | bytearray):
        raise QueryError(f"{what} {cell!r} must be two integers (x, y), not a "
                         f"{type(cell).__name__}", param=what)
    note = ""
    try:
        x, y = cell  # type: ignore[misc]
        if isinstance(x, bool | np.bool_) or isinstance(y, bool | np.bool_):
            note = ", not booleans"
            raise TypeError(note)
        return operator.index(x), operator.index(y)
    except (TypeError, ValueError):
        shown = " ".join(repr(cell).split())  # one line: a 2-D array's repr has several
        raise QueryError(f"{what} {shown} must be two integers (x, y){note}",
                         param=what) from None


def check_cell(grid: Grid, cell: object, what: str) -> tuple[int, int]:
    """(x, y) as ints (:func:`cell_xy`), on the grid and free; else QueryError naming
    ``what``, with :func:`swap_hint`."""
    x, y = cell_xy(cell, what)
    if not (0 <= x < grid.width and 0 <= y < grid.height):
        raise QueryError(f"{what} ({x}, {y}) lies outside the {grid.width}x{grid.height} grid "
                         f"(x in 0..{grid.width - 1}, y in 0..{grid.height - 1})"
                         f"{swap_hint(grid, x, y)}", param=what)
    if grid.blocked[y, x]:
        raise QueryError(f"{what} ({x}, {y}) is on a blocked cell{swap_hint(grid, x, y)}",
                         param=what)
    return x, y


def swap_hint(grid: Grid, x: int, y: int) -> str:
    """'; (y, x) is free: cells are (x, y) = (column, row)' when cell (x, y), refused as
    off the grid or blocked, is a free cell of the grid with its numbers swapped, else ''.
    (row, column), numpy's order, is the likely slip, as (lat, lon) is in a World; on a
    square map it never falls off the grid, so a blocked cell is where it shows. A swapped
    cell that is blocked too gets no hint: it would point to a cell as bad as the first
    (it did, for a cell off the grid)."""
    if x == y or not (0 <= y < grid.width and 0 <= x < grid.height) or grid.blocked[x, y]:
        return ""
    return f"; ({y}, {x}) is free: cells are (x, y) = (column, row)"


MAX_CELLS = 1 << 26  # 8192 x 8192: a search keeps about 50 bytes a cell (3.4 GB here)


def raster_shape(xspan: float, yspan: float, resolution: float) -> tuple[int, int]:
    """(width, height) in cells of an xspan x yspan extent at ``resolution`` metres a
    cell; an OptionError naming the size before anything is allocated when it is above
    :data:`MAX_CELLS` (a small resolution or one far-off coordinate)."""
    w, h = xspan / resolution, yspan / resolution
    if not (math.isfinite(w) and math.isfinite(h) and max(1.0, w) * max(1.0, h) <= MAX_CELLS):
        size = f"{w:.3g} x {h:.3g} cells" if math.isfinite(w * h) else "unbounded"
        raise OptionError(f"resolution={resolution:g} over a {xspan:.6g} x {yspan:.6g} extent "
                          f"makes {size}, above {MAX_CELLS:,}; use a coarser resolution",
                          param="resolution")
    return max(1, math.ceil(w)), max(1, math.ceil(h))


def check_file_cells(path: object, width: int, height: int, *, line: int | None = None,
                     what: str = "the map") -> None:
    """An InputFormatError naming ``path`` (and ``line``) when a ``width`` x ``height``
    grid read from it would have more than :data:`MAX_CELLS` cells: the readers of map
    files (.map headers, .npy headers, image sizes) call it before they allocate the grid,
    so a header that claims 3 x 10**12 cells is one line, not numpy's MemoryError."""
    if width * height > MAX_CELLS:
        raise InputFormatError(path, f"{what} is {width:,} x {height:,} cells "
                               f"({width * height:,}), over the limit of {MAX_CELLS:,} "
                               "(8192 x 8192) a grid may have", line=line)
