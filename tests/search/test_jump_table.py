"""JPS's straight-scan table against a cell-by-cell scan written from the rule: a scan
stops before a blocked cell, or on a free cell whose side cell is free while the side
cell behind it is blocked (a forced neighbour without corner cutting)."""

import numpy as np
import pytest

import skyroute
from skyroute.search.space import SearchSpace

STEP = ((1, 0), (-1, 0), (0, 1), (0, -1))  # table columns: east, west, south, north


def scan(free, x, y, dirn):
    """Steps to the first jump point, or minus the free steps to the wall."""
    dx, dy = STEP[dirn]
    sides = ((0, 1), (0, -1)) if dy == 0 else ((1, 0), (-1, 0))
    steps = 0
    while True:
        x, y = x + dx, y + dy
        if not free[y, x]:
            return -steps
        steps += 1
        for sx, sy in sides:
            if free[y + sy, x + sx] and not free[y + sy - dy, x + sx - dx]:
                return steps


@pytest.mark.parametrize("w, h, share, seed", [
    (7, 5, 0.2, 0), (62, 3, 0.0, 1), (63, 66, 0.1, 2), (64, 64, 0.3, 3),
    (130, 9, 0.05, 4), (9, 130, 0.05, 5), (200, 70, 0.4, 6)])
def test_table_equals_a_cell_by_cell_scan(w, h, share, seed):
    blocked = np.random.default_rng(seed).random((h, w)) < share
    space = SearchSpace(skyroute.Grid(blocked))
    table = space.jump_table()
    free = space.blocked.reshape(h + 2, space.Wp) == 0
    for y, x in np.argwhere(free):
        c = y * space.Wp + x
        for dirn in range(4):
            assert table[c, dirn] == scan(free, x, y, dirn), (x, y, dirn)


def test_a_long_jump_and_a_wall_at_once():
    blocked = np.zeros((3, 150), bool)
    blocked[0, 140] = True  # forced neighbour for an eastward scan along row 1 at x = 141
    space = SearchSpace(skyroute.Grid(blocked))
    table = space.jump_table()
    c = space.index((0, 1))
    assert table[c, 0] == 141  # east from (0, 1) to (141, 1)
    assert table[c, 1] == 0  # west: the border at once
    assert table[c, 3] == -1  # north: one free cell, then the border
