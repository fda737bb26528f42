"""A start or goal of a lon/lat world with no boundary is held to the reach a GeoJSON
world's zones and a boundary box are (``MAX_REACH`` from home): one typed (lat, lon) by
mistake was planned through, thousands of km long, and reported "found"."""

import json

import numpy as np
import pytest

import skyroute
from skyroute import QueryError
from skyroute.geo import lonlat_to_enu
from skyroute.world.geojson_world import MAX_REACH
from tests.cli.test_cli import run
from tests.conftest import ROOT

CITY = ROOT / "examples" / "city.csv"
A, B = (-3.1890, 55.9456), (-3.1850, 55.9432)  # two streets of the city, (lon, lat)
MADRID = (-3.7038, 40.4168)  # 1,700 km away; swapped, on the equator


METRES_HINT = "; points are (lon, lat) here: (north, east) metres from home are the 'ned' frame"


def _zones(tmp_path):
    ring = [[-3.19, 55.943], [-3.188, 55.943], [-3.188, 55.945], [-3.19, 55.945],
            [-3.19, 55.943]]
    path = tmp_path / "z.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {"name": "zone"},
         "geometry": {"type": "Polygon", "coordinates": [ring]}}]}))
    return path


def _km(world, point):
    """The distance the error should name, worked out here from the home."""
    return np.linalg.norm(lonlat_to_enu([point[0]], [point[1]], 0.0, world.home)) / 1000


def _worlds(tmp_path):
    yield skyroute.load_world(CITY, altitude=10)
    yield skyroute.load_world(CITY, altitude=10).in_frame("degrees")  # as fly's step drone
    yield skyroute.load_world(_zones(tmp_path))
    yield skyroute.load_world(_zones(tmp_path), frame="degrees")


@pytest.mark.parametrize("which", ["start", "goal"])
def test_a_point_typed_lat_lon_is_refused_with_the_hint(tmp_path, which):
    swapped = A[::-1]
    for world in _worlds(tmp_path):
        assert world.boundary is None and world.frame in ("lonlat", "degrees")
        start, goal = (swapped, B) if which == "start" else (B, swapped)
        with pytest.raises(QueryError) as err:
            skyroute.plan(world, start, goal)
        home = world.home
        assert str(err.value) == (
            f"{which} (55.9456000, -3.1890000) lies {_km(world, swapped):,.0f} km from the "
            f"world's home (lon {home.lon:g}, lat {home.lat:g}), more than the 1,000 km a "
            "world with no boundary reaches; (-3.1890000, 55.9456000) is within it: points "
            "are (lon, lat)"), world


@pytest.mark.parametrize("point", [MADRID, MADRID[::-1]])
def test_a_point_plainly_far_is_refused_without_the_hint(tmp_path, point):
    for world in _worlds(tmp_path):
        with pytest.raises(QueryError) as err:
            skyroute.plan(world, point, B)
        text = str(err.value)
        assert text.startswith(f"start {world._fmt_frame(point)} lies "
                               f"{_km(world, point):,.0f} km from the world's home")
        # no swapped hint; in the lonlat frame the note on metres (true of any point)
        metres = METRES_HINT if world.frame == "lonlat" else ""
        assert text.endswith("km a world with no boundary reaches" + metres), text


def test_a_point_just_inside_the_reach_is_still_planned(tmp_path):
    world = skyroute.load_world(CITY, altitude=10)
    home = world.home
    near, past = (home.lon, home.lat - 8.9), (home.lon, home.lat - 9.1)
    assert 0.98 * MAX_REACH < _km(world, near) * 1000 <= MAX_REACH < _km(world, past) * 1000
    for w in (world, world.in_frame("degrees")):
        r = skyroute.plan(w, near, A)
        assert r.found and r.path[0].tolist() == list(near)
        with pytest.raises(QueryError, match=r"^goal \(.*\) lies 1,011 km from"):
            skyroute.plan(w, A, past)


def test_hybrid_astar_shows_the_point_as_typed():
    # it checks plane points; the typed one is shown, not one back from the plane
    from skyroute.motion import hybrid

    world = skyroute.load_world(CITY, altitude=10)
    for which, (lon, lat) in (("start", A), ("goal", B)):
        start, goal = ((lat, lon, 0.0), (*B, 0.0)) if which == "start" else \
            ((*A, 0.0), (lat, lon, 0.0))
        with pytest.raises(QueryError) as err:
            hybrid.plan(world, start, goal, radius=10)
        assert str(err.value).startswith(f"{which} ({lat:.7f}, {lon:.7f}) lies "), err.value
        assert str(err.value).endswith("is within it: points are (lon, lat)")


@pytest.mark.parametrize("frame", ["ned", "enu"])
def test_metres_frames_keep_their_own_limit(frame):
    # their points are metres: 2,000 km from home is far, but still a point of the plane
    world = skyroute.load_world(CITY, altitude=10, frame=frame)
    r = skyroute.plan(world, (2e6, 0.0), (0.0, 0.0))
    assert r.found and r.cost == pytest.approx(2e6, rel=1e-6)


