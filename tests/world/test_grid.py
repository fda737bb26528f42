import copy
import pickle
import re

import numpy as np
import pytest
import shapely
from PIL import Image

import skyroute
from skyroute import Grid, InputFormatError, OptionError, load_map
from skyroute.world.image import from_array
from skyroute.world.segments import rasterize_segments


def test_grid_is_immutable_and_copies_its_input():
    a = np.zeros((2, 3), dtype=bool)
    g = Grid(a)
    a[0, 0] = True
    assert not g.blocked[0, 0]
    with pytest.raises(ValueError):
        g.blocked[0, 0] = True


def test_cell_world_round_trip():
    g = Grid(np.zeros((4, 5), bool), resolution=0.5, origin=(10.0, -2.0))
    cells = np.array([[0, 0], [4, 3], [2, 1]])
    np.testing.assert_allclose(g.to_world(cells), [[10.25, -1.75], [12.25, -0.25],
                                                   [11.25, -1.25]])
    np.testing.assert_array_equal(g.to_cell(g.to_world(cells)), cells)
    np.testing.assert_array_equal(g.to_cell([[9.99, -2.0]]), [[-1, 0]])


@pytest.mark.parametrize("bad", [np.zeros((0, 3)), np.zeros(3), np.zeros((2, 2, 2))])
def test_bad_shapes_raise(bad):
    with pytest.raises(OptionError):
        Grid(bad)


def test_inflate_point_robot_seed_case():
    # A point robot with 0.3 m padding on a 0.1 m grid: one blocked cell grows into the
    # disc of cells whose centres lie within 0.3 m of its centre (3 cells).
    a = np.zeros((9, 9), bool)
    a[4, 4] = True
    g = Grid(a, resolution=0.1).inflate(0.3)
    yy, xx = np.mgrid[0:9, 0:9]
    expected = (xx - 4) ** 2 + (yy - 4) ** 2 <= 9
    np.testing.assert_array_equal(g.blocked, expected)
    assert g.blocked.sum() == 29
    assert Grid(a).inflate(0.0).blocked.sum() == 1


def test_inflate_rejects_negative():
    with pytest.raises(OptionError, match="safety=-1"):
        Grid(np.zeros((2, 2), bool)).inflate(-1)


def test_old_names_still_work_with_a_deprecation_warning():
    a = np.zeros((9, 9), bool)
    a[4, 4] = True
    with pytest.warns(DeprecationWarning, match="clearance"):
        old = Grid(a).inflate(clearance=2.0)
    np.testing.assert_array_equal(old.blocked, Grid(a).inflate(2.0).blocked)
    with pytest.warns(DeprecationWarning, match="cell_size"):
        g = Grid(a, cell_size=0.5)
    assert g.resolution == 0.5
    with pytest.warns(DeprecationWarning, match="cell_size"):
        assert g.cell_size == 0.5
    with pytest.raises(OptionError, match="not both"):
        Grid(a, 0.5, cell_size=0.5)


def test_segments_rasterise_cells_they_cross():
    # A wall from (0, 0) to (4, 2) metres on a 1 m grid with bounds 0..5 x 0..3. It
    # crosses cells (0,0) (1,0) (2,1) (3,1) and touches closed squares at the vertex
    # (2, 1): cells (2,0), (1,1); and at its end (4, 2): cells (4,1), (3,2), (4,2).
    g = rasterize_segments(np.array([[0.0, 0.0, 4.0, 2.0]]), resolution=1.0,
                           bounds=(0, 0, 5, 3))
    expected = np.array([
        [1, 1, 1, 0, 0],
        [0, 1, 1, 1, 1],
        [0, 0, 0, 1, 1],
    ], dtype=bool)
    np.testing.assert_array_equal(g.blocked, expected)


