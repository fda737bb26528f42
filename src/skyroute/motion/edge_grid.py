"""A uniform bucket grid over the zone edges, so a compiled test of a move, a sight line
or a point meets only the edges near it, not every edge of the world.

Built once per world (:func:`build`) as three arrays, CSR style: ``meta`` (x0, y0, cell,
nx, ny), ``start`` (nx * ny + 1,) and ``ids``, the edges of bucket b being
``ids[start[b]:start[b + 1]]``. An edge is listed in every bucket its segment passes
through or comes within ``cell * 1e-6`` of, found row by row (:func:`row_cols`); a query
walks the buckets its own segment, or its box of a given reach, passes through, padded
by the same slack (:mod:`skyroute.motion.zone_kernels`: ``sight``, ``near``, ``inside``). Every
edge that meets the query's segment shares a point with it, and that point's bucket is
walked by both: the queries answer exactly what a test of every edge answers (the tests
compare them on random segments, boxes and points). Out of the grid (the edges' box and
half a cell) there is no edge.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

SLACK = 1e-6  # of a cell: the padding that absorbs rounding in the bucket arithmetic


def build(edges: np.ndarray, cell: float | None = None
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(meta, start, ids) for ``edges`` (E, 4): by default about one bucket per edge,
    square buckets no smaller than the edges' mean length over four (so an edge spans a
    few buckets), at most 4,096 across; or buckets ``cell`` wide."""
    e = np.ascontiguousarray(edges, dtype=float).reshape(-1, 4)
    if len(e) == 0:
        return np.array([0.0, 0.0, 1.0, 1.0, 1.0]), np.zeros(2, np.int64), np.zeros(0, np.int64)
    lo = np.minimum(e[:, :2], e[:, 2:]).min(axis=0)
    hi = np.maximum(e[:, :2], e[:, 2:]).max(axis=0)
    w, h = hi - lo
    mean = float(np.hypot(e[:, 2] - e[:, 0], e[:, 3] - e[:, 1]).mean())
    if cell is None:
        cell = max(math.sqrt(max(w * h, 1e-300) / len(e)), mean / 4, max(w, h) / 4096,
                   1e-300)
    cell = float(cell)
    x0, y0 = lo[0] - cell / 2, lo[1] - cell / 2
    nx = math.floor((w + cell) / cell) + 1
    ny = math.floor((h + cell) / cell) + 1
    meta = np.array([x0, y0, cell, float(nx), float(ny)])
    start, ids = _fill(e, meta)
    return meta, start, ids


@njit(cache=True, inline="always")
def index(v, origin, cell, n):
    """The bucket column (or row) of coordinate v, -1 below the grid and n above it."""
    f = (v - origin) / cell
    if not f >= 0.0:  # NaN lands below as well
        return -1
    if f >= n:
        return n
    return min(int(f), n - 1)  # f >= 0: truncation is the floor


@njit(cache=True)
def row_cols(ax, ay, bx, by, r, meta, pad):
    """(c0, c1): the columns of row r that segment ab comes within ``pad`` of (clamped to
    the grid; c0 > c1 when none)."""
    x0, y0, cell, nx = meta[0], meta[1], meta[2], int(meta[3])
    ylo, yhi = min(ay, by), max(ay, by)
    b0 = max(ylo, y0 + r * cell - pad)
    b1 = min(yhi, y0 + (r + 1) * cell + pad)
    if b0 > b1:
        return 0, -1
    xlo, xhi = min(ax, bx), max(ax, bx)
    if by != ay:
        u = ax + (b0 - ay) * (bx - ax) / (by - ay)
        v = ax + (b1 - ay) * (bx - ax) / (by - ay)
        lo_, hi_ = min(u, v), max(u, v)
        xlo, xhi = max(xlo, lo_), min(xhi, hi_)
        if xlo > xhi:  # rounding on a steep edge: keep the clamp's point
            xlo, xhi = xhi, xlo
    c0 = max(index(xlo - pad, x0, cell, nx), 0)
    c1 = min(index(xhi + pad, x0, cell, nx), nx - 1)
    return c0, c1


@njit(cache=True, inline="always")
def rows(ay, by, meta, pad):
    y0, cell, ny = meta[1], meta[2], int(meta[4])
    return (max(index(min(ay, by) - pad, y0, cell, ny), 0),
            min(index(max(ay, by) + pad, y0, cell, ny), ny - 1))


@njit(cache=True)
def _visit(edges, meta, count, ids, fill):
    """Count each edge's buckets (``ids`` empty) or list it in them."""
    nx = int(meta[3])
    pad = meta[2] * SLACK
    for i in range(edges.shape[0]):
        ax, ay, bx, by = edges[i, 0], edges[i, 1], edges[i, 2], edges[i, 3]
        r0, r1 = rows(ay, by, meta, pad)
        for r in range(r0, r1 + 1):
            c0, c1 = row_cols(ax, ay, bx, by, r, meta, pad)
            for c in range(c0, c1 + 1):
                b = r * nx + c
                if ids.shape[0] == 0:
                    count[b + 1] += 1
                else:
                    ids[fill[b]] = i
                    fill[b] += 1


def _fill(edges, meta):
    count = np.zeros(int(meta[3]) * int(meta[4]) + 1, np.int64)
    none = np.zeros(0, np.int64)
    _visit(edges, meta, count, none, none)
    start = np.cumsum(count)
    ids = np.empty(start[-1], np.int64)
    if len(ids):
        _visit(edges, meta, count, ids, start[:-1].copy())
    return start, ids
