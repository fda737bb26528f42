"""colliders.csv home lines: a malformed number is an InputFormatError on line 1, and a
byte-order mark (Excel writes one) is read past; a file too large is refused unread."""

import pytest

import skyroute
from skyroute import InputFormatError
from skyroute.world.colliders import read_colliders

HEADER = "posX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ"
HOME = "lat0 37.792480, lon0 -122.397450"
BOXES = "10,0,5,2,3,5\n-20,20,40,5,5,40\n"


@pytest.mark.parametrize("home", ["lat0 37.79.2480, lon0 -122.397450", "lat0 ., lon0 .",
                                  "lat0 37.792480, lon0 -", "lat0 -, lon0 1..2"])
def test_malformed_home_line_names_line_1(tmp_path, home):
    path = tmp_path / "c.csv"
    path.write_text(f"{home}\n{HEADER}\n{BOXES}")
    with pytest.raises(InputFormatError) as err:
        skyroute.load_world(path)
    assert err.value.line == 1
    assert str(err.value) == f"{path}:1: expected 'lat0 <deg>, lon0 <deg>', got {home!r}"


def test_empty_file_names_line_1(tmp_path):
    path = tmp_path / "c.csv"
    path.write_text("")
    with pytest.raises(InputFormatError, match="got an empty file") as err:
        read_colliders(path)
    assert err.value.line == 1


def test_byte_order_mark_is_read_past(tmp_path):
    plain, bom = tmp_path / "plain.csv", tmp_path / "bom.csv"
    plain.write_text(f"{HOME}\n{HEADER}\n{BOXES}")
    bom.write_bytes(b"\xef\xbb\xbf" + plain.read_bytes())
    a, b = skyroute.load_world(plain, frame="enu"), skyroute.load_world(bom, frame="enu")
    assert (b.home.lat, b.home.lon) == (a.home.lat, a.home.lon) == (37.79248, -122.39745)
    assert list(b.obstacles) == list(a.obstacles)
    text = read_colliders("upload.csv", text="\ufeff" + plain.read_text(), frame="enu")
    assert list(text.obstacles) == list(a.obstacles)


# -- size limits: refused before the file is read or its rows parsed ----------------------

def test_a_file_past_the_byte_limit_is_refused_before_it_is_read(tmp_path):
    from skyroute.world import colliders

    path = tmp_path / "huge.csv"
    with path.open("wb") as fh:  # sparse: no 10 MB written
        fh.truncate(colliders.MAX_BYTES + 1)
    with pytest.raises(InputFormatError) as err:
        skyroute.load_world(path)
    assert str(err.value) == (f"{path}: 10,000,001 bytes, over the limit of 10,000,000 for "
                              "a colliders file (at most 50,000 boxes)")


def test_a_file_of_too_many_boxes_is_refused_before_its_rows_are_parsed(tmp_path):
    from skyroute.world import colliders

    text = f"{HOME}\n{HEADER}\n" + "1,1,1,1,1,1\n" * (colliders.MAX_BOXES + 1)
    path = tmp_path / "city.csv"
    path.write_text(text)
    words = "50,001 boxes, over the limit of 50,000 in a colliders file"
    with pytest.raises(InputFormatError) as err:
        read_colliders(path)
    assert str(err.value) == f"{path}: {words}"
    with pytest.raises(InputFormatError, match=f"^upload.csv: {words}$"):  # an upload too
        read_colliders("upload.csv", text=text)
    # at the limit it is read (blank lines are not boxes)
    path.write_text(f"{HOME}\n{HEADER}\n\n" + "1,1,1,1,1,1\n" * colliders.MAX_BOXES)
    assert len(read_colliders(path).obstacles) == colliders.MAX_BOXES


@pytest.mark.parametrize("home", ["lat0 +37.792480, lon0 -122.397450",
                                  "lat0 3.7792480e1, lon0 -1.22397450E2",
                                  "LAT0 37.792480, LON0 -122.397450",
                                  "lat0\t37.792480 ,lon0   -122.397450"])
@pytest.mark.parametrize("header", [HEADER, HEADER.lower(), HEADER.replace(",", ", "),
                                    HEADER.upper()])
def test_odd_but_valid_home_lines_and_headers_read_as_the_plain_file(tmp_path, home, header):
    # a sign, an exponent or capitals in line 1 were "expected 'lat0 <deg>, lon0 <deg>'",
    # and a header in other capitals was refused
    plain, odd = tmp_path / "plain.csv", tmp_path / "odd.csv"
    plain.write_text(f"{HOME}\n{HEADER}\n{BOXES}")
    odd.write_text(f"{home}\n{header}\n{BOXES}")
    a, b = read_colliders(plain, frame="enu"), read_colliders(odd, frame="enu")
    assert (b.home.lat, b.home.lon) == (a.home.lat, a.home.lon)
    assert list(b.obstacles) == list(a.obstacles)


@pytest.mark.parametrize("home", ["lat0 nan, lon0 -122.39", "lat0 inf, lon0 -122.39"])
def test_a_home_that_is_no_place_names_line_1(tmp_path, home):
    path = tmp_path / "c.csv"
    path.write_text(f"{home}\n{HEADER}\n{BOXES}")
    with pytest.raises(InputFormatError, match="is not a place") as err:
        read_colliders(path)
    assert err.value.line == 1


