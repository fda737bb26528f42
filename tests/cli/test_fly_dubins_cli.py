"""``skyroute fly --vehicle dubins``: Hybrid A* by default, only free paths, tours.

Every written trajectory is re-checked here without skyroute's collision code: shapely
distances from its densely sampled poses, with the sagitta of the sampling as slack.
"""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest
import shapely

import skyroute
from tests.cli.test_cli import run
from tests.conftest import ROOT

CITY = str(ROOT / "examples" / "city.csv")
BASE = ["fly", CITY, "--frame", "ned", "--vehicle", "dubins", "--altitude", "10",
        "--safety", "2", "--radius", "8"]


def assert_free(rows, radius: float, step: float) -> None:
    """No sampled point inside a (grown) building, and none nearer to one than the
    sagitta of an arc of ``step`` (so the arcs between samples stay out too)."""
    world = skyroute.load_world(CITY, altitude=10, safety=2, frame="ned")
    plane = world.to_plane(np.asarray(rows)[:, :2])
    sagitta = radius * (1 - math.cos(step / (2 * radius)))
    union = shapely.unary_union(world.obstacles)
    d = shapely.distance(union, shapely.points(plane))
    assert (d > sagitta - 1e-9).all(), d.min()


def test_default_is_hybrid_and_every_written_pose_is_free(monkeypatch, capsys, tmp_path):
    out, png = tmp_path / "t.csv", tmp_path / "t.png"
    code, text, err = run(monkeypatch, capsys, *BASE, "--start", "0,0,90",
                          "--goal", "120,-180", "--step", "0.5", "--json", "--out", str(out),
                          "--plot", str(png))
    assert code == 0, err
    doc = json.loads(text)
    assert doc["reached"] and doc["metrics"]["status"] == "found"
    header, *body = list(csv.reader(out.open()))
    rows = [[float(v) for v in r] for r in body]
    assert header == ["north", "east", "heading_deg"]
    assert rows[0] == [0.0, 0.0, 90.0]  # exactly the start pose typed (compass heading)
    assert rows[-1][:2] == pytest.approx([120.0, -180.0], abs=1e-9)
    assert_free(rows, 8.0, 0.5)
    # it is at least as long as the exact 2D route, and not much longer
    exact = skyroute.plan(skyroute.load_world(CITY, altitude=10, safety=2, frame="ned"),
                          (0, 0), (120, -180)).cost
    assert exact <= doc["metrics"]["length"] <= 1.2 * exact
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_goal_heading_and_runway_approach(monkeypatch, capsys):
    code, text, err = run(monkeypatch, capsys, *BASE, "--start", "0,0,0",
                          "--goal", "-30,120,180", "--approach", "25", "--json")
    assert code == 0, err
    traj = np.array(json.loads(text)["trajectory"])
    assert traj[-1].tolist() == [-30.0, 120.0, 180.0]
    # the last 25 m are straight along the runway heading (south): east constant
    tail = traj[traj[:, 0] >= -30.0 + 1e-9][-10:]
    assert np.allclose(tail[:, 1], 120.0, atol=1e-6) and np.allclose(tail[:, 2], 180.0)


def test_no_path_within_the_budget_exits_1_and_writes_nothing(monkeypatch, capsys,
                                                              tmp_path):
    out = tmp_path / "t.json"
    code, text, _ = run(monkeypatch, capsys, *BASE, "--start", "0,0,90", "--goal",
                        "120,-180", "--max-expansions", "5", "--json", "--out", str(out))
    assert code == 1 and not out.exists()
    assert json.loads(text)["metrics"]["status"] == "budget_exhausted"


def test_json_of_a_flight_not_found_is_strict_json(monkeypatch, capsys):
    """A search out of budget has no length: --json printed `"length": Infinity`, which
    is no JSON (RFC 8259: jq and JSON.parse refuse it); it is null."""
    def refuse(name):
        raise ValueError(f"{name} is not JSON")

    code, text, _ = run(monkeypatch, capsys, *BASE, "--start", "0,0,90", "--goal",
                        "120,-180", "--max-expansions", "5", "--json")
    doc = json.loads(text, parse_constant=refuse)
    assert code == 1 and doc["metrics"]["status"] == "budget_exhausted"
    assert doc["metrics"]["length"] is None


