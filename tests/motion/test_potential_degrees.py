"""The potential field on a world in the "degrees" frame. Its distances are plane units
there, degrees, as every distance of a World; its defaults, documented in metres, are
taken into degrees (World.metres_in_plane). Before, the defaults (step and tolerance
0.5) were half a degree, 55 km, and every goal of a city was "reached" at once, in 0
moves."""

import json
import math

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from pyproj import Geod

from skyroute import World, load_world
from skyroute.geo import Home, enu_to_lonlat, metres_per_degree_north
from skyroute.motion.potential import DEFAULTS, course, run_field

GEOD = Geod(ellps="WGS84")
LON0, LAT0 = -3.188, 55.944  # Edinburgh, George Square
K = 0.5  # the layout's size: START to GOAL about 250 m


def _at(*offsets):
    """(lon, lat, ...) at LON0, LAT0 plus K times the offsets (degrees)."""
    return tuple((LON0, LAT0)[i % 2] + K * d for i, d in enumerate(offsets))


START, GOAL = _at(-0.0032, 0.0012), _at(0.0030, -0.0015)
BOX = shapely.box(*_at(-0.004, -0.0025, 0.004, 0.0025))


def _zones():
    """No-fly zones in lon/lat: two blocks and a C opening towards the start (a trap the
    plain field stalls in), between START and GOAL."""
    c = _at(-0.0004, -0.0010, 0.0006, 0.0010)
    slot = _at(-0.0005, -0.0007, 0.0004, 0.0007)
    return [shapely.box(*c).difference(shapely.box(*slot)),
            shapely.box(*_at(-0.0025, 0.0003, -0.0016, 0.0008)),
            shapely.box(*_at(0.0014, -0.0008, 0.0020, -0.0002))]


@pytest.fixture
def zones_file(tmp_path):
    feats = [{"type": "Feature", "properties": {"name": f"zone {i}"},
              "geometry": shapely.geometry.mapping(z)} for i, z in enumerate(_zones())]
    feats.append({"type": "Feature", "properties": {"name": "area", "boundary": True},
                  "geometry": shapely.geometry.mapping(BOX)})
    path = tmp_path / "zones.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": feats}))
    return path


def _flown(run) -> np.ndarray:
    return run.path if run.trace is None else run.trace


def _metres(lonlat: np.ndarray) -> float:
    """The geodesic length of a lon/lat polyline (pyproj alone)."""
    return float(GEOD.line_length(lonlat[:, 0], lonlat[:, 1]))


def _outside_the_zones(lonlat: np.ndarray) -> None:
    """The polyline enters no zone's interior and stays inside the area: shapely on
    the lon/lat path against the zones as written, not through the world."""
    line = shapely.LineString(lonlat)
    for zone in _zones():
        assert not zone.relate_pattern(line, "T********"), zone  # interiors never meet
    assert BOX.contains(line)


@pytest.mark.parametrize("mode", ["step", "arc"])
def test_the_default_run_on_a_degrees_world_reaches_the_goal_outside_the_zones(zones_file,
                                                                              mode):
    """Default options on a GeoJSON world loaded in "degrees": the goal is reached
    (within the default tolerance, 0.5 m north and less east: at most 0.5 m on the
    ellipsoid) in moves of about half a metre, by a path that enters no zone."""
    world = load_world(zones_file, frame="degrees")
    run = run_field(world, START, GOAL, mode=mode)
    lonlat = _flown(run)
    assert run.reached, run
    assert tuple(lonlat[0]) == START
    assert GEOD.inv(*lonlat[-1], *GOAL)[2] < 0.5
    _outside_the_zones(lonlat)
    straight = GEOD.inv(*START, *GOAL)[2]
    assert straight < _metres(lonlat) < 2 * straight
    assert run.moves > straight / 0.5  # moves of at most the default 0.5 m
    assert run.distance == pytest.approx(shapely.LineString(lonlat).length)  # degrees


