"""A start or goal inside an obstacle: the free point the error suggests is free as printed,
outside every obstacle (not only the one named) and not closed in by a block."""

import re

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

import skyroute
from skyroute import QueryError
from skyroute.world.world import World
from tests.conftest import SHARED

FCND = SHARED / "fcnd" / "colliders.csv"


def rect_world(boxes, boundary=None, frame="enu"):
    polys = shapely.box(*np.asarray(boxes, dtype=float).T)
    n = len(polys)
    return World(polys, np.full(n, -np.inf), np.full(n, np.inf), (), boundary, frame)


def suggested(world, start, goal=(50.0, 50.0)) -> tuple[float, float]:
    """The point the error suggests, as printed."""
    with pytest.raises(QueryError, match="nearest free point") as info:
        skyroute.plan(world, start, goal)
    a, b = re.search(r"nearest free point \(([-\d.]+), ([-\d.]+)\)", str(info.value)).groups()
    return float(a), float(b)


def test_not_inside_an_overlapping_neighbour():
    # the start is in box 0 by its right edge; box 1 covers that edge: the way out is up
    world = rect_world([(0, 0, 2, 2), (1.5, 0, 4, 1.8)])
    p = suggested(world, (1.9, 1.7))
    assert world.is_free([p])[0]
    assert p == (2.01, 1.81)  # by the corner where the two edges meet; not (2.00, 1.70)


def test_not_in_a_pocket_closed_in_by_the_block():
    # four boxes round a 1 m courtyard; the start is in the west box by the courtyard
    world = rect_world([(0, 0, 1, 3), (2, 0, 3, 3), (0, 0, 3, 1), (0, 2, 3, 3)])
    p = suggested(world, (0.9, 1.5))
    assert p == (-0.01, 1.5)  # not (1.0, 1.5), in the courtyard
    assert skyroute.plan(world, p, (50, 50)).found


def test_free_as_printed_to_the_cm():
    # the edge is at x = 1.0004: 1 mm past it prints as 1.00, which lies inside
    world = rect_world([(0, 0, 1.0004, 1)])
    p = suggested(world, (0.9, 0.5))
    assert p == (1.01, 0.5)
    assert world.is_free([p])[0]


def test_inside_the_boundary():
    boundary = shapely.box(-0.5, -10, 10, 10)
    world = rect_world([(-1, -1, 1, 1)], boundary=boundary)
    p = suggested(world, (-0.4, 0.0), goal=(5, 5))
    assert p in [(-0.4, 1.01), (-0.4, -1.01)]  # not (-1.00, 0.00), outside the boundary
    assert world.is_free([p])[0]


@st.composite
def worlds_and_points(draw):
    boxes = []
    for _ in range(draw(st.integers(1, 6))):
        x, y = draw(st.integers(0, 8)), draw(st.integers(0, 8))
        w, h = draw(st.integers(1, 5)), draw(st.integers(1, 5))
        off = draw(st.sampled_from([0.0, 0.0004, 0.003]))
        boxes.append((x - off, y - off, x + w + off, y + h + off))
    k = draw(st.integers(0, len(boxes) - 1))
    x0, y0, x1, y1 = boxes[k]
    u, v = draw(st.floats(0.05, 0.95)), draw(st.floats(0.05, 0.95))
    return boxes, (round(x0 + u * (x1 - x0), 2), round(y0 + v * (y1 - y0), 2))


@settings(max_examples=60, deadline=None)
@given(worlds_and_points())
def test_suggestion_is_free_and_reachable(case):
    boxes, start = case
    world = rect_world(boxes)
    if world.is_free([start])[0]:
        return
    p = suggested(world, start)
    assert world.is_free([p])[0]
    # reachable from far outside every box (not closed in)
    assert skyroute.plan(world, p, (50, 50)).found


@pytest.mark.shared_data
def test_fcnd_block_of_touching_boxes():
    # (300, 200) north, east lies in a block of 10 m boxes grown by 5 m into each other;
    # the suggestion was (300.00, 190.77): the edge of the box named, inside its neighbour
    city = skyroute.load_world(FCND, altitude=5, safety=5, frame="ned")
    p = suggested(city, (300, 200), goal=(0, 0))
    assert city.is_free([p])[0]
    assert skyroute.plan(city, (0, 0), p).found


def test_a_turning_vehicle_can_start_from_the_suggestion():
    """The suggestion lay on the obstacle's edge, (50.00, 60.00): free, but Hybrid A*'s
    pieces keep clear of every edge, so `fly --vehicle dubins` from it found no path
    (after 572 expansions). It is now a step of the printed resolution off the edge,
    on no edge."""
    from skyroute.motion.hybrid import plan as hybrid_plan

    world = rect_world([(40, 40, 60, 60)])
    for start in ((50.0, 45.0), (45.0, 50.0), (58.0, 59.0)):
        p = suggested(world, start, goal=(100.0, 100.0))
        assert hybrid_plan(world, p, (100.0, 100.0), 10.0).found
        assert world.is_free([p])[0]
        assert shapely.distance(world.obstacles[0], shapely.Point(p)) > 0
