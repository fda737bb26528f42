"""Headings across conventions: a Dubins path (poses in the world's convention) written
as FCND waypoints (radians clockwise from north) or read on the ellipsoid (pyproj's
azimuths) points the way the vehicle flies; a tour's headings are its arrival headings
in visiting order."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pyproj import Geod

import skyroute
from skyroute.io.world_out import waypoints
from skyroute.motion import dubins
from skyroute.motion.hybrid import plan as hybrid_plan
from tests.cli.test_fly_dubins_cli import CITY

R, STEP = 8.0, 0.5
CHORD = STEP / (2 * R) + 1e-6  # a chord's direction is within half its arc's turn


def _gap(a, b) -> np.ndarray:
    return np.abs((np.asarray(a) - np.asarray(b) + math.pi) % (2 * math.pi) - math.pi)


def _world(frame: str):
    return skyroute.load_world(CITY, altitude=10, safety=2, frame=frame)


def _query(frame: str):
    """Start (with a heading of 0.3 rad in the frame's convention) and goal, in the frame,
    the same places in every frame."""
    ned = _world("ned")
    s, g = np.array([[0.0, 0.0]]), np.array([[60.0, -50.0]])
    if frame == "ned":
        return (0.0, 0.0, 0.3), (60.0, -50.0)
    if frame == "enu":
        return (0.0, 0.0, 0.3), (-50.0, 60.0)
    return (*ned.to_lonlat(s)[0], 0.3), tuple(ned.to_lonlat(g)[0])


def _ned_heading(frame: str, h):
    """A heading of ``frame``'s convention as NED's (radians clockwise from north), by
    the table of docs/architecture.md (not by skyroute.geo)."""
    return np.asarray(h) if frame in ("ned", "lonlat") else math.pi / 2 - np.asarray(h)


@pytest.mark.parametrize("frame", ["ned", "enu", "lonlat"])
def test_a_dubins_path_as_fcnd_waypoints_heads_where_it_flies(frame):
    world = _world(frame)
    start, goal = _query(frame)
    res = hybrid_plan(world, start, goal, R)
    assert res.found
    poses = res.sample(STEP)
    rows = np.array(waypoints(world, poses[:, :2], 10.0))
    # each waypoint's heading is the track's into it: the pose's heading there within
    # the chord's turn (a lon/lat point repeated at the goal came back 5e-9 m away, and
    # its "track" turned the last waypoint 0.19 rad from the path)
    assert _gap(rows[1:, 3], _ned_heading(frame, poses[1:, 2])).max() <= CHORD
    assert rows[0, 3] == pytest.approx(_ned_heading(frame, 0.3) % (2 * math.pi), abs=CHORD)


def test_lonlat_pose_headings_are_pyprojs_azimuths():
    world = _world("lonlat")
    start, goal = _query("lonlat")
    poses = hybrid_plan(world, start, goal, R).sample(STEP)
    a, b = poses[:-1], poses[1:]
    moved = np.hypot(*(world.to_plane(b[:, :2]) - world.to_plane(a[:, :2])).T) > 1e-6
    az, _, _ = Geod(ellps="WGS84").inv(a[moved, 0], a[moved, 1], b[moved, 0], b[moved, 1])
    assert _gap(np.radians(az), b[moved, 2]).max() <= CHORD + 1e-3  # the grid's convergence


@pytest.mark.parametrize("world", [None, "ned"])
def test_a_tours_headings_are_its_arrival_headings_in_visiting_order(world):
    targets = [(60.0, 30.0), (-60.0, 60.0), (10.0, -50.0)]
    w = None if world is None else _world(world)
    res = dubins.tour((0.0, 0.0, 0.0), targets, R, world=w)
    assert res.found and sorted(res.order) == [0, 1, 2]
    for leg, k, h in zip(res.legs, res.order, res.headings, strict=True):
        end = leg.sample(STEP)[-1] if w is not None else dubins_end(leg)
        assert end[:2] == pytest.approx(targets[k], abs=1e-6)
        assert _gap(end[2], h) <= 1e-9
    first = res.sample(STEP)[0]
    assert first.tolist() == [0.0, 0.0, 0.0]  # the start pose's heading, as given


def dubins_end(pieces) -> np.ndarray:
    from skyroute.motion.pieces import sample

    return sample(pieces, STEP, pieces[0].start)[-1]


def test_fly_help_says_a_tour_starts_on_heading_0(monkeypatch):
    # --start-heading's help said "dubins: free when left out", but a tour (--targets)
    # starts on heading 0 when it is left out, as docs/cli.md says
    from typer.testing import CliRunner

    from skyroute.cli.app import app

    result = CliRunner().invoke(app, ["fly", "--help"], env={"COLUMNS": "200",
                                                             "TERMINAL_WIDTH": "200"})
    text = " ".join(result.output.replace("│", " ").split())
    assert result.exit_code == 0 and "free when left out, but 0 with --targets" in text, text


def test_a_tour_without_a_start_heading_starts_on_0(monkeypatch, capsys, tmp_path):
    from tests.cli.test_cli import run

    targets = tmp_path / "t.csv"
    targets.write_text("60,30\n-60,60\n")
    out = tmp_path / "tour.csv"
    code, _, err = run(monkeypatch, capsys, "fly", CITY, "--frame", "ned", "--vehicle",
                       "dubins", "--altitude", "10", "--safety", "2", "--radius", "8",
                       "--start", "0,0", "--targets", str(targets), "--out", str(out))
    assert code == 0, err
    first = out.read_text().splitlines()[1].split(",")
    assert [float(v) for v in first] == [0.0, 0.0, 0.0]  # north, east, heading_deg