def test_segment_clearance_is_exact_distance_to_the_wall():
    seg = np.array([[0.0, 2.5, 10.0, 2.5]])
    g = rasterize_segments(seg, resolution=0.5, safety=1.0, bounds=(0, 0, 10, 5))
    centres_y = g.to_world(np.c_[np.zeros(g.height), np.arange(g.height)])[:, 1]
    rows_blocked = g.blocked.all(axis=1)
    np.testing.assert_array_equal(rows_blocked, np.abs(centres_y - 2.5) <= 1.0)


def test_segment_file_and_errors(tmp_path):
    p = tmp_path / "walls.csv"
    p.write_text("x1,y1,x2,y2\n0,0,2,0\n2,0,2,2\n")
    g = load_map(p, resolution=0.5, safety=0.25)
    assert g.resolution == 0.5 and g.blocked.any() and not g.blocked.all()
    p.write_text("x1,y1,x2,y2\n0,0,2,0\n1,2,three,4\n")
    with pytest.raises(InputFormatError, match=r"walls\.csv:3: .*numbers"):
        load_map(p)
    p.write_text("0,0,2\n")
    with pytest.raises(InputFormatError, match=r"walls\.csv:1: expected 4 columns"):
        load_map(p)
    # a colliders city read as walls: "expected 4 columns x1,y1,x2,y2, got 2", no way on
    for home in ("lat0 55.944494, lon0 -3.186874", "LON0 -3.186874, LAT0 55.944494"):
        p.write_text(f"{home}\nposX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n0,0,5,1,1,5\n")
        with pytest.raises(InputFormatError, match=re.escape(
                "walls.csv:1: a colliders.csv city (line 1 'lat0 ..., lon0 ...'), not wall "
                "segments x1,y1,x2,y2: load it with skyroute.load_world")):
            load_map(p)
    # The first file's grid: the walls' extent on the 0.5 m lattice and one cell each
    # side, whatever the safety (it was grown by the safety too, from (-0.75, -0.75)), so
    # 6 x 6 cells from (-0.5, -0.5); blocked are the cells whose closed squares the walls
    # touch (y = 0 is the edge of rows 0 and 1, x = 2 of columns 4 and 5), no centre of
    # another lying within 0.25 m.
    expected = np.zeros((6, 6), bool)
    expected[0:2, :] = expected[:, 4:6] = True
    np.testing.assert_array_equal(g.blocked, expected)
    assert tuple(g.origin) == (-0.5, -0.5)


@pytest.mark.parametrize("header", ["x1,y1,x2,y2\r\n", ""])
def test_segment_file_with_a_byte_order_mark_reads_as_without(tmp_path, header):
    rows = "0,0,2,0\r\n2,0,2,2\r\n"
    plain, bom = tmp_path / "walls.csv", tmp_path / "excel.csv"
    plain.write_text(header + rows)
    bom.write_bytes(b"\xef\xbb\xbf" + (header + rows).encode())  # Excel's "CSV UTF-8"
    np.testing.assert_array_equal(load_map(bom).blocked, load_map(plain).blocked)


@pytest.mark.parametrize("lead", ["# walls of the hall\n", "\n\n", "# a\n\n  \n# b\n",
                                  "#x1,y1,x2,y2\n"])
@pytest.mark.parametrize("header", ["x1,y1,x2,y2\n", "X1, Y1, X2, Y2\n", ""])
def test_a_header_under_comments_or_blank_lines_is_still_the_header(tmp_path, lead, header):
    # under a '# walls' line the header was read as a wall of words: "walls.csv:2:
    # x1,y1,x2,y2 must be numbers, got ['x1', 'y1', 'x2', 'y2']"
    rows = "0,0,2,0\n2,0,2,2\n"
    plain, odd = tmp_path / "walls.csv", tmp_path / "odd.csv"
    plain.write_text(rows)
    odd.write_text(lead + header + rows)
    np.testing.assert_array_equal(load_map(odd).blocked, load_map(plain).blocked)


