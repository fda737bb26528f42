"""Wall maps given as line segments in metres (CSV ``x1,y1,x2,y2``), rasterised to a Grid.

A cell is blocked when a wall passes through it (touching its closed square) or when its
centre lies within ``safety`` of a wall, measured exactly to the segment.

The raster's cells lie on the lattice of multiples of the resolution, and it covers the
walls' bounding box and one cell more on every side, whatever the safety: a cell (x, y)
names the same place with any margin. The margin blocks cells inside the raster and
never grows it (outside the raster there is nowhere to plan anyway).
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
from numba import njit

from skyroute.errors import CITY, CityNotWallsError, InputFormatError, OptionError
from skyroute.files import read_text
from skyroute.world.geometry import point_segment_dist2
from skyroute.world.grid import MAX_CELLS, Grid, raster_shape

OUTLIER = 10  # a wall that makes the map this many times as long is named as the cause


def read_segments(path: str | Path) -> np.ndarray:
    """Read ``x1,y1,x2,y2`` rows (an optional header row of names is skipped) as (N, 4)."""
    return _read(Path(path))[0]


def load_segments(path: str | Path, *, resolution: float, safety: float = 0.0) -> Grid:
    """Read a walls file and rasterise it (:func:`rasterize_segments`). A raster above
    :data:`~skyroute.world.grid.MAX_CELLS` names what made it so: the line of the one
    wall far from the others (a mistyped coordinate), else ``resolution``; always with
    the file (``safety`` never grows the raster)."""
    path = Path(path)
    seg, lines = _read(path)
    if not (math.isfinite(resolution) and resolution > 0 and math.isfinite(safety)
            and safety >= 0):  # rasterize_segments names the option
        return rasterize_segments(seg, resolution=resolution, safety=safety, name=path.name)
    try:
        raster_shape(*_span(seg, resolution), resolution)
    except OptionError as exc:
        raise _too_large(path, seg, lines, resolution, exc) from None
    return rasterize_segments(seg, resolution=resolution, safety=safety, name=path.name)


def _span(seg: np.ndarray, resolution: float) -> tuple[float, float]:
    """Width and height (metres) of the default raster: the walls' extent and one cell
    on every side (as :func:`rasterize_segments` pads it; the safety margin adds none)."""
    pad = 2 * resolution
    xs, ys = seg[:, [0, 2]], seg[:, [1, 3]]
    return float(xs.max() - xs.min() + pad), float(ys.max() - ys.min() + pad)


def wall_lattice(segments: np.ndarray, resolution: float) -> tuple[int, int, int, int]:
    """The default raster's cells on the lattice of multiples of ``resolution``: (i0, j0,
    i1, j1) with origin (i0, j0) * resolution and (i1 - i0) x (j1 - j0) cells, the
    walls' bounding box floored and ceiled to the lattice and one cell more on every
    side. It depends on the walls and the resolution only, never on the safety margin,
    so a cell names the same place with any margin."""
    xs, ys = segments[:, [0, 2]], segments[:, [1, 3]]
    i0, j0 = math.floor(xs.min() / resolution) - 1, math.floor(ys.min() / resolution) - 1
    i1, j1 = math.ceil(xs.max() / resolution) + 1, math.ceil(ys.max() / resolution) + 1
    return i0, j0, i1, j1


def _fits(span: tuple[float, float], resolution: float) -> bool:
    try:
        raster_shape(*span, resolution)
    except OptionError:
        return False
    return True


def _too_large(path: Path, seg: np.ndarray, lines: list[int], resolution: float,
               exc: OptionError) -> InputFormatError | OptionError:
    """The error for a walls raster above MAX_CELLS (``exc``: raster_shape's)."""
    w, h = _span(seg, resolution)
    size = f"{w:.6g} x {h:.6g} m, {w / resolution:.3g} x {h / resolution:.3g} cells at " \
        f"{resolution:g} m a cell, above {MAX_CELLS:,}"
    # the wall reaching farthest from the median of all the ends, in either axis; it is
    # the one to blame when the others fit and it makes the map 10 times as long
    ends = seg.reshape(-1, 2)
    reach = np.abs(ends - np.median(ends, axis=0)).max(axis=1).reshape(-1, 2).max(axis=1)
    k = int(np.argmax(reach))
    rest = np.delete(seg, k, axis=0)
    if not len(rest) or (_fits(_span(rest, resolution), resolution)
                         and max(w, h) >= OUTLIER * max(_span(rest, resolution))):
        x1, y1, x2, y2 = seg[k]
        return InputFormatError(path, f"the wall ({x1:g}, {y1:g}) - ({x2:g}, {y2:g}) "
                                f"stretches the map to {size}; is a coordinate wrong? "
                                "(else use a coarser resolution)", line=lines[k])
    return OptionError(f"{path}: {exc}", param="resolution")


def _read(path: Path) -> tuple[np.ndarray, list[int]]:
    """(N, 4) segments and the line each came from."""
    text = read_text(path)
    rows, lines, first = [], [], True
    for n, row in enumerate(csv.reader(text.splitlines()), start=1):
        if not row or all(not c.strip() for c in row) or row[0].lstrip().startswith("#"):
            continue
        # the header is the first row that is neither blank nor a comment (under a
        # '# walls' line it was refused as a wall of words)
        header, first = first, False
        if header and row[0].strip().lower() in ("x1", "x0", "x"):
            continue
        if n == 1 and row[0].strip().lower().startswith(("lat0", "lon0")):
            raise CityNotWallsError(path, f"{CITY}: load it with skyroute.load_world", line=1)
        if len(row) != 4:
            raise InputFormatError(path, f"expected 4 columns x1,y1,x2,y2, got {len(row)}",
                                   line=n)
        try:
            vals = [float(c) for c in row]
        except ValueError:
            raise InputFormatError(path, f"x1,y1,x2,y2 must be numbers, got {row!r}",
                                   line=n) from None
        if not all(math.isfinite(v) for v in vals):
            raise InputFormatError(path, "coordinates must be finite", line=n)
        rows.append(vals)
        lines.append(n)
    if not rows:
        raise InputFormatError(path, "no segments")
    return np.array(rows, dtype=np.float64), lines


def rasterize_segments(segments: np.ndarray, *, resolution: float, safety: float = 0.0,
                       bounds: tuple[float, float, float, float] | None = None,
                       name: str = "segments") -> Grid:
    """Rasterise (N, 4) segments at ``resolution`` metres per cell.

    ``bounds`` = (xmin, ymin, xmax, ymax) defaults to the segments' extent on the
    lattice of multiples of ``resolution`` and one cell more on every side
    (:func:`wall_lattice`); the safety margin blocks cells in it but does not move or
    grow it, so a cell names the same place with any ``safety``.
    """
    if not (math.isfinite(resolution) and resolution > 0):
        raise OptionError(f"resolution={resolution!r} must be a positive number",
                          param="resolution")
    if not (math.isfinite(safety) and safety >= 0):
        raise OptionError(f"safety={safety!r} must be a number >= 0", param="safety")
    seg = np.ascontiguousarray(segments, dtype=np.float64).reshape(-1, 4)
    if bounds is None:
        raster_shape(*_span(seg, resolution), resolution)  # refused before any allocation
        i0, j0, i1, j1 = wall_lattice(seg, resolution)
        # the shape counted in whole cells: (i1 - i0) * s / s can round up a cell
        xmin, ymin, width, height = i0 * resolution, j0 * resolution, i1 - i0, j1 - j0
    else:
        xmin, ymin, xmax, ymax = (float(b) for b in bounds)
        width, height = raster_shape(xmax - xmin, ymax - ymin, resolution)
    blocked = np.zeros((height, width), dtype=np.bool_)
    _rasterize(seg, xmin, ymin, resolution, safety, blocked)
    return Grid(blocked, resolution, (xmin, ymin), name=name)


@njit(cache=True)
def _segment_hits_box(ax, ay, bx, by, x0, y0, x1, y1):
    # Liang-Barsky clipping of the segment against the closed box.
    t0, t1 = 0.0, 1.0
    dx, dy = bx - ax, by - ay
    for p, q in ((-dx, ax - x0), (dx, x1 - ax), (-dy, ay - y0), (dy, y1 - ay)):
        if p == 0.0:
            if q < 0.0:
                return False
        else:
            r = q / p
            if p < 0.0:
                t0 = max(t0, r)
            else:
                t1 = min(t1, r)
            if t0 > t1:
                return False
    return True


@njit(cache=True)
def _rasterize(seg, xmin, ymin, s, clearance, blocked):
    h, w = blocked.shape
    r2 = clearance * clearance
    for i in range(seg.shape[0]):
        ax, ay, bx, by = seg[i, 0], seg[i, 1], seg[i, 2], seg[i, 3]
        c0 = max(0, math.floor((min(ax, bx) - clearance - xmin) / s) - 1)
        c1 = min(w - 1, math.floor((max(ax, bx) + clearance - xmin) / s) + 1)
        r0 = max(0, math.floor((min(ay, by) - clearance - ymin) / s) - 1)
        r1 = min(h - 1, math.floor((max(ay, by) + clearance - ymin) / s) + 1)
        for r in range(r0, r1 + 1):
            cy0 = ymin + r * s
            for c in range(c0, c1 + 1):
                if blocked[r, c]:
                    continue
                cx0 = xmin + c * s
                near = point_segment_dist2(cx0 + 0.5 * s, cy0 + 0.5 * s, ax, ay, bx, by) <= r2
                if near or _segment_hits_box(ax, ay, bx, by, cx0, cy0, cx0 + s, cy0 + s):
                    blocked[r, c] = True
