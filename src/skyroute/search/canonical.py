"""Canonical successors: which moves A* needs to try from a cell, given how it got there.

On an 8-connected grid without corner cutting, every shortest path has an equally short
"canonical" twin that takes its diagonal steps before its straight ones wherever it can
(Sturtevant & Rabin, "Canonical Orderings on Grids", IJCAI 2016; the pruning rules of
Jump Point Search, Harabor & Grastien 2011/2014). A search that only generates canonical
successors still finds an optimal path, and skips the neighbours the parent already
reached at least as cheaply:

- arrived diagonally by (dx, dy): (dx, 0), (0, dy) and (dx, dy) (no forced neighbours
  without corner cutting);
- arrived straight by (dx, 0): (dx, 0), plus, for each side s, (0, s) and (dx, s) when
  (0, s) is free but (-dx, s), beside the parent, is blocked (a forced neighbour); the
  same turned for vertical arrivals.

``succ[k, m]`` is the set of moves to try (bits in :data:`moves.MOVES` order) for a cell
with move mask ``m`` entered by move k (k = 8: the start). The forced test reads the mask
alone: with the parent and (0, s) free, the diagonal (-dx, s) is illegal exactly when
its cell is blocked. Built once at import (9 x 256 bytes, stays in L1 cache).
"""

from __future__ import annotations

import numpy as np

from skyroute.search.moves import MOVES

START = 8


def _move(dx: int, dy: int) -> int:
    return MOVES.index((dx, dy))


def _successors(k: int, m: int) -> int:
    if k == START:
        return m
    dx, dy = MOVES[k]
    if dx and dy:
        bits = 1 << _move(dx, 0) | 1 << _move(0, dy) | 1 << k
    else:
        bits = 1 << k
        for s in (-1, 1):
            side, diag = ((0, s), (dx, s)) if dy == 0 else ((s, 0), (s, dy))
            behind = (-dx, s) if dy == 0 else (s, -dy)
            if m >> _move(*side) & 1 and not m >> _move(*behind) & 1:
                bits |= 1 << _move(*side) | 1 << _move(*diag)
    return bits & m


def successor_table(canonical: bool) -> np.ndarray:
    """(9, 256) uint8: the moves to try per entering move and mask; every legal move
    when ``canonical`` is False (4-connected grids, corner cutting)."""
    table = np.empty((START + 1, 256), np.uint8)
    for k in range(START + 1):
        for m in range(256):
            table[k, m] = _successors(k, m) if canonical else m
    table.setflags(write=False)
    return table


#: the lowest set bit's index of each byte: kernels walk a move set bit by bit, not
#: testing all 8 moves (each test a branch that random obstacles make unpredictable)
LOWEST = np.array([(m & -m).bit_length() - 1 for m in range(256)], np.int64)
LOWEST.setflags(write=False)

CANONICAL = successor_table(True)
EVERY = successor_table(False)