def test_a_header_is_read_only_once(tmp_path):
    p = tmp_path / "walls.csv"
    p.write_text("# walls\nx1,y1,x2,y2\n0,0,2,0\nx1,y1,x2,y2\n")
    with pytest.raises(InputFormatError, match=r"walls\.csv:4: x1,y1,x2,y2 must be numbers"):
        load_map(p)


def test_png_dark_pixels_are_blocked(tmp_path):
    img = np.full((3, 4), 255, np.uint8)
    img[1, 2] = 0
    img[2, 0] = 100
    Image.fromarray(img).save(tmp_path / "m.png")
    g = load_map(tmp_path / "m.png", resolution=0.2)
    expected = np.zeros((3, 4), bool)
    expected[1, 2] = expected[2, 0] = True
    np.testing.assert_array_equal(g.blocked, expected)
    assert g.resolution == 0.2


def test_npy_and_unknown_suffix(tmp_path):
    np.save(tmp_path / "m.npy", np.eye(3))
    np.testing.assert_array_equal(load_map(tmp_path / "m.npy").blocked, np.eye(3, dtype=bool))
    (tmp_path / "m.txt").write_text("x")
    with pytest.raises(InputFormatError, match="unknown map type"):
        load_map(tmp_path / "m.txt")
    (tmp_path / "bad.png").write_text("not an image")
    with pytest.raises(InputFormatError, match=r"bad\.png: cannot read as an image"):
        load_map(tmp_path / "bad.png")


@pytest.mark.parametrize("content, words", [
    (b"junk", "not a .npy file"),
    (None, "not a .npy file"),  # an .npz archive named .npy
    (np.array([[0.0, np.nan], [0.0, 0.0]]), "NaN at cell (1, 0) (x, y)"),
])
def test_npy_that_is_no_array_or_holds_nan_is_one_line(tmp_path, content, words):
    p = tmp_path / "m.npy"
    if content is None:
        with p.open("wb") as fh:
            np.savez(fh, a=np.zeros((2, 2)))
    elif isinstance(content, bytes):
        p.write_bytes(content)
    else:
        np.save(p, content)
    with pytest.raises(InputFormatError) as err:
        load_map(p)
    assert str(err.value).startswith(f"{p}: ") and words in str(err.value)
    assert "allow_pickle" not in str(err.value)


@pytest.mark.parametrize("make, param", [
    (lambda a: from_array(a), "array"),
    (lambda a: Grid(a), "blocked"),
])
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_an_array_holding_nan_is_refused_naming_its_cell(make, param, dtype):
    # bool(nan) is True: the NaN cell (2, 1) was read as blocked, as .npy files were
    a = np.zeros((3, 4), dtype)
    a[1, 2] = a[2, 0] = np.nan
    with pytest.raises(OptionError) as err:
        make(a)
    assert str(err.value) == f"{param} has NaN at cell (2, 1) (x, y); use 0 for free and " \
        "non-zero for blocked"
    assert err.value.param == param
    a[1, 2] = a[2, 0] = 1.0  # numbers still read as before: non-zero blocked
    assert make(a).blocked.tolist() == (a != 0).tolist()


def test_missing_file_lists_bundled_maps(tmp_path):
    with pytest.raises(InputFormatError, match=r"no such file.*den312d"):
        load_map(tmp_path / "nothing.map")


@pytest.mark.parametrize("segments, resolution", [
    ([[0.0, 0.0, 10.0, 0.0]], 1e-7),  # a resolution meant in kilometres
    ([[0.0, 0.0, 1e12, 0.0]], 1.0),  # one far-off coordinate
])
def test_a_raster_too_large_is_refused_before_it_is_allocated(segments, resolution):
    from skyroute.world.grid import MAX_CELLS

    with pytest.raises(OptionError, match=rf"above {MAX_CELLS:,}; use a coarser resolution"):
        rasterize_segments(np.array(segments), resolution=resolution)
    world = skyroute.World([shapely.LineString(np.reshape(segments, (2, 2))).buffer(0.5)],
                           [0], [10], ("wall",), frame="enu")
    with pytest.raises(OptionError, match="use a coarser resolution"):
        world.rasterize(resolution)