def test_boxes_are_named_by_their_own_line_after_blank_lines(tmp_path):
    # after a blank line every box was named by the line before its own: a start inside
    # the box of line 6 was said to be inside 'box at line 5'
    path = tmp_path / "c.csv"
    path.write_text(f"{HOME}\n{HEADER}\n10,0,5,2,3,5\n\n\n-20,20,40,5,5,40\n")
    city = read_colliders(path, frame="ned")
    assert city.names == ("box at line 3", "box at line 6")
    with pytest.raises(skyroute.QueryError, match="inside obstacle 'box at line 6'"):
        skyroute.plan(city.at(10), (-20, 20), (40, 40))


def test_the_first_fcnd_layout_with_the_home_on_two_lines_reads_as_the_later_one(tmp_path):
    # FCND-Motion-Planning's first colliders.csv (2018; students' forks keep it) has line
    # 1 'lat0,lon0', line 2 the values, the header on line 3: "expected 'lat0 <deg>, lon0
    # <deg>', got 'lat0,lon0'"
    plain, first = tmp_path / "plain.csv", tmp_path / "first.csv"
    plain.write_text(f"{HOME}\n{HEADER}\n{BOXES}")
    first.write_text(f"lat0,lon0\n37.792480,-122.397450\n{HEADER}\n{BOXES}")
    a, b = read_colliders(plain, frame="ned"), read_colliders(first, frame="ned")
    assert (b.home.lat, b.home.lon) == (a.home.lat, a.home.lon) == (37.79248, -122.39745)
    assert list(b.obstacles) == list(a.obstacles)
    assert b.names == ("box at line 4", "box at line 5")


@pytest.mark.parametrize("text, line, words", [
    ("lat0,lon0\n", 2, "expected '<lat0>,<lon0>' under line 1's 'lat0,lon0', got the end"),
    ("lat0,lon0\n37.79;-122.39\n", 2, "got '37.79;-122.39'"),
    ("lat0,lon0\n97.79,-122.39\n", 2, "home lat0 97.79, lon0 -122.39 is not a place"),
    (f"lat0,lon0\n37.79,-122.39\n{BOXES}", 3, "expected the header"),
    (f"lat0,lon0\n37.79,-122.39\n{HEADER}\n", 4, "no boxes after the header"),
    (f"lat0,lon0\n37.79,-122.39\n{HEADER}\n1,1,1,1,1,1\n1,1,1\n", 5, "expected 6 numbers"),
])
def test_the_first_fcnd_layout_names_its_own_lines(tmp_path, text, line, words):
    path = tmp_path / "c.csv"
    path.write_text(text)
    with pytest.raises(InputFormatError) as err:
        read_colliders(path)
    assert err.value.line == line and words in str(err.value)


# -- how far from home a box may reach ----------------------------------------------------

@pytest.mark.parametrize("row, km", [
    ("4182912.5,553400.2,5,2,3,5", "4,219.4"),  # UTM northing, easting: not from home
    ("49995,0,5,6,3,5", "50.0"),  # 50,001 m north: just past
    ("-30000,-40000,5,1,1,5", "50.0"),  # 50,001.4 m as the crow flies (a corner)
])
def test_a_box_far_from_home_is_refused_naming_its_line(tmp_path, row, km):
    """Past MAX_CITY_REACH the tangent plane at home is over a metre off: a box there was
    read and planned round silently (UTM coordinates for metres from home, 4,219 km
    away, gave a path 'found' around a box on another continent)."""
    for home, line in ((HOME, 4), ("lat0,lon0\n37.792480,-122.397450", 5)):
        path = tmp_path / "far.csv"
        path.write_text(f"{home}\n{HEADER}\n10,0,5,2,3,5\n{row}\n")
        with pytest.raises(InputFormatError) as err:
            skyroute.load_world(path)
        assert str(err.value) == (
            f"{path}:{line}: the box reaches {km} km from home, over the 50 km limit: "
            "posX, posY are metres north and east of lat0, lon0, not UTM or another origin "
            "(beyond 50 km the tangent plane at home is over a metre off)")


def test_a_box_within_the_reach_is_read(tmp_path):
    from skyroute.world.colliders import MAX_CITY_REACH

    path = tmp_path / "wide.csv"
    path.write_text(f"{HOME}\n{HEADER}\n29998,-39998,5,1,1,5\n0,49990,5,2,9.9,5\n")
    world = skyroute.load_world(path, frame="ned")
    # 49,999.0 and 49,999.9 m from home at their farthest corners
    assert world.bounds == pytest.approx((-39999, -2, 49999.9, 29999))
    assert MAX_CITY_REACH == 50_000


def test_the_reach_holds_the_plane_to_a_metre_of_its_lon_lat():
    """The limit's reason, measured: a plane point 50 km from home, to (lon, lat) and back,
    lands within 1.6 m of itself (and its ground distance within 1.1 m of its plane
    distance); at 100 km both are over 8 m, more than FCND's 5 m margin."""
    import numpy as np
    from pyproj import Geod

    from skyroute.geo import Home, enu_to_lonlat, lonlat_to_enu

    home = Home(-122.39745, 37.79248, 0.0)
    for d, most in ((50e3, 1.6), (100e3, None)):
        lonlat = enu_to_lonlat([d], [0.0], 0.0, home)
        back = lonlat_to_enu(lonlat[:, 0], lonlat[:, 1], 0.0, home)[0]
        off = float(np.hypot(back[0] - d, back[1]))
        ground = Geod(ellps="WGS84").inv(home.lon, home.lat, *lonlat[0, :2])[2]
        if most is None:
            assert off > 8 and d - ground > 8
        else:
            assert off < most and d - ground < 1.1
