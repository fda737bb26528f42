"""The zone edges' bucket grid: each indexed query answers what a scan of every edge
answers (shapely's proper crossings for sight), on random edge sets and queries whose
coordinates land on bucket boundaries, edge ends and collinear overlaps."""

import numpy as np
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from skyroute.motion import edge_grid
from skyroute.motion.zone_kernels import _inside, _near, inside, near, sight

# half-integers: with buckets 0.5, 1 or 2 wide many points sit on a bucket's side
coord = st.integers(-12, 12).map(lambda v: v / 2)
point = st.tuples(coord, coord)
edge = st.tuples(coord, coord, coord, coord).filter(lambda e: e[:2] != e[2:])


@st.composite
def edge_sets(draw):
    edges = np.array(draw(st.lists(edge, min_size=1, max_size=30)), dtype=float)
    owner = np.array(draw(st.lists(st.integers(0, 3), min_size=len(edges),
                                   max_size=len(edges))), dtype=np.int64)
    cell = draw(st.sampled_from([None, 0.5, 1.0, 2.0, 3.7]))
    return edges, owner, edge_grid.build(edges, cell)


@settings(max_examples=300, deadline=None)
@given(edge_sets(), point, point)
def test_sight_is_shapelys_no_proper_crossing(es, p, q):
    edges, _, grid = es
    segs = shapely.linestrings(edges.reshape(-1, 2, 2))
    expect = not shapely.crosses(shapely.LineString([p, q]), segs).any() if p != q else True
    assert sight(*p, *q, edges, *grid) == expect


@settings(max_examples=300, deadline=None)
@given(edge_sets(), point, st.sampled_from([0.0, 0.25, 0.5, 1.0, 1.5, 3.0]))
def test_near_is_the_scan_of_every_edge(es, p, reach):
    edges, _, grid = es
    assert np.array_equal(near(*p, reach, edges, *grid), _near(*p, edges, reach))


@settings(max_examples=300, deadline=None)
@given(edge_sets(), point)
def test_inside_is_the_scan_of_every_edge(es, p):
    edges, owner, grid = es
    assert inside(*p, edges, owner, 4, *grid) == _inside(*p, edges, owner, 4)


def test_points_and_segments_off_the_grid_meet_no_edge():
    edges = np.array([[0.0, 0.0, 1.0, 0.0], [1.0, 0.0, 1.0, 1.0]])
    grid = edge_grid.build(edges)
    assert sight(-5.0, 0.5, 5.0, 0.5, edges, *grid) is False  # crosses the grid
    assert sight(-5.0, 5.0, 5.0, 5.0, edges, *grid) is True
    assert len(near(50.0, 50.0, 1.0, edges, *grid)) == 0
    assert inside(0.5, -50.0, edges, np.zeros(2, np.int64), 1, *grid) == -1


def test_an_edge_is_listed_only_in_the_buckets_it_passes():
    # a diagonal across a 10 x 10 grid: about 2 * 10 buckets, not the 100 of its box
    edges = np.array([[0.0, 0.0, 10.0, 10.0], [0.0, 10.0, 0.5, 10.0]])
    meta, _, ids = edge_grid.build(edges, 1.0)
    assert int(meta[3]) * int(meta[4]) >= 100
    assert np.count_nonzero(ids == 0) <= 40