WALLS = "x1,y1,x2,y2\n0,0,10,0\n0,5,10,5\n{far}\n2,2,4,4\n"


@pytest.mark.parametrize("far, options, error, words", [
    # one mistyped coordinate (1e9 for 10): its line is named, not only the resolution
    ("0,0,1e9,3", {}, InputFormatError,
     r"^{p}:4: the wall \(0, 0\) - \(1e\+09, 3\) stretches the map to 1e\+09 x 7 m, "
     r"1e\+09 x 7 cells at 1 m a cell, above 67,108,864; is a coordinate wrong\?"),
    ("-4e8,2,3,2", {}, InputFormatError, r"^{p}:4: the wall \(-4e\+08, 2\) - \(3, 2\)"),
    # walls spread evenly at a resolution meant in kilometres: the resolution, with the file
    ("1,1,2,2", {"resolution": 1e-5}, OptionError,
     r"^{p}: resolution=1e-05 over a 10 x 5\.00002 extent .*; use a coarser resolution$"),
])
def test_a_walls_raster_too_large_names_the_file_and_the_cause(tmp_path, far, options,
                                                               error, words):
    p = tmp_path / "walls.csv"
    p.write_text(WALLS.format(far=far))
    with pytest.raises(error, match=words.format(p=re.escape(str(p)))) as info:
        load_map(p, **options)
    assert "\n" not in str(info.value)
    if error is OptionError:
        assert info.value.param == next(iter(options))


def test_a_folder_is_not_a_map_and_does_not_hide_a_bundled_one(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "den312d").mkdir()
    assert load_map("den312d").width == 65  # the bundled map, not the folder
    with pytest.raises(InputFormatError, match="a folder, not a map file"):
        load_map(tmp_path / "den312d")
    fifo = tmp_path / "pipe.map"  # a pipe (e.g. a process substitution) is read as a file
    import os
    import threading

    os.mkfifo(fifo)
    text = skyroute.bundled_maps()["den312d"].read_text()
    writer = threading.Thread(target=fifo.write_text, args=(text,))
    writer.start()
    assert load_map(fifo).width == 65
    writer.join()


def test_an_empty_path_or_a_geojson_world_is_named_as_such(tmp_path):
    # "" read as the folder ".": ".: a folder, not a map file"
    with pytest.raises(OptionError, match=r"^path='' is empty: give a map file") as info:
        load_map("")
    assert info.value.param == "path"
    # GeoJSON zones read "unknown map type '.geojson'", naming no way on
    zones = tmp_path / "zones.geojson"
    zones.write_text('{"type": "FeatureCollection", "features": []}')
    with pytest.raises(skyroute.errors.WorldNotGridError, match=re.escape(
            f"{zones}: GeoJSON zones (.geojson), a world, not a grid map (.map, .csv walls, "
            ".npy, an image): load it with skyroute.load_world")):
        load_map(zones)


@pytest.mark.parametrize("copy_of", [copy.copy, copy.deepcopy,
                                     lambda g: pickle.loads(pickle.dumps(g))])
def test_a_copied_or_unpickled_grid_stays_read_only(copy_of):
    # a writable copy could be changed under the search cache keyed by the grid and
    # then planned through its new walls
    g = copy_of(Grid(np.zeros((3, 5), bool), resolution=0.5, origin=(1.0, 2.0), name="g"))
    assert not g.blocked.flags.writeable
    assert (g.resolution, g.origin, g.name) == (0.5, (1.0, 2.0), "g")
    with pytest.raises(ValueError):
        g.blocked[:, 2] = True
    assert skyroute.plan(g, (0, 1), (4, 1)).cost == 4


@pytest.mark.parametrize("kwargs,param", [
    ({"resolution": "1"}, "resolution"), ({"resolution": [1]}, "resolution"),
    ({"resolution": True}, "resolution"), ({"origin": (1,)}, "origin"),
    ({"origin": None}, "origin"), ({"origin": (float("nan"), 0.0)}, "origin"),
    ({"origin": (0.0, float("inf"))}, "origin")])
