"""FCND waypoints of a World path: [north, east, altitude, heading]."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

from skyroute.io.world_out import waypoints
from skyroute.world.world import World

EAST, NORTH = math.pi / 2, 0.0  # NED headings: clockwise from north


@pytest.fixture
def world():
    """An empty 100 m world whose points are (north, east)."""
    return World(np.empty(0, dtype=object), np.empty(0), np.empty(0), (),
                 boundary=shapely.box(-100, -100, 100, 100), frame="ned")


@pytest.mark.parametrize("path, headings", [
    # a point repeated inside the path: it had heading 0 (north) after flying east
    ([(0, 0), (0, 10), (0, 10), (10, 10)], [EAST, EAST, EAST, NORTH]),
    # repeated first: the next leg's heading, as the first point takes the first leg's
    ([(0, 0), (0, 0), (0, 10)], [EAST, EAST, EAST]),
    # repeated last (a goal appended to a path that already ends there)
    ([(0, 0), (10, 0), (10, 0), (10, 0)], [NORTH] * 4),
    ([(0, 0), (0, -10), (0, -10)], [3 * EAST] * 3),
    ([(5, 5), (5, 5)], [0.0, 0.0]),  # no leg moves: no direction to keep
    ([(5, 5)], [0.0]),
])
def test_a_zero_length_leg_keeps_the_heading_of_the_leg_before(world, path, headings):
    rows = waypoints(world, np.array(path, dtype=float), 5.0)
    assert [r[:3] for r in rows] == [[n, e, 5.0] for n, e in path]
    assert [r[3] for r in rows] == pytest.approx(headings)
