"""Map files whose header claims a grid above MAX_CELLS (a .map's width and height, a
.npy header's shape, an image's size): refused naming the file before the grid is
allocated. A small file could claim 3 x 10**12 cells and end in numpy's MemoryError (a
traceback) or Pillow's DecompressionBombError."""

import struct
import tracemalloc
import zlib

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from skyroute import InputFormatError, load_map
from skyroute.world import movingai
from skyroute.world.grid import MAX_CELLS
from tests.cli.test_cli import run

ROWS = "....\n.@@.\n....\n"


def peak_bytes(fn):
    """(what ``fn()`` raised, the peak bytes traced while it ran)."""
    tracemalloc.start()
    try:
        with pytest.raises(InputFormatError) as err:
            fn()
        return err.value, tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


@settings(max_examples=40, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(height=st.integers(1, 10**7), width=st.integers(1, 10**13))
def test_a_map_header_over_the_cell_limit_is_refused_on_its_width_line(tmp_path, height,
                                                                      width):
    path = tmp_path / "big.map"
    path.write_text(f"type octile\nheight {height}\nwidth {width}\nmap\n{ROWS}")
    if height * width <= MAX_CELLS:  # the rows then disagree with the header, as before
        with pytest.raises(InputFormatError) as err:
            load_map(path)
        assert err.value.line > 3
        return
    err, peak = peak_bytes(lambda: load_map(path))
    assert err.line == 3 and "over the limit of 67,108,864" in str(err)
    assert str(err).startswith(f"{path}:3: the header's map is {width:,} x {height:,} cells")
    assert peak < 16 << 20  # nothing of the claimed size (>= 64 MiB) allocated


def test_a_map_file_past_the_byte_limit_is_refused_before_it_is_read(tmp_path):
    path = tmp_path / "huge.map"
    with path.open("wb") as fh:  # sparse: nothing written
        fh.truncate(movingai.MAX_BYTES + 1)
    with pytest.raises(InputFormatError, match=r"bytes, over the limit of .* for a map file"):
        load_map(path)


def test_an_uploaded_map_text_is_checked_the_same(tmp_path):
    text = "type octile\nheight 3\nwidth 1000000000000\nmap\n" + ROWS
    err, peak = peak_bytes(lambda: movingai.read_map("upload.map", text=text))
    assert str(err).startswith("upload.map:3: the header's map is 1,000,000,000,000 x 3")
    assert peak < 16 << 20


def npy_claiming(path, shape):
    """A .npy file whose header claims ``shape`` of bools, with 100 bytes of data."""
    header = f"{{'descr': '|b1', 'fortran_order': False, 'shape': {shape}, }}"
    header = header.ljust(117) + "\n"
    path.write_bytes(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) +
                     header.encode() + bytes(100))
    return path


@pytest.mark.parametrize("shape, words", [
    ((10**6, 10**6), "the array is 1,000,000 x 1,000,000 cells (1,000,000,000,000)"),
    ((20000, 20000), "the array is 20,000 x 20,000 cells"),
    ((10**9,), "expected a non-empty 2-D array, got shape (1000000000,)"),
])
def test_a_npy_header_over_the_cell_limit_is_refused_before_it_is_loaded(tmp_path, shape,
                                                                        words):
    path = npy_claiming(tmp_path / "big.npy", shape)
    err, peak = peak_bytes(lambda: load_map(path))
    assert str(err).startswith(f"{path}: {words}")
    assert peak < 16 << 20


def png_claiming(path, width, height):
    """A PNG whose header says ``width`` x ``height`` grey pixels, with no pixel data."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + \
            struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) +
                     chunk(b"IDAT", zlib.compress(b"")) + chunk(b"IEND", b""))
    return path


@pytest.mark.parametrize("width, height, words", [
    (10000, 10000, "the image is 10,000 x 10,000 cells (100,000,000), over the limit"),
    # past twice Pillow's own limit: its DecompressionBombError, one line too
    (100000, 100000, "Image size (10000000000 pixels) exceeds limit"),
])
def test_an_image_over_the_cell_limit_is_refused_before_it_is_decoded(tmp_path, width,
                                                                     height, words):
    path = png_claiming(tmp_path / "big.png", width, height)
    err, peak = peak_bytes(lambda: load_map(path))
    assert str(err).startswith(f"{path}: {words}")
    assert peak < 16 << 20


def test_maps_within_the_limit_still_load(tmp_path):
    from PIL import Image

    np.save(tmp_path / "m.npy", np.eye(3))
    Image.fromarray(np.full((2, 5), 255, np.uint8)).save(tmp_path / "m.png")
    (tmp_path / "m.map").write_text(f"type octile\nheight 3\nwidth 4\nmap\n{ROWS}")
    assert load_map(tmp_path / "m.npy").blocked.shape == (3, 3)
    assert load_map(tmp_path / "m.png").blocked.shape == (2, 5)
    assert load_map(tmp_path / "m.map").blocked.shape == (3, 4)


@pytest.mark.parametrize("make", ["map", "npy", "png"])
def test_plan_on_an_oversized_map_is_one_line_exit_2(monkeypatch, capsys, tmp_path, make):
    path = {"map": lambda p: (p.write_text("type octile\nheight 3\nwidth 10000000000\nmap\n"
                                           + ROWS), p)[1],
            "npy": lambda p: npy_claiming(p, (10**5, 10**5)),
            "png": lambda p: png_claiming(p, 100000, 100000)}[make](tmp_path / f"big.{make}")
    code, out, err = run(monkeypatch, capsys, "plan", str(path), "--start", "0,0",
                         "--goal", "1,1")
    assert code == 2 and out == ""
    assert err.startswith(f"skyroute: error: {path}") and err.count("\n") == 1, err