def test_grid_resolution_and_origin_are_checked(kwargs, param):
    with pytest.raises(OptionError) as err:
        Grid(np.zeros((3, 3)), **kwargs)
    assert err.value.param == param


@pytest.mark.parametrize("kwargs", [{"resolution": "2"}, {"safety": "1"}])
def test_load_map_options_must_be_numbers(kwargs):
    with pytest.raises(OptionError, match="must be a finite number"):
        load_map("den312d", **kwargs)


def test_load_map_path_errors_are_skyroute_errors(tmp_path):
    with pytest.raises(InputFormatError, match="cannot read"):
        load_map("x" * 300 + ".map")  # longer than a file name may be
    with pytest.raises(OptionError, match="must be a file path"):
        load_map(None)
    np.save(tmp_path / "rec.npy", np.zeros((2, 2), dtype=[("a", "i4")]))
    with pytest.raises(InputFormatError, match="numbers or booleans"):
        load_map(tmp_path / "rec.npy")


@pytest.mark.parametrize("suffix", [".png", ".tiff"])
def test_a_16_bit_image_reads_as_its_8_bit_twin(tmp_path, suffix):
    grey = np.array([[0, 40, 100, 127, 128, 200, 255]], np.uint8)
    Image.fromarray(grey).save(tmp_path / "a8.png")
    Image.fromarray(grey.astype(np.uint16) * 257).save(tmp_path / f"a16{suffix}")
    with Image.open(tmp_path / f"a16{suffix}") as img:
        assert img.mode.startswith("I")  # Pillow's 16-bit grey: the case under test
    eight, sixteen = load_map(tmp_path / "a8.png"), load_map(tmp_path / f"a16{suffix}")
    assert eight.blocked.tolist() == [[True, True, True, True, False, False, False]]
    assert sixteen.blocked.tolist() == eight.blocked.tolist()


def test_an_image_is_read_in_bands_of_rows_not_as_float_copies_of_the_whole(tmp_path):
    # the whole image went to RGBA and then to float32 grey: 20 bytes a pixel, 1.4 GB
    # for a PNG at the 8192 x 8192 limit; numpy's and Python's allocations only here
    # (tracemalloc does not see Pillow's own image memory)
    import tracemalloc

    grey = np.full((2048, 1024), 255, np.uint8)
    grey[100:1900, 500] = 0
    rgba = np.dstack([grey] * 3 + [np.full_like(grey, 255)])
    rgba[:5, :5, 3] = 0  # transparent: free whatever its colour
    rgba[:5, :5, :3] = 0
    Image.fromarray(grey).save(tmp_path / "g.png")
    Image.fromarray(rgba).save(tmp_path / "a.png")
    for name in ("g.png", "a.png"):
        tracemalloc.start()
        try:
            grid = load_map(tmp_path / name)
            peak = tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()
        np.testing.assert_array_equal(grid.blocked, grey < 128)
        assert peak < 8 * grey.size, f"{name}: {peak / grey.size:.1f} bytes a pixel"


def test_a_floating_point_image_is_refused(tmp_path):
    Image.fromarray(np.zeros((2, 2), np.float32)).save(tmp_path / "f.tiff")
    with pytest.raises(InputFormatError, match="floating-point image"):
        load_map(tmp_path / "f.tiff")


def test_reprs_summarise_grid_result_and_index():
    """A notebook shows a line, not the arrays: sizes, counts and statistics."""
    grid = load_map("den312d")
    assert repr(grid) == ("<Grid 'den312d.map': 65x81 cells, "
                          f"{int(grid.blocked.sum())} blocked, resolution 1, origin (0.0, 0.0)>")
    r = skyroute.plan(grid, (50, 76), (60, 13))
    text = repr(r)
    assert text.startswith("<PlanResult found, cost 112.556, 109 points, astar: ")
    assert f"{r.expanded} expanded" in text and "array" not in text
    stopped = repr(skyroute.plan(grid, (50, 76), (60, 13), max_expansions=5))
    assert stopped.startswith("<PlanResult budget_exhausted, 0 points") and "cost" not in stopped
    assert repr(skyroute.prepare(grid)).startswith("<PreparedGrid 'den312d.map': subgoal index")


