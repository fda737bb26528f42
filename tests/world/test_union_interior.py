"""Touching and overlapping obstacles are one building: a point or a segment is free only
when it meets no interior of the obstacles' union (shapely's union is the reference).

Each obstacle was tested alone, so a segment along the face two touching boxes share, or
through it from outside, touched both and was "free": the field robot flew 16 m through
a building of two boxes, and the grid planners' shortcut cut straight through it."""

import math
from types import SimpleNamespace

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

import skyroute
from skyroute import QueryError
from skyroute.fleet import nofly
from skyroute.motion.potential import run_field
from skyroute.world.world import World
from tests.cli.test_cli import run


def rect_world(boxes, boundary=None):
    polys = shapely.box(*np.asarray(boxes, dtype=float).T)
    n = len(polys)
    return World(polys, np.full(n, -np.inf), np.full(n, np.inf), (), boundary, "enu")


def union_free(union, a, b) -> bool:
    """The reference: the segment (or point) meets no interior of the union."""
    g = shapely.Point(a) if tuple(a) == tuple(b) else shapely.LineString([a, b])
    return not union.relate_pattern(g, "T********")


TWO = rect_world([(0, 0, 10, 20), (10, 0, 20, 20)])  # touching along x = 10


@pytest.mark.parametrize("a, b, free", [
    ((10, 2), (10, 18), False),    # along the shared face, between two points on it
    ((10, -5), (10, 25), False),   # from outside, straight through the shared face
    ((10, -5), (10, 0), True),     # up to the face's outer end: touching a corner
    ((-5, 0), (25, 0), True),      # along the outer edges of both
    ((5, -5), (5, 25), False),     # through one box's interior (as before)
])
def test_a_segment_along_or_through_a_shared_face_is_blocked(a, b, free):
    assert union_free(shapely.union_all(TWO.obstacles), a, b) is free
    assert TWO.segments_free([a], [b]).tolist() == [free]
    assert TWO.segment_free(a, b) is free


def test_a_point_on_a_shared_face_is_inside_and_named():
    assert TWO.is_free([(10, 5), (10, 0), (0, 5)]).tolist() == [False, True, True]
    assert TWO.blocking([(10, 5), (10, 0)]).tolist() == [0, -1]
    with pytest.raises(QueryError, match=r"start \(10.00, 5.00\) lies inside obstacle "
                                         r"'obstacle 0'; nearest free point"):
        skyroute.plan(TWO, (10, 5), (30, 5), algorithm="theta")


def test_overlapping_and_corner_touching_boxes():
    over = rect_world([(0, 0, 12, 20), (10, 0, 20, 20)])
    assert not over.segments_free([(11, -5), (10, -5)], [(11, 25), (10, 25)]).any()
    # boxes meeting at one corner leave the diagonal through it free (no interior there)
    corner = rect_world([(0, 0, 10, 10), (10, 10, 20, 20)])
    assert corner.segments_free([(0, 20)], [(20, 0)]).tolist() == [True]
    assert corner.is_free([(10, 10)]).tolist() == [True]
    # an L of three boxes: through the inner corner where all three meet
    ell = rect_world([(0, 0, 10, 10), (10, 0, 20, 10), (0, 10, 10, 20)])
    assert ell.segments_free([(10, 10), (10, 10)], [(10, 0), (0, 10)]).tolist() == \
        [False, False]
    assert ell.segments_free([(10, 10)], [(20, 20)]).tolist() == [True]


@pytest.mark.parametrize("algorithm", ["theta", "astar", "visibility", "prm"])
def test_planners_go_round_a_building_of_two_boxes(algorithm):
    # the grid planners' shortcut ran straight along the shared face: cost 30
    r = skyroute.plan(TWO, (10, -5), (10, 25), algorithm=algorithm)
    union = shapely.union_all(TWO.obstacles)
    assert r.found and r.cost > 40
    assert all(union_free(union, a, b) for a, b in zip(r.path[:-1], r.path[1:],
                                                       strict=True))


def test_the_field_robot_does_not_start_on_a_shared_wall():
    with pytest.raises(QueryError, match="lies inside obstacle"):
        run_field(TWO, (10, 2), (10, 18))


