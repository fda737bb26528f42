"""A walls raster's cells name the same places whatever the safety margin."""

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

import skyroute
from skyroute.world.segments import rasterize_segments

ROOM = np.array([[0, 0, 20, 0], [20, 0, 20, 10], [20, 10, 0, 10], [0, 10, 0, 0],
                 [8, 0, 8, 6]], dtype=float)

coordinate = st.floats(-50, 50, allow_nan=False).map(lambda v: round(v, 2))


@settings(max_examples=40, deadline=None)
@given(walls=st.lists(st.tuples(coordinate, coordinate, coordinate, coordinate),
                      min_size=1, max_size=4),
       resolution=st.sampled_from([0.25, 0.5, 1.0, 1.5, 2.0]),
       safety=st.floats(0.1, 4.0).map(lambda v: round(v, 2)))
def test_the_safety_margin_neither_moves_nor_grows_the_raster(walls, resolution, safety):
    # the origin was the walls' box less safety and a cell: with --safety 1 at 0.5 m a
    # cell, cell (5, 5) lay at (1.25, 1.25) m instead of (2.25, 2.25) m
    seg = np.array(walls)
    bare = rasterize_segments(seg, resolution=resolution)
    grown = rasterize_segments(seg, resolution=resolution, safety=safety)
    assert grown.origin == bare.origin and grown.blocked.shape == bare.blocked.shape
    cells = np.argwhere(np.ones_like(bare.blocked))[:, ::-1]
    np.testing.assert_array_equal(grown.to_world(cells), bare.to_world(cells))
    # the cells lie on the lattice of multiples of the resolution and cover the walls
    assert all(o / resolution == pytest.approx(round(o / resolution)) for o in bare.origin)
    box = np.array([seg[:, [0, 2]].min(), seg[:, [1, 3]].min(), seg[:, [0, 2]].max(),
                    seg[:, [1, 3]].max()])
    ox, oy = bare.origin
    assert ox <= box[0] - resolution + 1e-9 and oy <= box[1] - resolution + 1e-9
    assert ox + bare.width * resolution >= box[2] + resolution - 1e-9
    assert oy + bare.height * resolution >= box[3] + resolution - 1e-9
    # the margin blocks every free cell whose centre is within it, and only those
    lines = shapely.multilinestrings([seg.reshape(-1, 2, 2)])
    centres = shapely.points(grown.to_world(cells))
    near = shapely.distance(centres, lines) <= safety
    flat = lambda a: a[cells[:, 1], cells[:, 0]]  # noqa: E731
    np.testing.assert_array_equal(flat(grown.blocked), flat(bare.blocked) | near)


def test_a_cell_names_the_same_place_with_any_safety(tmp_path):
    p = tmp_path / "walls.csv"
    p.write_text("x1,y1,x2,y2\n" + "\n".join(",".join(f"{v:g}" for v in w) for w in ROOM))
    grids = [skyroute.load_map(p, resolution=0.5, safety=s) for s in (0, 1, 2.5)]
    # safety 0 is as before: the room's box, from 0 m, and a cell more on every side
    assert grids[0].origin == (-0.5, -0.5) and grids[0].blocked.shape == (22, 42)
    for g in grids[1:]:
        assert g.origin == grids[0].origin and g.blocked.shape == grids[0].blocked.shape
        assert g.to_world([(5, 5)]).tolist() == [[2.25, 2.25]]


def test_a_margin_wider_than_the_walls_blocks_every_cell_of_the_same_raster(tmp_path):
    # it grew the raster by the margin on every side: safety=1e6 was refused as a raster
    # of 2e6 x 2e6 m, and any safety moved every cell
    p = tmp_path / "walls.csv"
    p.write_text("0,0,10,0\n0,5,10,5\n")
    bare, wide = (skyroute.load_map(p, safety=s) for s in (0, 1e6))
    assert wide.blocked.shape == bare.blocked.shape == (7, 12)
    assert wide.origin == bare.origin == (-1.0, -1.0) and wide.blocked.all()
