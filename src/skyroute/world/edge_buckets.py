"""Segments bucketed on a uniform grid (CSR), so a compiled test of a segment or a point
against many obstacle edges looks only at the edges near it.

Bucket b = iy * nx + ix covers [x0 + ix * cell, x0 + (ix + 1) * cell) and likewise in y;
its edges are ``items[start[b]:start[b + 1]]``, in increasing edge order. An edge is in
every bucket its bounding box, grown by ``eps``, overlaps. The grid starts one cell
before the edges' lower corner and ends at least one cell after their upper corner.
"""

from __future__ import annotations

import numpy as np
from numba import njit


def bucket_edges(edges: np.ndarray, cell: float, eps: float) -> tuple:
    """(start, items, x0, y0, nx, ny) for (E, 4) ``edges`` (x1, y1, x2, y2), E >= 1."""
    lo = np.minimum(edges[:, :2], edges[:, 2:]).min(0)
    hi = np.maximum(edges[:, :2], edges[:, 2:]).max(0)
    x0, y0 = float(lo[0] - cell), float(lo[1] - cell)
    nx = int((hi[0] - x0) // cell) + 2
    ny = int((hi[1] - y0) // cell) + 2
    start, items = _bucket(edges, x0, y0, float(cell), nx, ny, float(eps))
    return start, items, x0, y0, nx, ny


@njit(cache=True)
def _cells(edges, e, x0, y0, cell, eps):
    """The bucket ranges (c0, c1, r0, r1) of edge e's box grown by eps."""
    return (int((min(edges[e, 0], edges[e, 2]) - eps - x0) // cell),
            int((max(edges[e, 0], edges[e, 2]) + eps - x0) // cell),
            int((min(edges[e, 1], edges[e, 3]) - eps - y0) // cell),
            int((max(edges[e, 1], edges[e, 3]) + eps - y0) // cell))


@njit(cache=True)
def _bucket(edges, x0, y0, cell, nx, ny, eps):
    """CSR buckets: every bucket an edge's box (grown by eps) overlaps lists the edge."""
    count = np.zeros(nx * ny + 1, np.int64)
    for e in range(edges.shape[0]):
        c0, c1, r0, r1 = _cells(edges, e, x0, y0, cell, eps)
        for r in range(r0, r1 + 1):
            for c in range(c0, c1 + 1):
                count[r * nx + c + 1] += 1
    start = np.cumsum(count)
    items = np.empty(start[-1], np.int64)
    fill = start[:-1].copy()
    for e in range(edges.shape[0]):
        c0, c1, r0, r1 = _cells(edges, e, x0, y0, cell, eps)
        for r in range(r0, r1 + 1):
            for c in range(c0, c1 + 1):
                b = r * nx + c
                items[fill[b]] = e
                fill[b] += 1
    return start, items
