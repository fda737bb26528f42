"""Read a path back out of a parent array, as flat cells and as (x, y) cells with its
length (compiled, shared by every grid search)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def trace(parent, start, goal):
    """Flat indices from ``start`` to ``goal`` following ``parent`` pointers back."""
    count = 1
    c = goal
    while c != start:
        c = parent[c]
        count += 1
    out = np.empty(count, np.int64)
    c = goal
    for i in range(count - 1, -1, -1):
        out[i] = c
        if i:
            c = parent[c]
    return out


@njit(cache=True)
def trace_moves(moves, offs, start, goal):
    """Flat indices from ``start`` to ``goal`` following the entering move of each cell
    back (``moves[c]`` = k: c was entered from ``c - offs[k]``)."""
    count = 1
    c = goal
    while c != start:
        c -= offs[moves[c]]
        count += 1
    out = np.empty(count, np.int64)
    c = goal
    for i in range(count - 1, -1, -1):
        out[i] = c
        if i:
            c -= offs[moves[c]]
    return out


@njit(cache=True)
def to_cells(flat, Wp):
    """(K, 2) float (x, y) cells of flat indices, and the polyline's Euclidean length."""
    out = np.empty((len(flat), 2))
    length = 0.0
    for i in range(len(flat)):
        out[i, 0] = flat[i] % Wp - 1
        out[i, 1] = flat[i] // Wp - 1
        if i:
            dx = out[i, 0] - out[i - 1, 0]
            dy = out[i, 1] - out[i - 1, 1]
            length += math.sqrt(dx * dx + dy * dy)
    return out, length

