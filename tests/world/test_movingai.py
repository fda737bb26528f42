from pathlib import Path

import numpy as np
import pytest

from skyroute import InputFormatError, load_map
from skyroute.world.movingai import read_map, read_scen
from tests.conftest import MOVINGAI, movingai_pairs

SMALL = "type octile\nheight 3\nwidth 4\nmap\n.@..\nGTS.\n..OW\n"


def write(tmp_path: Path, text: str | bytes, name: str = "m.map") -> Path:
    p = tmp_path / name
    p.write_bytes(text.encode() if isinstance(text, str) else text)
    return p


def test_terrain_characters_and_cell_order(tmp_path):
    g = read_map(write(tmp_path, SMALL))
    assert (g.width, g.height) == (4, 3)
    expected = np.array([[0, 1, 0, 0], [0, 1, 0, 0], [0, 0, 1, 1]], dtype=bool)
    np.testing.assert_array_equal(g.blocked, expected)
    assert g.is_free((0, 0)) and not g.is_free((1, 0))  # (x, y) = (column, row)
    assert not g.is_free((3, 2))  # water is blocked


@pytest.mark.parametrize("variant", ["crlf", "no-final-newline", "crlf-no-final", "bom",
                                     "bom-crlf", "blank-end", "spaces-end", "tab-in-type"])
def test_line_endings(tmp_path, variant):
    text = SMALL
    if "crlf" in variant:
        text = text.replace("\n", "\r\n")
    if "final" in variant:
        text = text.rstrip("\r\n")
    if variant.startswith("bom"):  # Notepad's "UTF-8 with BOM"
        text = "\ufeff" + text
    text += {"blank-end": "\n\n", "spaces-end": "  \n\t\n"}.get(variant, "")
    if variant == "tab-in-type":  # as 'height\t3' always was
        text = text.replace("type octile", "type\toctile ")
    g = read_map(write(tmp_path, text))
    np.testing.assert_array_equal(g.blocked, read_map(write(tmp_path, SMALL, "b.map")).blocked)


@pytest.mark.parametrize("text, line, words", [
    ("type foo\nheight 1\nwidth 1\nmap\n.\n", 1, "type octile"),
    ("type octile\nheight x\nwidth 1\nmap\n.\n", 2, "integer"),
    ("type octile\nheight 1\nwidt 1\nmap\n.\n", 3, "width"),
    ("type octile\nheight 1\nwidth 1\nmop\n.\n", 4, "'map'"),
    ("type octile\nheight 2\nwidth 2\nmap\n..\n.\n", 6, "width 2"),
    ("type octile\nheight 2\nwidth 2\nmap\n..\n", 5, "height 2 but 1"),
    ("type octile\nheight 1\nwidth 2\nmap\n..\n..\n", 6, "height 1 but 2"),
    ("type octile\nheight 1\nwidth 3\nmap\n.x.\n", 5, "unknown terrain 'x' at column 1"),
    ("", 1, "empty"),
])
def test_malformed_maps_name_the_line(tmp_path, text, line, words):
    p = write(tmp_path, text)
    with pytest.raises(InputFormatError) as err:
        read_map(p)
    assert err.value.line == line
    assert str(err.value).startswith(f"{p}:{line}: ")
    assert words in str(err.value)


def test_a_byte_order_mark_is_read_past_in_a_scen_too(tmp_path):
    plain = read_scen(write(tmp_path, SCEN, "m.map.scen"))
    bom = read_scen(write(tmp_path, "\ufeff" + SCEN.replace("\n", "\r\n"), "b.map.scen"))
    np.testing.assert_array_equal(bom.starts, plain.starts)
    assert bom.map_name == "m.map"


def test_binary_file_is_a_format_error(tmp_path):
    with pytest.raises(InputFormatError, match="ASCII"):
        read_map(write(tmp_path, b"type octile\n\xff\xfe"))


SCEN = "version 1\n0\tm.map\t4\t3\t0\t0\t3\t0\t3.00000000\n1\tm.map\t4\t3\t0\t2\t2\t1\t2.41421\n"


def test_scen_columns_and_tolerance(tmp_path):
    sc = read_scen(write(tmp_path, SCEN, "m.map.scen"))
    assert len(sc) == 2 and sc.map_name == "m.map" and (sc.width, sc.height) == (4, 3)
    np.testing.assert_array_equal(sc.starts, [[0, 0], [0, 2]])
    np.testing.assert_array_equal(sc.goals, [[3, 0], [2, 1]])
    assert sc.matches(0, 3.0) and not sc.matches(0, 3.0001)
    assert sc.matches(1, 1 + 2 ** 0.5)  # 5 printed decimals: rounding allowed
    assert not sc.matches(1, 2.4143)