@pytest.mark.parametrize("mode", ["step", "arc"])
def test_the_default_run_in_degrees_is_about_as_long_as_in_lonlat(zones_file, mode):
    """The same GeoJSON world loaded in "degrees" and in "lonlat" (metres round its
    home), default options: both reach the goal, and their lengths on the ellipsoid
    agree within 10 % (measured: 7.5 % in step mode, 5 % in arc mode). Not closer: in
    degrees the robot is isotropic on the lon/lat plane, so its step, sensor range and
    tolerance east are cos(56 deg) = 0.56 of those north, where in lonlat they are
    the same metres every way."""
    runs = [run_field(load_world(zones_file, frame=frame), START, GOAL, mode=mode)
            for frame in ("degrees", "lonlat")]
    assert all(r.reached for r in runs), runs
    deg, ll = (_metres(_flown(r)) for r in runs)
    assert deg == pytest.approx(ll, rel=0.1)


def test_explicit_distances_are_plane_units_degrees():
    """step=1e-5 on a "degrees" world is 1e-5 degrees a move, measured in the plane
    (east as well as north), not 1e-5 metres; the tolerance left out is its default
    0.5 m in degrees (4.5e-6), not half a degree (before: "reached" at the start, 0
    moves). A free world, so every move is a full step along the field, but the last,
    which lands on the goal from within a step of it."""
    world = World([], [], [], (), BOX, "degrees", Home(LON0, LAT0))
    run = run_field(world, START, GOAL, step=1e-5, escape=False)
    assert run.reached, run
    moves = np.hypot(*np.diff(run.path, axis=0).T)
    np.testing.assert_allclose(moves[:-1], 1e-5, rtol=1e-9)
    assert tuple(run.path[-1]) == GOAL and moves[-1] < 2e-5
    straight = math.dist(START, GOAL)  # a straight line in degrees
    assert run.moves == math.floor(straight / 1e-5)
    assert run.distance == pytest.approx(straight)


def test_the_defaults_are_their_metres_over_the_metres_per_degree_of_latitude():
    """World.metres_in_plane: the identity in the metres frames; in "degrees", metres
    over the metres per degree of latitude at the home (111,341 m at 55.944 N, by
    pyproj's geodesic along the meridian)."""
    deg = World([], [], [], (), BOX, "degrees", Home(LON0, LAT0))
    per = GEOD.inv(LON0, LAT0 - 0.05, LON0, LAT0 + 0.05)[2] / 0.1
    assert metres_per_degree_north(LAT0) == pytest.approx(per, rel=1e-6)
    assert deg.metres_in_plane(0.5) == pytest.approx(0.5 / per, rel=1e-6)
    assert World([], [], [], (), None, "degrees").metres_in_plane(2.0, near=(0, 90)) == \
        pytest.approx(2.0 / 111_694.0, rel=1e-5)  # defined at a pole too
    assert deg.in_frame("lonlat").metres_in_plane(0.5) == 0.5
    assert DEFAULTS["step"] == 0.5 and DEFAULTS["tolerance"] == 0.5


def _degrees_course(name: str, lon: float, lat: float):
    """A built-in course (enu metres) placed at (lon, lat) and carried to "degrees"
    vertex by vertex through the tangent plane (World.in_frame), with its start and
    goal in lon/lat."""
    world, start, goal = course(name)
    centre = np.array([30.0, 30.0])
    move = lambda p: p - centre  # noqa: E731 -- home at the course's centre
    enu = World(shapely.transform(world.obstacles, move), world.floors, world.ceilings,
                world.names, shapely.transform(world.boundary, move), "enu",
                Home(lon, lat))
    s, t = enu_to_lonlat(*np.array([start, goal]).T - centre[:, None], 0.0, enu.home)[:, :2]
    return enu.in_frame("degrees"), s, t


@settings(max_examples=6, deadline=None)
@given(lat=st.floats(-70, 70), lon=st.floats(-179, 179), mode=st.sampled_from(["step", "arc"]),
       name=st.sampled_from(["medium", "hard"]))
def test_a_course_anywhere_on_earth_flies_with_the_defaults_in_degrees(lat, lon, mode, name):
    """A course (47 m start to goal) carried to any latitude in "degrees": the default
    run reaches the goal (within 0.5 m on the ellipsoid) along a free path at least as
    long as the straight line, in moves no longer than 0.5 m."""
    deg, s, t = _degrees_course(name, lon, lat)
    run = run_field(deg, s, t, mode=mode)
    assert run.reached, run
    path = _flown(run)
    assert deg.segments_free(path[:-1], path[1:]).all()
    assert GEOD.inv(*path[-1], *t)[2] < 0.5 + 1e-6
    straight = GEOD.inv(*s, *t)[2]
    assert _metres(path) >= straight - 1e-6
    assert run.moves >= straight / 0.5