def test_fly_field_through_a_building_of_two_colliders_boxes(monkeypatch, capsys, tmp_path):
    # two 10 x 20 m boxes sharing the face north = 5: it flew 16 m along it, "found"
    p = tmp_path / "two.csv"
    p.write_text("lat0 37.792480, lon0 -122.397450\n"
                 "posX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n"
                 "0,0,10,5,10,10\n10,0,10,5,10,10\n")
    code, out, err = run(monkeypatch, capsys, "fly", str(p), "--frame", "local", "--vehicle",
                         "field", "--start", "5,-8", "--goal", "5,8", "--altitude", "5")
    assert code == 2 and "Traceback" not in out + err
    assert "start (5.00, -8.00) lies inside obstacle 'box at line 3'" in out + err


def test_a_runway_along_the_edge_two_no_fly_zones_share_crosses_them():
    # zones are (north, east) points; they share the edge east = 10
    scenario = SimpleNamespace(no_fly_zones=[
        SimpleNamespace(name="west", points=[(0, 0), (20, 0), (20, 10), (0, 10)]),
        SimpleNamespace(name="east", points=[(0, 10), (20, 10), (20, 20), (0, 20)])])
    with pytest.raises(QueryError, match="runway crosses no-fly zone 'west'"):
        nofly.check_line(scenario, (-5, 10), (25, 10), "runway")
    assert nofly.crossed(scenario, shapely.LineString([(-5, -1), (25, -1)])) is None


# -- property: the World's answer is shapely's union-interior answer ---------------------

lattice = st.integers(0, 8)


@st.composite
def boxes_and_segments(draw):
    """Boxes on a unit lattice (so they touch and overlap often, and their union is
    exact) and segments between lattice points, half-lattice points or anywhere."""
    boxes = []
    for _ in range(draw(st.integers(2, 6))):
        x, y = draw(lattice), draw(lattice)
        boxes.append((x, y, x + draw(st.integers(1, 4)), y + draw(st.integers(1, 4))))
    if draw(st.booleans()):  # a neighbour sharing the first box's right face
        _, y0, x1, y1 = boxes[0]
        boxes.append((x1, y0 + draw(st.integers(-1, y1 - y0 - 1)), x1 + 2, y1))
    end = st.one_of(st.tuples(lattice, lattice),
                    st.tuples(lattice, lattice).map(lambda p: (p[0] + 0.5, p[1] + 0.5)),
                    st.tuples(st.floats(-1, 13), st.floats(-1, 13)))
    segments = draw(st.lists(st.tuples(end, end), min_size=1, max_size=12))
    return boxes, segments


@settings(max_examples=150, deadline=None)
@given(boxes_and_segments())
def test_segments_and_points_agree_with_shapely_union(case):
    boxes, segments = case
    world = rect_world(boxes)
    union = shapely.union_all(world.obstacles)
    a = np.array([s[0] for s in segments], dtype=float)
    b = np.array([s[1] for s in segments], dtype=float)
    expected = [union_free(union, p, q) for p, q in zip(a, b, strict=True)]
    assert world.segments_free(a, b).tolist() == expected
    assert [world.segment_free(p, q) for p, q in zip(a, b, strict=True)] == expected
    pts = np.vstack([a, b, (a + b) / 2])
    assert world.is_free(pts).tolist() == [union_free(union, p, p) for p in pts]
    # a blocked point is named by an obstacle it lies in or on
    j = world.blocking(pts)
    assert all(world.obstacles[k].intersects(shapely.Point(p))
               for k, p in zip(j, pts, strict=True) if k >= 0)


def test_visibility_graph_agrees_with_shapely_union_on_a_block_of_boxes():
    # a city block: touching and overlapping boxes; the exact path still bends at the
    # union's corners only, and is as long as the shortest path round the block
    world = rect_world([(0, 0, 10, 10), (10, 0, 20, 10), (5, 10, 15, 20), (14, 5, 25, 12)])
    r = skyroute.plan(world, (-1, 15), (30, 5))
    union = shapely.union_all(world.obstacles)
    assert r.found and all(union_free(union, a, b)
                           for a, b in zip(r.path[:-1], r.path[1:], strict=True))
    assert r.cost == pytest.approx(math.dist((-1, 15), (5, 20)) + math.dist((5, 20), (15, 20))
                                   + math.dist((15, 20), (25, 12)) + math.dist((25, 12),
                                                                               (30, 5)),
                                   rel=1e-12)