@pytest.mark.parametrize("text, line, words", [
    ("version 2\n", 1, "version 1"),
    ("version 1\n0\tm.map\t4\t3\t0\t0\t3\t0\n", 2, "9 tab-separated"),
    ("version 1\n0 m.map 4 3 0 0 3 0 3.0\n", 2,
     "9 tab-separated columns, got 1 (its columns are separated by spaces)"),
    ("version 1\n0 m.map 4 3 0 0 3 0\n", 2, "9 tab-separated columns, got 1"),
    ("version 1\n0\tm.map\t4\t3\ta\t0\t3\t0\t3.0\n", 2, "integers"),
    ("version 1\n0\tm.map\t4\t3\t0\t0\t4\t0\t3.0\n", 2, "outside"),
    ("version 1\n0\tm.map\t4\t3\t0\t0\t3\t0\t3.0\n0\tm.map\t5\t3\t0\t0\t3\t0\t3.0\n", 3,
     "differs"),
    ("version 1\n", 2, "no scenario lines"),
])
def test_malformed_scen_name_the_line(tmp_path, text, line, words):
    p = write(tmp_path, text, "bad.scen")
    with pytest.raises(InputFormatError) as err:
        read_scen(p)
    assert err.value.line == line and words in str(err.value)


@pytest.mark.shared_data
def test_every_shared_map_and_scen_parses():
    pairs = movingai_pairs()
    assert len(pairs) == 18
    for map_path, scen_path in pairs:
        g, sc = read_map(map_path), read_scen(scen_path)
        assert (sc.width, sc.height) == (g.width, g.height), map_path.name
        assert not g.blocked[sc.starts[:, 1], sc.starts[:, 0]].any()
        assert not g.blocked[sc.goals[:, 1], sc.goals[:, 0]].any()


@pytest.mark.shared_data
def test_bundled_maps_are_the_reference_bytes():
    from skyroute import bundled_maps

    maps = bundled_maps()
    assert set(maps) >= {"den312d", "Berlin_1_256", "Paris_1_512"}
    for path in maps.values():
        assert path.read_bytes() == (MOVINGAI / path.name).read_bytes()
    assert load_map("den312d").blocked.shape == (81, 65)


def test_a_tab_or_space_after_the_last_scen_column_is_no_column(tmp_path):
    # "expected 9 tab-separated columns, got 10 (its columns are separated by spaces)":
    # a trailing tab was a tenth column, and the hint blamed spaces there were none of
    plain = read_scen(write(tmp_path, SCEN, "m.map.scen"))
    for end in ("\t", " ", "\t\t"):
        sc = read_scen(write(tmp_path, SCEN.replace("\n0", f"{end}\n0").replace(
            "2.41421\n", f"2.41421{end}\n"), "t.map.scen"))
        np.testing.assert_array_equal(sc.starts, plain.starts)
        np.testing.assert_array_equal(sc.optimal, plain.optimal)
        np.testing.assert_array_equal(sc.tolerance, plain.tolerance)


def test_every_scen_line_must_name_the_same_map(tmp_path):
    # only the first line's map column was checked against the map: a line for another
    # map of the same size ran on this one
    p = write(tmp_path, SCEN.replace("1\tm.map", "1\tother.map"), "m.map.scen")
    with pytest.raises(InputFormatError) as err:
        read_scen(p)
    assert err.value.line == 3 and "map 'other.map' differs from the first line's 'm.map'" \
        in str(err.value)


@pytest.mark.parametrize("version", ["", "version 0\n", "version 0.0\r\n"])
def test_a_version_0_scen_reads_as_hog2_reads_it(tmp_path, version):
    # HOG2's loader reads a file with no version line (or 'version 0') as 7 columns, no
    # map size: "expected 'version 1', got '0\tm.map\t0\t0\t3\t0\t3.00000000'"
    v0 = "0\tm.map\t0\t0\t3\t0\t3.00000000\n1\tm.map\t0\t2\t2\t1\t2.41421\n"
    sc = read_scen(write(tmp_path, version + v0, "m.map.scen"))
    v1 = read_scen(write(tmp_path, SCEN, "v1.map.scen"))
    assert (sc.width, sc.height, sc.map_name) == (None, None, "m.map")
    for name in ("starts", "goals", "optimal", "tolerance", "buckets"):
        np.testing.assert_array_equal(getattr(sc, name), getattr(v1, name))


def test_a_version_0_scen_is_checked_against_its_map(tmp_path):
    from skyroute.bench.grid import load_case

    m = write(tmp_path, "type octile\nheight 3\nwidth 4\nmap\n....\n.@..\n....\n", "m.map")
    s = write(tmp_path, "0\tm.map\t0\t0\t3\t0\t3\n\n0\tm.map\t0\t0\t4\t0\t4\n", "m.map.scen")
    with pytest.raises(InputFormatError) as err:
        load_case(m, s, per_map=0)
    assert str(err.value) == f"{s}:3: goal (4, 0) lies outside m.map (4x3)"


def test_nine_columns_with_no_version_line_say_what_is_missing(tmp_path):
    p = write(tmp_path, SCEN.partition("\n")[2], "m.map.scen")
    with pytest.raises(InputFormatError) as err:
        read_scen(p)
    assert err.value.line == 1 and str(err.value).endswith(
        "expected 7 tab-separated columns, got 9 (a file of 9 columns starts with the line "
        "'version 1')")