def test_the_default_budget_says_which_flags_to_raise(monkeypatch, capsys):
    # without --max-expansions the search had no budget: a radius tiny beside the city
    # ran until the machine's memory was gone; now a default (lowered here) ends it
    from skyroute.motion import hybrid

    monkeypatch.setattr(hybrid, "MAX_NODES", 3 * 2000, raising=False)
    code, text, err = run(monkeypatch, capsys, *BASE[:-2], "--radius", "0.5", "--start",
                          "0,0,90", "--goal", "120,-180", "--json")
    assert code == 1, err
    m = json.loads(text)["metrics"]
    assert m["status"] == "budget_exhausted" and m["expanded"] == 2000
    assert m["why"].startswith("Hybrid A* stopped after 2,000 expansions (the default "
                               "--max-expansions); the world is ")
    assert m["why"].endswith("turning radii across (--radius 0.5): raise --max-expansions "
                             "or --radius")
    code, text, _ = run(monkeypatch, capsys, *BASE, "--start", "0,0,90", "--goal",
                        "120,-180", "--max-expansions", "5")
    assert code == 1 and "stopped after 5 expansions (--max-expansions)" in text


def test_waypoints_cut_a_building_where_hybrid_finds_a_free_path(monkeypatch, capsys):
    """The issue's case: curves through the route's corners clip a building (and say so);
    Hybrid A* on the same query flies round it."""
    query = ["--start", "0,0,90", "--goal", "120,-180", "--step", "0.5", "--json"]
    code, text, err = run(monkeypatch, capsys, *BASE, "--planner", "waypoints", *query)
    assert code == 0, err
    old = json.loads(text)
    world = skyroute.load_world(CITY, altitude=10, safety=2, frame="ned")
    track = shapely.LineString(world.to_plane(np.array(old["trajectory"])[:, :2]))
    assert old["metrics"]["free"] is False
    assert shapely.unary_union(world.obstacles).relate_pattern(track, "T********")
    code, text, err = run(monkeypatch, capsys, *BASE, *query)
    assert code == 0, err
    assert_free(json.loads(text)["trajectory"], 8.0, 0.5)


@pytest.mark.parametrize("head", ["north,east\n", "\ufeff"])
def test_tour_visits_every_target(monkeypatch, capsys, tmp_path, head):
    # "\ufeff": Excel's byte-order mark before the first target, which was then taken for
    # a header and silently dropped from the tour
    targets = tmp_path / "targets.csv"
    points = [(60.0, 30.0), (-60.0, 60.0), (0.0, -120.0), (-120.0, -60.0)]  # on streets
    targets.write_text(head + "".join(f"{n},{e}\n" for n, e in points), encoding="utf-8")
    # No --goal: a tour has none (it was a required option, exit 2 "Missing option").
    code, text, err = run(monkeypatch, capsys, *BASE, "--start", "0,0,0",
                          "--targets", str(targets), "--step", "0.5", "--json")
    assert code == 0, err
    doc = json.loads(text)
    m = doc["metrics"]
    assert m["method"] == "exact" and sorted(m["order"].split()) == ["1", "2", "3", "4"]
    traj = np.array(doc["trajectory"])
    for p in points:
        assert np.hypot(*(traj[:, :2] - p).T).min() < 1e-6
    assert_free(doc["trajectory"], 8.0, 0.5)
    assert m["bound"] <= m["length"] + 1e-9


def test_a_tour_to_a_walled_off_target_is_no_path(monkeypatch, capsys, tmp_path):
    """A target inside a closed ring of buildings: `fly --targets` said `found`, `reached
    True`, order `0 0` (the last target flown to twice), and wrote a trajectory that
    never came near the walled one. It is `no_path`, exit 1, and writes nothing."""
    city = tmp_path / "ring.csv"
    city.write_text("lat0 37.792480, lon0 -122.397450\n"
                    "posX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n"
                    "100,80,20,30,5,20\n100,120,20,30,5,20\n"
                    "75,100,20,5,25,20\n125,100,20,5,25,20\n", encoding="utf-8")
    targets, out = tmp_path / "targets.csv", tmp_path / "tour.csv"
    targets.write_text("100,100\n0,50\n", encoding="utf-8")
    code, text, err = run(monkeypatch, capsys, "fly", str(city), "--frame", "ned",
                          "--vehicle", "dubins", "--start", "0,0", "--targets", str(targets),
                          "--json", "--out", str(out))
    assert code == 1, err
    m = json.loads(text)["metrics"]
    assert m["status"] == "no_path" and m["length"] is None and m["order"] == ""
    assert not out.exists()