@pytest.mark.parametrize("cells", [[[1, 2, 3], [4, 5, 6]], [1, 2, 3], "ab"])
def test_grid_conversions_refuse_what_is_not_n_by_2(cells):
    # [[1, 2, 3], [4, 5, 6]] came back as three points
    grid = Grid(np.zeros((8, 8), bool))
    for convert in (grid.to_world, grid.to_cell):
        with pytest.raises(skyroute.QueryError):
            convert(cells)


@pytest.mark.parametrize("cell", [(1, 2, 3), "ab", (1.5, 2), None])
def test_grid_cell_tests_refuse_what_is_not_two_integers(cell):
    grid = Grid(np.zeros((8, 8), bool))
    for test in (grid.is_free, grid.in_bounds):
        with pytest.raises(skyroute.QueryError, match="two integers"):
            test(cell)
    assert grid.is_free((np.int64(1), np.int64(2))) and not grid.in_bounds((8, 0))


@pytest.mark.parametrize("make, param", [(Grid, "blocked"), (from_array, "array")])
@pytest.mark.parametrize("bad, words", [
    # text was read by its truth value: "0" and "." are non-empty, so blocked
    (np.array([["0", "1"], ["0", "0"]]), "got dtype <U1: convert text first"),
    ([[".", "@"], [".", "."]], "got dtype <U1: convert text first"),
    (np.array([[b"0", b"1"]]), "got dtype |S1: convert text first"),
    ([[0, None], [0, 0]], "got None"),  # None read as free
    ([[0, "x"], [1, 0]], "got dtype <U21"),
    (np.zeros((2, 2), complex), "got dtype complex128"),
    ([[0, 1], [0]], "its rows of equal length"),  # numpy's own ValueError
])
def test_an_array_of_text_or_ragged_rows_is_refused_naming_it(make, param, bad, words):
    with pytest.raises(OptionError) as err:
        make(bad)
    assert err.value.param == param
    assert str(err.value).startswith(f"{param} must ") and words in str(err.value)


def _holding_an_array():
    a = np.zeros((1, 2), dtype=object)
    a[0, 1] = np.eye(3)
    return a


@pytest.mark.parametrize("make, param", [(Grid, "blocked"), (from_array, "array")])
@pytest.mark.parametrize("bad, words", [
    # numpy reads a sparse matrix as one object: its repr ran over two lines
    (lambda: __import__("scipy.sparse").sparse.csr_matrix(np.eye(3)), "got csr_matrix"),
    (_holding_an_array, "got array([[1., 0., 0.], [0., 1., 0.], [0., 0., 1.]])"),
    (lambda: None, "got None"),
])
def test_an_object_that_is_no_number_is_named_in_one_line(make, param, bad, words):
    with pytest.raises(OptionError) as err:
        make(bad())
    assert err.value.param == param and "\n" not in str(err.value)
    assert str(err.value).startswith(f"{param} must ") and str(err.value).endswith(words)


@pytest.mark.parametrize("values", [
    np.array([[0, 1], [0, 0]], dtype=object),  # numbers as objects: read as numbers
    [[False, np.True_], [0, 0.0]],
    np.asfortranarray([[0, 7], [0, 0]], dtype=np.int8),
    np.array([[0, 0, 1, 0], [0, 0, 0, 0]], np.uint8)[:, ::2],  # a strided view
])
def test_arrays_of_numbers_in_any_type_or_layout_read_alike(values):
    assert Grid(values).blocked.tolist() == [[False, True], [False, False]]


