"""The potential field on a world in the "degrees" frame: its distances are metres there
too. Before, the defaults (step and tolerance 0.5) were half a degree, 30 to 55 km, and
every goal of a city was "reached" at once, in 0 moves."""

import json
import math

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from pyproj import Geod

from skyroute import OptionError, World, load_world
from skyroute.geo import Home, enu_to_lonlat, lonlat_to_enu
from skyroute.motion.potential import course, run_field

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


@pytest.mark.parametrize("mode", ["step", "arc"])
def test_the_default_run_on_a_degrees_world_reaches_the_goal_outside_the_zones(zones_file,
                                                                              mode):
    """Default options on a GeoJSON world loaded in "degrees": the goal is reached
    (within the default tolerance of 0.5 m, measured on the ellipsoid) by a path that
    enters no zone and stays inside the area, checked with shapely on the lon/lat path
    against the zones as written, not through the world."""
    world = load_world(zones_file, frame="degrees")
    run = run_field(world, START, GOAL, mode=mode)
    lonlat = _flown(run)
    assert run.reached, run
    assert tuple(lonlat[0]) == START
    _, _, off = GEOD.inv(*lonlat[-1], *GOAL)
    assert off < 0.5
    line = shapely.LineString(lonlat)
    for zone in _zones():
        assert not zone.relate_pattern(line, "T********"), zone  # interiors never meet
    assert BOX.contains(line)
    straight = GEOD.inv(*START, *GOAL)[2]
    assert straight < _metres(lonlat) < 2 * straight
    assert run.moves > straight / 0.5 / 2  # moves of about the default 0.5 m
    assert run.distance == pytest.approx(line.length)  # plane units: degrees


@pytest.mark.parametrize("mode", ["step", "arc"])
@pytest.mark.parametrize("kw", [{}, {"step": 2.0, "tolerance": 1.0, "sensor_range": 10.0}])
def test_the_same_world_in_degrees_and_in_lonlat_flies_the_same_run(zones_file, mode, kw):
    """The GeoJSON world loaded in "degrees" and in "lonlat" (metres round its home), the
    same options: the runs are the same on the ground (lengths on the ellipsoid within
    1 %, moves within 3 %), the defaults and explicit values alike."""
    runs = [run_field(load_world(zones_file, frame=frame), START, GOAL, mode=mode, **kw)
            for frame in ("degrees", "lonlat")]
    assert all(r.reached for r in runs), runs
    deg, ll = (_metres(_flown(r)) for r in runs)
    assert deg == pytest.approx(ll, rel=0.01)
    assert runs[0].moves == pytest.approx(runs[1].moves, rel=0.03)


def _degrees_course(name: str, lon: float, lat: float):
    """A built-in course (enu metres) placed at (lon, lat) and carried to "degrees"
    vertex by vertex through the tangent plane (World.in_frame)."""
    world, start, goal = course(name)
    centre = np.array([30.0, 30.0])
    move = lambda p: p - centre  # noqa: E731 -- home at the course's centre
    enu = World(shapely.transform(world.obstacles, move), world.floors, world.ceilings,
                world.names, shapely.transform(world.boundary, move), "enu",
                Home(lon, lat))
    return enu, enu.in_frame("degrees"), start - centre, goal - centre


@settings(max_examples=8, deadline=None)
@given(lat=st.floats(-70, 70), lon=st.floats(-179, 179), mode=st.sampled_from(["step", "arc"]),
       name=st.sampled_from(["medium", "hard"]), heading=st.floats(0, 2 * math.pi))
def test_a_course_anywhere_on_earth_flies_the_same_in_degrees_as_in_metres(lat, lon, mode,
                                                                           name, heading):
    """A course carried to any latitude: in "degrees", with default options and the
    same start heading (converted with pyproj alone), the run is the one flown in
    metres: it reaches the goal, its path projected back to metres is as long within
    1 %, and it ends within the tolerance of the goal."""
    enu, deg, s, t = _degrees_course(name, lon, lat)
    home = enu.home
    ends = enu_to_lonlat(np.array([s[0], t[0], s[0] + math.cos(heading)]),
                         np.array([s[1], t[1], s[1] + math.sin(heading)]), 0.0, home)[:, :2]
    d = ends[2] - ends[0]
    h_deg = math.atan2(d[1], d[0])  # the same direction on the flat lon/lat plane
    metres = run_field(enu, s, t, mode=mode, heading=heading)
    degrees = run_field(deg, ends[0], ends[1], mode=mode, heading=h_deg)
    assert metres.reached and degrees.reached, (metres, degrees)
    back = lonlat_to_enu(*_flown(degrees).T, 0.0, home)[:, :2]
    assert np.hypot(*np.diff(back, axis=0).T).sum() == pytest.approx(metres.distance,
                                                                      rel=0.01)
    assert math.dist(back[-1], t) < 0.5 + 1e-6
    assert deg.segments_free(_flown(degrees)[:-1], _flown(degrees)[1:]).all()


def test_a_degrees_world_at_a_pole_is_refused_naming_the_frame():
    """At a pole a degree of longitude has no length: one OptionError, not a run with
    infinite or zero moves."""
    world = World([shapely.box(10, 89.9, 10.5, 89.95)], [-np.inf], [np.inf], (),
                  shapely.box(0, 89.8, 20, 89.99), "degrees", Home(10, 89.995))
    with pytest.raises(OptionError, match=r"at a pole .*frame 'lonlat'"):
        run_field(world, (1, 89.85), (19, 89.85))