def test_a_flight_along_a_face_two_buildings_share_is_refused(monkeypatch, capsys,
                                                             tmp_path):
    """Two buildings touching along east 50: a start and a goal on that face were free
    points, and the flight between them ran 16 m through the block (found, exit 0).
    It is one line naming the start, inside the block, exit 2, and no file."""
    city, out = tmp_path / "two.csv", tmp_path / "t.csv"
    city.write_text("lat0 37.792480, lon0 -122.397450\n"
                    "posX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n"
                    "50,45,20,10,5,20\n50,55,20,10,5,20\n", encoding="utf-8")
    code, text, err = run(monkeypatch, capsys, "fly", str(city), "--frame", "ned",
                          "--vehicle", "dubins", "--start", "42,50,0", "--goal", "58,50,0",
                          "--out", str(out))
    assert code == 2 and text == "" and not out.exists()
    assert err == ("skyroute: error: start (42.00, 50.00) lies inside obstacle 'box at line "
                   "3'; nearest free point (39.99, 50.00)\n")


@pytest.mark.parametrize("args, words", [
    (["--start", "15,-30", "--goal", "120,-180"], "lies inside obstacle"),
    (["--start", "0,0,north", "--goal", "120,-180"], "--start '0,0,north' must be"),
    (["--start", "0,0", "--goal", "120,-180", "--radius", "-1"], "--radius -1.0 must be"),
    (["--start", "0,0,10", "--start-heading", "10", "--goal", "120,-180"],
     "give the start heading once"),
    (["--start", "0,0", "--goal", "120,-180", "--approach", "20"], "--approach: give the"),
    (["--start", "0,0", "--goal", "120,-180", "--planner", "moves"], "--planner 'moves'"),
    # these spoke of the library's start=(0.0, 0.0, inf) in radians, not of the option
    (["--start", "0,0", "--goal", "120,-180", "--start-heading", "inf"],
     "--start-heading inf must be a finite number"),
    (["--start", "0,0", "--goal", "120,-180", "--goal-heading", "nan"],
     "--goal-heading nan must be a finite number"),
])
def test_bad_poses_are_one_line_exit_2(monkeypatch, capsys, tmp_path, args, words):
    out = tmp_path / "t.json"
    code, text, err = run(monkeypatch, capsys, *BASE[:-2], *args, "--out", str(out))
    assert code == 2 and err.count("\n") == 1 and words in err, err
    assert not out.exists() and text == ""


@pytest.mark.parametrize("vehicle", ["dubins", "step"])
def test_no_goal_and_no_targets_is_one_line_exit_2(monkeypatch, capsys, vehicle):
    code, text, err = run(monkeypatch, capsys, "fly", CITY, "--frame", "ned", "--vehicle",
                          vehicle, "--altitude", "10", "--start", "0,0")
    assert code == 2 and text == ""
    assert err == "skyroute: error: give --goal A,B (or --targets FILE with --vehicle " \
                  "dubins)\n"


def test_bad_targets_file_names_the_line(monkeypatch, capsys, tmp_path):
    targets = tmp_path / "t.csv"
    targets.write_text("30,30\n30;x\n")
    code, _, err = run(monkeypatch, capsys, *BASE, "--start", "0,0", "--goal", "0,0",
                       "--targets", str(targets))
    assert code == 2 and f"{targets}:2: expected two numbers" in err


@pytest.mark.parametrize("extra", [["--goal", "120,-180"], ["--goal", "120,-180", "--planner",
                                                            "waypoints"]])