def test_a_grid_or_a_bad_shape_given_as_blocked_is_named():
    g = Grid(np.zeros((2, 2)))
    with pytest.raises(OptionError, match=r"^blocked must be an array, got a Grid") as err:
        Grid(g)  # it read "must be a non-empty 2-D array, got shape ()"
    assert err.value.param == "blocked"
    for bad in (np.zeros(3), np.zeros((0, 2)), None):
        with pytest.raises(OptionError) as err:
            Grid(bad)
        assert err.value.param == "blocked"


def test_a_grids_cells_cannot_be_made_writeable_again():
    """numpy lets an array that owns its memory be made writeable again: with
    ``g.blocked.flags.writeable = True`` a wall drawn into a grid already searched was
    walked through, as the search reused the workspace cached for the old cells."""
    g = Grid(np.zeros((5, 5), dtype=bool))
    assert skyroute.plan(g, (0, 0), (4, 4)).cost == pytest.approx(4 * np.sqrt(2))
    with pytest.raises(ValueError):
        g.blocked.flags.writeable = True
    with pytest.raises(ValueError):
        g.blocked.setflags(write=True)
    assert g.blocked.flags.c_contiguous and not g.blocked.flags.writeable
    for copied in (copy.deepcopy(g), pickle.loads(pickle.dumps(g)), g.inflate(1)):
        with pytest.raises(ValueError):
            copied.blocked.setflags(write=True)
    # the way to change cells: a new Grid from a copy
    b = g.blocked.copy()
    b[:4, 2] = True
    assert skyroute.plan(Grid(b), (0, 0), (4, 4)).cost == pytest.approx(6 + np.sqrt(2))


@pytest.mark.parametrize("start, hint", [
    ((4, 1), "; (1, 4) is free: cells are (x, y) = (column, row)"),  # (row, column)
    ((4, 0), ""),  # (0, 4), swapped, is on the grid but blocked: no hint to a bad cell
    ((4, 4), ""),  # off the grid either way: nothing to suggest
    ((1, 7), ""),
    ((-1, 2), ""),
])
def test_a_cell_off_the_grid_says_when_it_is_free_swapped(start, hint):
    """A cell typed (row, column), numpy's order, lies off a grid that is not square
    where (column, row) is a free cell of it; the error says so, as a lon/lat World says
    it of (lat, lon). A cell off the grid either way, or whose swapped cell is blocked,
    gets no hint (it pointed to a blocked cell)."""
    blocked = np.zeros((6, 3), bool)  # 3 wide, 6 high
    blocked[4, 0] = True  # cell (0, 4)
    with pytest.raises(skyroute.QueryError) as err:
        skyroute.plan(Grid(blocked), start, (1, 1))
    x, y = start
    assert str(err.value) == (f"start ({x}, {y}) lies outside the 3x6 grid (x in 0..2, "
                              f"y in 0..5){hint}")


@pytest.mark.parametrize("goal, hint", [
    ((2, 1), "; (1, 2) is free: cells are (x, y) = (column, row)"),  # (row, column)
    ((3, 0), ""),  # (0, 3), swapped, is blocked too
    ((2, 2), ""),  # the same cell swapped
    ((0, 5), ""),  # (5, 0), swapped, is off the grid
])
def test_a_blocked_cell_says_when_it_is_free_swapped(goal, hint):
    """On a square map a cell typed (row, column) never falls off the grid: a blocked
    cell is where the slip shows, and the error names the swapped cell when it is free."""
    blocked = np.zeros((6, 4), bool)  # 4 wide, 6 high
    blocked[1, 2] = blocked[0, 3] = blocked[3, 0] = blocked[2, 2] = blocked[5, 0] = True
    with pytest.raises(skyroute.QueryError) as err:
        skyroute.plan(Grid(blocked), (1, 1), goal)
    assert str(err.value) == f"goal {goal} is on a blocked cell{hint}"
    assert err.value.param == "goal"