def test_a_world_with_a_boundary_still_says_outside_the_map():
    world = skyroute.load_world(CITY, altitude=10, boundary="-3.2,55.93,-3.17,55.96")
    with pytest.raises(QueryError, match=r"^start \(55.9456000, -3.1890000\) lies outside "
                                         r"the map .*is inside: points are \(lon, lat\)$"):
        skyroute.plan(world, A[::-1], B)


@pytest.mark.parametrize("command", [
    ["plan-world", "--geojson"], ["fly", "--vehicle", "step", "--out"],
    ["fly", "--vehicle", "dubins", "--out"]])
def test_cli_refuses_it_in_one_line_exit_2_writing_nothing(monkeypatch, capsys, tmp_path,
                                                         command):
    out = tmp_path / "p.geojson"
    code, text, err = run(monkeypatch, capsys, command[0], str(CITY), *command[1:], str(out),
                          "--altitude", "10", "--start=55.9456,-3.1890",
                          "--goal=-3.1850,55.9432")
    assert code == 2 and text == "" and err.count("\n") == 1 and not out.exists(), err
    assert err.startswith("skyroute: error: start (55.9456000, -3.1890000) lies ")
    assert err.endswith("is within it: points are (lon, lat)\n")


def test_a_point_typed_in_metres_is_refused_naming_the_ned_frame(monkeypatch, capsys):
    # FCND writes points (north, east) metres from home: --start 0,0 (home) in the
    # default lonlat frame was refused as 5,965 km away, naming no way on
    code, text, err = run(monkeypatch, capsys, "plan-world", str(CITY), "--altitude", "10",
                          "--start", "0,0", "--goal", "120,-180")
    assert code == 2 and text == ""
    assert err == ("skyroute: error: start (0.0000000, 0.0000000) lies 5,965 km from the "
                   "world's home (lon -3.18687, lat 55.9445), more than the 1,000 km a world "
                   f"with no boundary reaches{METRES_HINT}\n")
    code, text, err = run(monkeypatch, capsys, "plan-world", str(CITY), "--altitude", "10",
                          "--start", "0,0", "--goal", "120,-180", "--frame", "ned")
    assert code == 0, err


def test_a_point_in_metres_outside_a_boundary_names_the_ned_frame():
    world = skyroute.load_world(CITY, altitude=10, boundary="-3.2,55.93,-3.17,55.96")
    with pytest.raises(QueryError, match=r"^start \(20.0000000, 80.0000000\) lies outside "
                                         r"the map .*'ned' frame$"):
        skyroute.plan(world, (20, 80), B)


# -- at the FCND city's latitude the same slips are no place at all -------------------

SF = "lat0 37.792480, lon0 -122.397450\nposX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n" \
     "50,50,10,5,5,10\n-50,-50,10,5,5,10\n"
SF_HOME, SF_GOAL = (-122.397450, 37.792480), (-122.396428, 37.795232)
NOT_A_PLACE = ("is not a place: expected (lon, lat) degrees, lon in [-180, 180], lat in "
               "[-90, 90]")


@pytest.mark.parametrize("boundary, swapped", [
    (None, "is one, within the 1,000 km a world with no boundary reaches"),
    ("-122.41,37.78,-122.38,37.80", "is one, inside the map")])
def test_a_point_that_is_no_place_says_what_it_likely_was(tmp_path, boundary, swapped):
    # (lat, lon) from the colliders' "lat0, lon0" line, or FCND's (north, east) metres:
    # at 37.8 N both are no place (lat -122.4, lat -180), and the error gave no hint
    city = tmp_path / "sf.csv"
    city.write_text(SF)
    world = skyroute.load_world(city, altitude=5, safety=5, boundary=boundary)
    with pytest.raises(QueryError) as err:
        skyroute.plan(world, SF_HOME, SF_GOAL[::-1])
    assert str(err.value) == (f"goal (37.79523, -122.3964) {NOT_A_PLACE}; (-122.3964280, "
                              f"37.7952320) {swapped}: points are (lon, lat)")
    with pytest.raises(QueryError) as err:
        skyroute.plan(world, (120, -180), SF_GOAL)
    assert str(err.value) == f"start (120, -180) {NOT_A_PLACE}{METRES_HINT}"
    with pytest.raises(QueryError) as err:  # plainly nothing near: no hint
        skyroute.plan(world, SF_HOME, (5e7, 5e7))
    assert str(err.value) == f"goal (5e+07, 5e+07) {NOT_A_PLACE}"


def test_cli_with_a_safety_margin_keeps_the_hint(monkeypatch, capsys, tmp_path):
    # with --safety, the CLI converted a refused point again to see whether only the
    # margin blocked it: "not a place" came back from that, without the hint
    city = tmp_path / "sf.csv"
    city.write_text(SF)
    code, text, err = run(monkeypatch, capsys, "plan-world", str(city), "--altitude", "5",
                          "--safety", "5", "--start=-122.397450,37.792480",
                          "--goal=37.795232,-122.396428")
    assert code == 2 and text == "" and err.count("\n") == 1
    assert err.endswith("; (-122.3964280, 37.7952320) is one, within the 1,000 km a world "
                        "with no boundary reaches: points are (lon, lat)\n"), err
