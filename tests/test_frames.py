"""One set of frames for Python and the command line (docs/architecture.md, conventions).

For every frame, ``skyroute.plan`` on a world loaded in that frame and ``skyroute
plan-world --frame F --json`` read the same typed points and return the same path and
cost; the same query in different frames is the same flight; errors speak the caller's
frame. Data: the synthetic city and zone file shipped in examples/.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import skyroute
from skyroute.geo import heading_from_plane, heading_to_plane
from tests.cli.test_cli import run
from tests.conftest import ROOT

CITY = str(ROOT / "examples" / "city.csv")
ZONES = str(ROOT / "examples" / "lunch" / "website" / "buildings" / "no-fly-zones.geojson")
BOX = "-3.17,55.969,-3.1618,55.9726"

# one query per world, typed in each frame (ned/enu: metres from the world's home)
CITY_LONLAT = ((-3.1890, 55.9456), (-3.1850, 55.9432))
ZONES_LONLAT = ((-3.1690, 55.9700), (-3.1625, 55.9720))


def typed(world_lonlat: skyroute.World, lonlat, frame: str) -> tuple[float, float]:
    """The point ``lonlat`` as a user of ``frame`` types it (rounded to 1e-9)."""
    w = world_lonlat.in_frame(frame)
    p = w.from_plane(w.plane_from_lonlat([lonlat]))[0]
    return round(float(p[0]), 9), round(float(p[1]), 9)


def cases():
    for path, kw, lonlat, frames in (
            (CITY, {"altitude": 10, "safety": 2}, CITY_LONLAT, ("lonlat", "ned", "enu")),
            (ZONES, {"boundary": BOX}, ZONES_LONLAT, ("lonlat", "ned", "enu", "degrees"))):
        for frame in frames:
            for algorithm in ("visibility", "astar"):
                yield pytest.param(path, kw, lonlat, frame, algorithm,
                                   id=f"{path.rsplit('/', 1)[-1]}-{frame}-{algorithm}")


@pytest.mark.parametrize("path, kw, lonlat, frame, algorithm", list(cases()))
def test_python_and_cli_agree_in_every_frame(monkeypatch, capsys, path, kw, lonlat, frame,
                                             algorithm):
    base = skyroute.load_world(path, **kw)
    a, b = (typed(base, p, frame) for p in lonlat)
    world = skyroute.load_world(path, frame=frame, **kw)
    assert world.frame == frame
    res = skyroute.plan(world, a, b, algorithm=algorithm)
    assert res.found and res.extra["frame"] == frame
    args = ["plan-world", path, "--frame", frame, f"--start={a[0]!r},{a[1]!r}",
            f"--goal={b[0]!r},{b[1]!r}", "--algorithm", algorithm, "--json"]
    for k, v in kw.items():
        args += [f"--{k}", str(v)]
    code, out, err = run(monkeypatch, capsys, *args)
    assert code == 0, err
    doc = json.loads(out)
    assert doc["frame"] == frame and doc["cost"] == res.cost
    np.testing.assert_array_equal(doc["path"], res.path)
    np.testing.assert_array_equal(doc["path_lonlat"], res.path_lonlat)
    # the path is in the caller's frame: its ends are the typed points
    np.testing.assert_allclose(res.path[0], a, atol=1e-6)
    np.testing.assert_allclose(res.path[-1], b, atol=1e-6)


@pytest.mark.parametrize("path, kw, lonlat", [(CITY, {"altitude": 10, "safety": 2},
                                               CITY_LONLAT)])
def test_one_query_is_one_flight_whatever_the_frame(path, kw, lonlat):
    base = skyroute.load_world(path, **kw)
    results = {}
    for frame in ("lonlat", "ned", "enu"):
        w = skyroute.load_world(path, frame=frame, **kw)
        results[frame] = skyroute.plan(w, *(typed(base, p, frame) for p in lonlat))
    costs = [r.cost for r in results.values()]
    assert max(costs) - min(costs) < 1e-6  # metres; typed points are rounded to 1e-9
    for r in results.values():
        np.testing.assert_allclose(r.path_lonlat, results["lonlat"].path_lonlat, atol=1e-9)
    # ned is enu with the axes swapped
    np.testing.assert_allclose(results["ned"].path, results["enu"].path[:, ::-1], atol=1e-6)


def test_errors_speak_the_callers_frame():
    lonlat = skyroute.load_world(CITY, altitude=10, safety=2)
    ned = lonlat.in_frame("ned")
    inside = lonlat.from_plane([lonlat.obstacles[0].centroid.coords[0]])[0]
    with pytest.raises(skyroute.QueryError, match=r"start \(-3\.\d{7}, 55\.\d{7}\) lies inside "
                                                  r"obstacle 'box at line \d+'; nearest free "
                                                  r"point \(-3\.\d{7}, 55\.\d{7}\)"):
        skyroute.plan(lonlat, inside, CITY_LONLAT[1])
    ne = ned.from_plane(ned.plane_from_lonlat([inside]))[0]
    with pytest.raises(skyroute.QueryError, match=rf"goal \({ne[0]:.2f}, {ne[1]:.2f}\) lies "
                                                  "inside obstacle"):
        skyroute.plan(ned, (0, 0), ne)
    zones = skyroute.load_world(ZONES, boundary=BOX, frame="ned")
    with pytest.raises(skyroute.QueryError, match=r"goal \(5000\.00, 0\.00\) lies outside the "
                                                  r"map \(north in \(-20\d\.\d+, 20\d\.\d+\), "
                                                  r"east in \(-25\d\.\d+, 25\d\.\d+\)\)"):
        skyroute.plan(zones, (0, 0), (5000, 0))


@pytest.mark.parametrize("bad, words", [
    (np.array([[1.0, 2.0, 0.0]]), "goal must be (a, b) numbers"),
    ((1.0,), "goal must be (a, b) numbers"),
    ((math.nan, 1.0), "goal must be finite numbers"),
    (("a", "b"), "goal must be numbers"),
    (None, "goal must be (a, b) numbers"),
    ([[0, 0], [1, 1]], "goal must be one point"),
])
def test_malformed_points_are_query_errors_naming_the_argument(bad, words):
    world = skyroute.load_world(CITY, altitude=10, safety=2, frame="enu")
    with pytest.raises(skyroute.QueryError) as info:
        skyroute.plan(world, (0, 0), bad)
    assert words in str(info.value)


def test_lonlat_points_must_be_places():
    world = skyroute.load_world(CITY, altitude=10, safety=2)
    with pytest.raises(skyroute.QueryError, match=r"start .*is not a place"):
        skyroute.plan(world, (0.0, 120.0), CITY_LONLAT[1])


def test_headings_one_convention_per_frame():
    # compass frames: 0 = north, 90 degrees = east; plane: anticlockwise from +x (east)
    assert heading_to_plane(0.0, "ned") == pytest.approx(math.pi / 2)
    assert heading_to_plane(math.pi / 2, "lonlat") == pytest.approx(0.0)
    assert heading_to_plane(1.0, "enu") == pytest.approx(1.0)
    assert heading_to_plane(1.0, "degrees") == pytest.approx(1.0)
    h = np.linspace(0, 2 * math.pi, 17)[:-1]
    for frame in ("lonlat", "ned", "enu", "degrees"):
        np.testing.assert_allclose(heading_from_plane(heading_to_plane(h, frame), frame), h,
                                   atol=1e-12)
    world = skyroute.load_world(CITY, frame="ned")
    assert float(world.heading_to_plane(math.pi)) == pytest.approx(1.5 * math.pi)  # south


def test_a_world_in_degrees_is_the_same_world():
    metres = skyroute.load_world(ZONES, boundary=BOX)
    degrees = skyroute.load_world(ZONES, boundary=BOX, frame="degrees")
    moved = metres.in_frame("degrees")
    for a, b in zip(moved.obstacles, degrees.obstacles, strict=True):
        np.testing.assert_allclose(np.asarray(a.exterior.coords), np.asarray(b.exterior.coords),
                                   atol=1e-9)
    assert moved.frame == "degrees" and moved.plane == "degrees"


def test_local_is_an_alias_of_ned_and_metres_is_deprecated():
    assert skyroute.load_world(CITY, frame="local").frame == "ned"
    with pytest.warns(DeprecationWarning, match="enu"):
        w = skyroute.World([], [], [], (), None, "metres")
    assert w.frame == "enu"
    with pytest.raises(skyroute.OptionError, match="frame='mercator' is not valid"):
        skyroute.load_world(CITY, frame="mercator")
    with pytest.raises(skyroute.OptionError, match="needs a home"):
        skyroute.World([], [], [], (), None, "lonlat")


def test_fly_reads_the_same_frames(monkeypatch, capsys, tmp_path):
    """fly's default frame is the world's own (lonlat), as plan-world's; the step drone
    flies the same moves whether the points come as lonlat or degrees."""
    a, b = ZONES_LONLAT
    common = ["fly", ZONES, "--boundary", BOX, f"--start={a[0]},{a[1]}",
              f"--goal={b[0]},{b[1]}", "--json"]
    code, out, err = run(monkeypatch, capsys, *common)
    assert code == 0, err
    lonlat = json.loads(out)
    code, out, err = run(monkeypatch, capsys, *common, "--frame", "degrees")
    assert code == 0, err
    degrees = json.loads(out)
    assert lonlat["moves"] == degrees["moves"] and lonlat["metrics"]["moves"] > 0
    assert lonlat["moves"][0][:2] == [a[0], a[1]]  # ILP rows start at the typed point


def test_fly_lattice_in_ned_matches_python(monkeypatch, capsys):
    from skyroute.motion.turn_lattice import plan_turns_world

    world = skyroute.load_world(CITY, altitude=10, safety=2, frame="ned")
    res = plan_turns_world(world, (0, 0), (120, -180), resolution=2.0,
                           start_heading=math.radians(90))
    assert res.found and res.path.shape[1] == 2
    assert np.hypot(*(res.path[0] - (0, 0))) < 2.0 and np.hypot(*(res.path[-1] - (120, -180))) < 2
    code, out, err = run(monkeypatch, capsys, "fly", CITY, "--frame", "ned", "--vehicle",
                         "lattice", "--start", "0,0", "--goal", "120,-180", "--altitude", "10",
                         "--safety", "2", "--resolution", "2", "--start-heading", "90",
                         "--json")
    assert code == 0, err
    traj = np.array(json.loads(out)["trajectory"])
    np.testing.assert_allclose(traj[:, :2], res.path)
    np.testing.assert_allclose(traj[:, 2], np.degrees(res.headings))
    assert traj[0, 2] == pytest.approx(90.0)  # heading east, as asked, in compass degrees