def test_plot_title_shows_the_reported_length(monkeypatch, capsys, tmp_path, extra):
    # The title gave the sampled polyline's length (236.436 m against 236.451 in the table).
    import matplotlib.axes

    titles = []
    set_title = matplotlib.axes.Axes.set_title
    monkeypatch.setattr(matplotlib.axes.Axes, "set_title",
                        lambda ax, label, *a, **k: titles.append(label) or
                        set_title(ax, label, *a, **k))
    png = tmp_path / "dubins.png"
    code, text, err = run(monkeypatch, capsys, *BASE, "--start", "0,0,90", *extra, "--step",
                          "4", "--plot", str(png), "--json")
    assert code == 0, err
    length = json.loads(text)["metrics"]["length"]
    assert titles == [f"city.csv: dubins, {length:.6g} m"]
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_goal_one_quarter_turn_away_is_flown_as_that_turn(monkeypatch, capsys):
    # a right turn of radius 8 from north ends 8 north, 8 east, heading east: the path
    # is that arc (4 pi = 12.57), not the arc after a whole circle (62.8) as the Dubins
    # words' rounding once made it
    code, text, err = run(monkeypatch, capsys, *BASE, "--start", "0,0,0", "--goal", "8,8,90",
                          "--step", "1", "--json")
    assert code == 0, err
    doc = json.loads(text)
    assert doc["metrics"]["length"] == pytest.approx(8 * math.pi / 2, rel=1e-9)
    rows = np.asarray(doc["trajectory"])
    assert np.all(np.diff(rows[:, 2]) > 0)  # the heading only swings clockwise, 0 to 90
    assert rows[-1].tolist() == pytest.approx([8.0, 8.0, 90.0], abs=1e-9)


@pytest.mark.parametrize("planner", ["hybrid", "waypoints"])
def test_a_step_too_small_to_sample_is_one_line_exit_2(monkeypatch, capsys, tmp_path,
                                                       planner):
    # --step 1e-12 along ~250 m was a MemoryError traceback (1e-7: gigabytes first)
    out = tmp_path / "t.csv"
    code, text, err = run(monkeypatch, capsys, *BASE, "--planner", planner, "--start",
                          "0,0,90", "--goal", "120,-180", "--step", "1e-12", "--out", str(out))
    assert code == 2 and not out.exists()
    line = (text + err).strip()
    assert "\n" not in line and "Traceback" not in line
    assert "--step 1e-12 along a path" in line and "more than 10,000,000 poses" in line


def test_waypoints_without_a_start_heading_pick_the_best(monkeypatch, capsys, tmp_path):
    # the waypoints planner set a start without heading to 0 (north): due east to a goal
    # 100 m away it turned right first, 106.3 m; the docs say a left-out heading is chosen
    city = tmp_path / "one.csv"
    city.write_text("lat0 37.792480, lon0 -122.397450\n"
                    "posX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n50,50,20,10,10,20\n")
    args = ["fly", str(city), "--frame", "ned", "--vehicle", "dubins", "--planner",
            "waypoints", "--altitude", "5", "--radius", "10", "--goal", "0,0", "--json"]
    code, text, err = run(monkeypatch, capsys, *args, "--start", "0,-100")
    assert code == 0, err
    doc = json.loads(text)
    assert doc["metrics"]["length"] == pytest.approx(100.0, abs=1e-9)
    assert [row[2] for row in doc["trajectory"]] == pytest.approx(
        [90.0] * len(doc["trajectory"]))  # east, all along
    code, text, err = run(monkeypatch, capsys, *args, "--start", "0,-100,0")  # told north
    assert code == 0, err
    assert json.loads(text)["metrics"]["length"] > 105


def test_waypoints_from_a_point_to_itself_turn_between_the_headings(monkeypatch, capsys):
    # the exact route from a point to itself is one point (as every planner gives it);
    # the waypoints planner still flies the Dubins path between the two headings there
    code, text, err = run(monkeypatch, capsys, *BASE, "--planner", "waypoints", "--start",
                          "0,0,0", "--goal", "0,0,90", "--json")
    assert code == 0, err
    doc = json.loads(text)
    assert doc["trajectory"][0] == [0.0, 0.0, 0.0]
    assert doc["trajectory"][-1] == pytest.approx([0.0, 0.0, 90.0], abs=1e-6)
    assert doc["metrics"]["length"] > 0 and len(doc["metrics"]["words"]) == 3
