"""``skyroute fly``: the step drone, Dubins and the turn lattice from the command line."""

import csv
import json
import math

import numpy as np
import pytest
import shapely
import typer.main

import skyroute
from skyroute.cli.app import app
from tests.cli.test_cli import run
from tests.conftest import ROOT, SHARED

ZONES = str(SHARED / "ilp2021" / "website" / "buildings" / "no-fly-zones.geojson")
BOX = str(SHARED / "ilp2021" / "testing" / "confinement-zone.geojson")
AT, SODERBERG = "--start=-3.186874,55.944494", "--goal=-3.191594,55.943658"


@pytest.fixture
def city(tmp_path, monkeypatch, capsys):
    p = tmp_path / "city.csv"
    assert run(monkeypatch, capsys, "synth-city", str(p), "--seed", "7")[0] == 0
    return str(p)


@pytest.mark.shared_data
def test_step_drone_moves_and_follow(monkeypatch, capsys, tmp_path):
    out = tmp_path / "moves.csv"
    code, text, err = run(monkeypatch, capsys, "fly", ZONES, "--boundary", BOX, AT, SODERBERG,
                          "--json", "--out", str(out))
    assert code == 0, err
    doc = json.loads(text)
    assert doc["reached"] and doc["metrics"]["moves"] == 31 == len(doc["moves"])
    rows = list(csv.reader(out.open()))
    assert rows[0] == ["from_lon", "from_lat", "angle", "to_lon", "to_lat"] and len(rows) == 32
    code, text, _ = run(monkeypatch, capsys, "fly", ZONES, "--boundary", BOX, AT, SODERBERG,
                        "--planner", "follow", "--json")
    assert code == 0 and json.loads(text)["metrics"]["moves"] >= 31


def test_dubins_and_lattice(monkeypatch, capsys, tmp_path, city):
    code, text, err = run(monkeypatch, capsys, "fly", city, "--frame", "local", "--vehicle",
                          "dubins", "--planner", "waypoints", "--radius", "8", "--start", "0,0",
                          "--goal", "120,-180",
                          "--altitude", "10", "--safety", "2", "--json")
    assert code == 0, err
    doc = json.loads(text)
    world = skyroute.load_world(city, frame="local", altitude=10, safety=2)
    # the trajectory is (north, east) in the ned frame; shapely works in the plane
    m = doc["metrics"]
    track = shapely.LineString(world.to_plane(np.array(doc["trajectory"])[:, :2]))
    assert m["length"] >= math.dist((0, 0), (-180, 120)) and track.length <= m["length"] + 1e-9
    enters = shapely.unary_union(world.obstacles).relate_pattern(track, "T********")
    assert m["free"] is (not enters)  # the samples checked again with shapely alone
    assert set(m["words"].split()) <= {"LSL", "RSR", "LSR", "RSL", "RLR", "LRL"}
    gj = tmp_path / "lattice.geojson"
    code, text, err = run(monkeypatch, capsys, "fly", city, "--frame", "local", "--vehicle",
                          "lattice", "--start", "0,0", "--goal", "120,-180", "--altitude",
                          "10", "--safety", "2", "--resolution", "2", "--json", "--out",
                          str(gj))
    assert code == 0, err
    m = json.loads(text)["metrics"]
    assert m["time"] >= m["length"] / 1.0  # the default 1 m/s, plus the time to turn
    assert json.loads(gj.read_text())["features"][0]["geometry"]["type"] == "LineString"


def test_field_arc_mode(monkeypatch, capsys, tmp_path, city):
    args = ["fly", city, "--frame", "local", "--vehicle", "field", "--start", "0,0",
            "--goal", "60,-40", "--altitude", "10", "--step", "1", "--json"]
    code, text, err = run(monkeypatch, capsys, *args, "--field-mode", "arc", "--max-turn",
                          "30")
    assert code == 0, err
    doc = json.loads(text)
    assert doc["reached"] and doc["metrics"]["moves"] > 0
    assert len(doc["trajectory"]) > doc["metrics"]["moves"]  # the arcs, sampled
    code, text, _ = run(monkeypatch, capsys, *args, "--field-mode", "glide")
    assert code == 2 and "--field-mode 'glide' is not valid" in text + _


@pytest.mark.shared_data
@pytest.mark.parametrize("args, words", [
    (["--vehicle", "boat"], "--vehicle 'boat' is not valid"),
    (["--planner", "greedy"], "--planner 'greedy' is not valid"),
    (["--out", "x.txt"], "--out x.txt: the suffix must be"),
])
def test_bad_options(monkeypatch, capsys, args, words):
    code, _, err = run(monkeypatch, capsys, "fly", ZONES, "--boundary", BOX, AT, SODERBERG,
                       *args)
    assert code == 2 and words in err and err.count("\n") == 1


def test_grid_planners_reach_goals_beyond_the_obstacles(city):
    world = skyroute.load_world(city, frame="enu", altitude=10, safety=2)
    r = skyroute.plan(world, (0, 0), (-180, 120), algorithm="astar")
    assert r.found and world.segments_free(r.path[:-1], r.path[1:]).all()


def test_field_reports_length_like_the_other_vehicles(monkeypatch, capsys, city):
    code, text, err = run(monkeypatch, capsys, "fly", city, "--frame", "local", "--vehicle",
                          "field", "--start", "0,0", "--goal", "60,-40", "--altitude", "10",
                          "--step", "1", "--json")
    assert code == 0, err
    doc = json.loads(text)
    m = doc["metrics"]
    # one name across vehicles (docs/cli.md); it was "distance" for the field alone
    assert set(m) == {"length", "moves", "smoothness", "status", "reached", "escape_moves"}
    world = skyroute.load_world(city, frame="local", altitude=10)
    flown = np.diff(world.to_plane(np.array(doc["trajectory"])), axis=0)
    assert m["length"] == pytest.approx(np.hypot(*flown.T).sum())
    assert m["moves"] == len(doc["trajectory"]) - 1 and m["escape_moves"] >= 0
    code, text, err = run(monkeypatch, capsys, "fly", city, "--frame", "local", "--vehicle",
                          "field", "--start", "0,0", "--goal", "60,-40", "--altitude", "10")
    assert code == 0, err
    rows = {line.split("│")[1].strip() for line in text.splitlines() if line.count("│") == 3}
    assert {"length", "escape moves"} <= rows and "distance" not in rows


def table_rows(text: str) -> dict:
    return {line.split("│")[1].strip(): line.split("│")[2].strip()
            for line in text.splitlines() if line.count("│") == 3}


STEP = ["--frame", "local", "--altitude", "10", "--start", "0,0", "--goal", "30,-40"]


@pytest.mark.parametrize("args, keys, labels", [
    # the step drone's length is in degrees, which its value says: labelled as the others'
    (["--vehicle", "step"], {"moves", "length_deg", "expanded", "seconds", "status"},
     {"moves", "length", "expanded", "seconds", "status"}),
    (["--vehicle", "field", "--step", "1"],
     {"length", "moves", "smoothness", "status", "escape_moves"},
     {"length", "moves", "smoothness", "status", "escape moves"}),
    (["--vehicle", "lattice", "--resolution", "5"],
     {"time", "length", "moves", "smoothness", "expanded", "status"}, None),
    (["--vehicle", "dubins", "--planner", "waypoints", "--radius", "8"],
     {"length", "moves", "smoothness", "free", "words"}, None),
    (["--vehicle", "dubins", "--radius", "8"],
     {"status", "length", "expanded", "seconds", "pieces", "moves", "smoothness"}, None),
])
def test_fly_tables_label_metrics_without_underscores(monkeypatch, capsys, city, args, keys,
                                                      labels):
    """The table showed "escape_moves" and "length_deg", unlike every other table's
    labels ("max frontier"); --json keeps its keys."""
    code, text, err = run(monkeypatch, capsys, "fly", city, *STEP, *args, "--json")
    assert code == 0, err
    doc = json.loads(text)
    assert set(doc["metrics"]) == keys | {"reached"} if "reached" in doc["metrics"] else keys
    code, text, err = run(monkeypatch, capsys, "fly", city, *STEP, *args)
    assert code == 0, err
    rows = table_rows(text)
    assert set(rows) == (labels or keys) | {"reached"}
    assert not any("_" in k for k in rows)
    if "length_deg" in keys:
        assert rows["length"] == f"{doc['metrics']['length_deg']:,.6f} deg"


def test_the_tour_bounds_are_labelled_without_underscores():
    from skyroute.cli.fly_cmd import metrics_table
    from skyroute.cli.tables import plain_console

    doc = {"reached": True, "metrics": {"status": "found", "length": 12.5, "method": "exact",
                                        "order": "2 1", "greedy_bound": 14.0, "bound": 12.5,
                                        "seconds": 0.25}}
    console = plain_console(width=80)
    with console.capture() as cap:
        console.print(metrics_table("t", doc, "m"))
    rows = table_rows(cap.get())
    assert rows["greedy bound"] == "14.000000 m" and rows["bound"] == "12.500000 m"
    assert not any("_" in k for k in rows)


@pytest.mark.parametrize("args, words", [
    (["--vehicle", "lattice", "--speed", "0"], "--speed 0.0 must be positive"),
    (["--vehicle", "lattice", "--turn-rate", "0"], "--turn-rate 0.0 must be positive"),
    (["--vehicle", "field", "--step", "0"], "--step 0.0 must be > 0"),
    (["--vehicle", "field", "--sensor-range", "0"], "--sensor-range 0.0 must be > 0"),
    (["--vehicle", "field", "--sensor-rays", "3"], "--sensor-rays 3 must be >= 4"),
    (["--vehicle", "field", "--field-mode", "arc", "--max-turn", "0"],
     "--max-turn 0.0 must be in (0, 180] degrees"),
    (["--vehicle", "field", "--field-mode", "arc", "--max-turn", "200"],
     "--max-turn 200.0 must be in (0, 180]"),
    # not finite: these said "--sensor-range inf must be > 0", true of inf
    (["--vehicle", "field", "--sensor-range", "inf"],
     "--sensor-range inf must be a finite number > 0\n"),
    (["--vehicle", "field", "--step", "nan"], "--step nan must be a finite number > 0\n"),
    (["--vehicle", "lattice", "--speed", "inf"], "--speed inf must be a finite positive number"),
    (["--vehicle", "field", "--field-mode", "arc", "--max-turn", "nan"],
     "--max-turn nan must be a finite number in (0, 180] degrees"),
    (["--vehicle", "dubins", "--radius", "inf"], "--radius inf must be a finite number > 0"),
])
def test_each_vehicle_option_is_named_alone(monkeypatch, capsys, city, args, words):
    # these were one message naming every option at once, in the library's units
    code, _, err = run(monkeypatch, capsys, "fly", city, "--frame", "local", "--start",
                       "0,0", "--goal", "50,50", *args)
    assert code == 2 and words in err and err.count("\n") == 1, err


CITY = str(ROOT / "examples" / "city.csv")
NED = ["fly", CITY, "--frame", "ned", "--altitude", "10", "--start", "0,0", "--goal",
       "120,-180"]


@pytest.mark.parametrize("args, words", [
    (["--radius", "50"], "--vehicle step does not use --radius (for dubins)"),
    (["--radius", "10"], "--vehicle step does not use --radius (for dubins)"),  # the default
    (["--step", "2"], "--vehicle step does not use --step (for dubins and field)"),
    (["--no-escape"], "--vehicle step does not use --no-escape (for field)"),
    (["--radius", "5", "--speed", "2"],
     "--vehicle step does not use --radius (for dubins) or --speed (for lattice)"),
    (["--vehicle", "dubins", "--speed", "2"], "--vehicle dubins does not use --speed (for "
                                              "lattice)"),
    (["--vehicle", "dubins", "--field-mode", "arc"], "--vehicle dubins does not use "
                                                     "--field-mode (for field)"),
    (["--vehicle", "lattice", "--reverse"], "--vehicle lattice does not use --reverse (for "
                                            "dubins)"),
    (["--vehicle", "lattice", "--goal-heading", "90"], "--vehicle lattice does not use "
                                                       "--goal-heading (for dubins)"),
    (["--vehicle", "field", "--planner", "moves"], "--vehicle field does not use --planner "
                                                   "(for step and dubins)"),
    (["--vehicle", "field", "--targets", "t.csv"], "--vehicle field does not use --targets "
                                                   "(for dubins)"),
    (["--vehicle", "field", "--start-heading", "0"], "--vehicle field does not use "
                                                     "--start-heading (for dubins and "
                                                     "lattice)"),
])
def test_an_option_the_vehicle_does_not_use_is_an_error(monkeypatch, capsys, tmp_path, args,
                                                        words):
    # e.g. --radius with the step drone was silently ignored
    out = tmp_path / "t.json"
    code, text, err = run(monkeypatch, capsys, *NED, *args, "--out", str(out))
    assert code == 2 and err == f"skyroute: error: {words}\n" and text == ""
    assert not out.exists()


@pytest.mark.parametrize("args, words", [
    (["--vehicle", "field", "--max-turn", "30"], "--field-mode step does not use --max-turn"),
    (["--vehicle", "dubins", "--planner", "waypoints", "--reverse", "--approach", "5"],
     "--planner waypoints does not use --approach or --reverse"),
    (["--vehicle", "dubins", "--planner", "waypoints", "--max-expansions", "9"],
     "--planner waypoints does not use --max-expansions"),
    (["--vehicle", "dubins", "--targets", "t.csv", "--planner", "hybrid", "--goal-heading",
      "90"], "--targets does not use --planner or --goal-heading"),
    (["--vehicle", "field", "--field-mode", "arcs"], "--field-mode 'arcs' is not valid"),
])
def test_an_option_the_mode_does_not_use_is_an_error(monkeypatch, capsys, tmp_path, args,
                                                     words):
    # e.g. --max-turn without --field-mode arc, or --reverse with --planner waypoints, was
    # silently ignored
    out = tmp_path / "t.json"
    code, text, err = run(monkeypatch, capsys, *NED, *args, "--out", str(out))
    assert code == 2 and err.startswith(f"skyroute: error: {words}") and text == "", err
    assert err.count("\n") == 1 and not out.exists()


def test_each_mode_table_entry_names_options_its_vehicle_takes():
    from skyroute.cli.fly_cmd import MODE_FLAG, TAKEN_BY, UNUSED_IN_MODE

    for (vehicle, mode), names in UNUSED_IN_MODE.items():
        assert mode in MODE_FLAG
        for name in names:
            assert vehicle in TAKEN_BY[name], (vehicle, mode, name)


@pytest.mark.parametrize("args, words", [
    (["--start", "0,0,90", "--goal", "120,-180"],
     "--start '0,0,90': --vehicle step does not use a start heading (for dubins and "
     "lattice)"),
    (["--vehicle", "field", "--start", "0,0,90", "--goal", "120,-180"],
     "--vehicle field does not use a start heading"),
    (["--vehicle", "lattice", "--start", "0,0", "--goal", "120,-180,90"],
     "--goal '120,-180,90': --vehicle lattice does not use a goal heading (for dubins)"),
])
def test_a_typed_heading_the_vehicle_does_not_use_is_an_error(monkeypatch, capsys, args,
                                                              words):
    code, text, err = run(monkeypatch, capsys, *NED[:4], *args)
    assert code == 2 and words in err and err.count("\n") == 1 and text == "", err


def test_every_vehicle_option_is_an_option_of_fly_and_says_whom_it_is_for():
    from skyroute.cli.fly_cmd import TAKEN_BY, VEHICLES

    cmd = typer.main.get_command(app).get_command(None, "fly")
    params = {p.name: p for p in cmd.params}
    for name, takers in TAKEN_BY.items():
        assert name in params and set(takers) < set(VEHICLES), name
        assert params[name].help.startswith(", ".join(takers) + ": "), name


def test_cli_md_lists_the_vehicle_options_as_the_table_does():
    import re

    from skyroute.cli.fly_cmd import TAKEN_BY

    text = (ROOT / "docs" / "cli.md").read_text()
    table = text[text.index("| option | vehicles |"):].split("\n\n")[0].splitlines()[2:]
    listed = {}
    for row in table:
        flags, vehicles = row.strip("|").split("|")
        for flag in re.findall(r"`--([a-z-]+)", flags):
            listed[flag.replace("-", "_")] = tuple(re.findall(r"`([a-z]+)`", vehicles))
    assert listed == TAKEN_BY


def test_the_table_gives_each_metric_its_unit(monkeypatch, capsys, city):
    """plan-world's table said "cost 221.383540 m"; fly's said "length 230.877" and
    "time 233.877" with no unit, and "expanded 12881" without separators."""
    code, text, err = run(monkeypatch, capsys, "fly", city, "--frame", "ned", "--vehicle",
                          "lattice", "--start", "0,0", "--goal", "120,-180", "--altitude",
                          "10", "--safety", "2", "--resolution", "2")
    assert code == 0, err
    code, doc, err = run(monkeypatch, capsys, "fly", city, "--frame", "ned", "--vehicle",
                         "lattice", "--start", "0,0", "--goal", "120,-180", "--altitude",
                         "10", "--safety", "2", "--resolution", "2", "--json")
    m = json.loads(doc)["metrics"]
    rows = {line.split("│")[1].strip(): line.split("│")[2].strip()
            for line in text.splitlines() if line.count("│") == 3}
    assert rows["length"] == f"{m['length']:,.6f} m" and rows["time"] == f"{m['time']:,.3f} s"
    assert rows["smoothness"] == f"{m['smoothness']:.4f} rad/move"
    assert m["expanded"] >= 1000 and rows["expanded"] == f"{m['expanded']:,}"
    assert rows["moves"] == str(m["moves"]) and rows["status"] == "found"


def test_a_field_escape_raster_too_large_names_step_not_resolution(monkeypatch, capsys,
                                                                   tmp_path):
    # the robot trapped in a U, its goal 14 km away: "--resolution 1 over a 10057 x 10070
    # extent makes ...; use a coarser resolution", an option --vehicle field refuses
    city = tmp_path / "u.csv"
    city.write_text("lat0 37.792480, lon0 -122.397450\nposX,posY,posZ,halfSizeX,halfSizeY,"
                    "halfSizeZ\n30,30,5,2,15,5\n43,17,5,15,2,5\n43,43,5,15,2,5\n")
    code, out, err = run(monkeypatch, capsys, "fly", str(city), "--frame", "ned",
                         "--vehicle", "field", "--start", "36,30", "--goal=-10000,-10000",
                         "--altitude", "1")
    assert (code, out) == (2, "") and err.count("\n") == 1, err
    assert err.startswith("skyroute: error: --step 1 makes the escape's raster") and \
        "use a larger step" in err, err


def test_field_arc_mode_escapes_a_blocked_start_and_says_why_without(monkeypatch, capsys):
    """examples/city.csv, a start 9 cm from a building facing it: the arc and its half
    are blocked, and `fly --vehicle field --field-mode arc` ended stuck after one move
    with 0 escape moves although the escape was on; it now takes the escape. With
    --no-escape the table and --json say why the goal was not reached."""
    args = ["fly", str(ROOT / "examples" / "city.csv"), "--frame", "ned", "--vehicle",
            "field", "--field-mode", "arc", "--start=-161.5762,16.8255", "--goal",
            "12.4584,86.6758", "--altitude", "10", "--safety", "2", "--json"]
    code, text, err = run(monkeypatch, capsys, *args)
    assert code == 0, err
    doc = json.loads(text)
    assert doc["reached"] and doc["metrics"]["escape_moves"] > 0
    assert "why" not in doc["metrics"]
    code, text, err = run(monkeypatch, capsys, *args, "--no-escape")
    assert code == 1
    m = json.loads(text)["metrics"]
    assert m["status"] == "stuck" and m["why"] == ("the arc along the field and its half "
                                                   "are blocked and the escape is off")


def test_dubins_out_writes_the_goal_once(monkeypatch, capsys, tmp_path):
    """A Hybrid A* path on examples/city.csv ending with a 2e-18 m arc: `fly --out`
    wrote the goal twice (the second row 5e-14 m from the first)."""
    out = tmp_path / "d.csv"
    code, _, err = run(monkeypatch, capsys, "fly", str(ROOT / "examples" / "city.csv"),
                       "--frame", "enu", "--vehicle", "dubins", "--radius", "8",
                       "--start=-35.7,-168.98", "--goal=-81.52,-27.41", "--altitude", "10",
                       "--safety", "2", "--out", str(out))
    assert code == 0, err
    rows = np.array(list(csv.reader(out.open()))[1:], dtype=float)
    assert rows[-1, :2].tolist() == [-81.52, -27.41]
    assert (np.hypot(*np.diff(rows[:, :2], axis=0).T) > 1e-6).all()


def _strict(text: str) -> dict:
    """JSON as RFC 8259 has it: Infinity and NaN refused (as jq and JSON.parse do)."""
    def refuse(name):
        raise ValueError(f"{name} is not JSON")
    return json.loads(text, parse_constant=refuse)


@pytest.mark.shared_data
@pytest.mark.parametrize("mode", ["step", "arc"])
def test_field_defaults_fly_in_the_degrees_frame(monkeypatch, capsys, mode):
    """`fly --vehicle field --frame degrees` with the defaults on the ILP zones: --step 1
    and --sensor-range 6 were degrees (the confinement area is 0.008 degrees across),
    so the goal was "reached" at once, 0 moves. The defaults are metres taken into
    degrees (1 m and 6 m north, less east): the run flies there in moves of at most a
    metre, from the start as typed to within a metre of the goal, outside the zones;
    its length is plane units, degrees."""
    from pyproj import Geod

    geod = Geod(ellps="WGS84")
    code, text, err = run(monkeypatch, capsys, "fly", ZONES, "--boundary", BOX,
                          "--frame", "degrees", "--vehicle", "field", "--field-mode", mode,
                          "--start=-3.1920,55.9460", "--goal=-3.1850,55.9430", "--json")
    assert code == 0, err
    doc = _strict(text)
    deg = np.array(doc["trajectory"])
    straight = geod.inv(-3.192, 55.946, -3.185, 55.943)[2]
    assert doc["reached"] and doc["metrics"]["moves"] > straight
    assert deg[0].tolist() == [-3.192, 55.946] and geod.inv(*deg[-1], -3.185, 55.943)[2] < 1
    assert straight < geod.line_length(*deg.T) < 1.5 * straight
    world = skyroute.load_world(ZONES, boundary=BOX, frame="degrees")
    assert world.segments_free(deg[:-1], deg[1:]).all()
    assert doc["metrics"]["length"] == pytest.approx(
        float(np.hypot(*np.diff(deg, axis=0).T).sum()))  # plane units: degrees


@pytest.mark.shared_data
def test_dubins_default_radius_in_the_degrees_frame_is_10_m(monkeypatch, capsys):
    """`fly --vehicle dubins --frame degrees` without --radius: the default was 10
    degrees (1,100 km round a city of 700 m: no_path); it is 10 m taken into degrees,
    and its --step 1 m too. A given --radius stays plane units: 10 is still 10 degrees,
    no path (its --json length null, not Infinity)."""
    from pyproj import Geod

    query = ["fly", ZONES, "--boundary", BOX, "--frame", "degrees", "--vehicle", "dubins",
             "--start=-3.1920,55.9460", "--goal=-3.1850,55.9430", "--json"]
    code, text, err = run(monkeypatch, capsys, *query)
    assert code == 0, err
    doc = _strict(text)
    deg = np.array(doc["trajectory"])
    assert doc["reached"] and doc["metrics"]["status"] == "found"
    metres = Geod(ellps="WGS84").line_length(*deg[:, :2].T)
    assert metres < 1.2 * Geod(ellps="WGS84").inv(-3.192, 55.946, -3.185, 55.943)[2]
    steps = np.hypot(*np.diff(deg[:, :2], axis=0).T)
    assert steps.max() <= 1.0 / 111_000  # samples of at most 1 m north
    code, text, _ = run(monkeypatch, capsys, *query, "--radius", "10")
    doc = _strict(text)  # its length is null, not Infinity
    assert code == 1 and doc["metrics"]["status"] == "no_path"
    assert doc["metrics"]["length"] is None




@pytest.mark.shared_data
def test_lattice_default_speed_in_the_degrees_frame_is_1_m_per_s(monkeypatch, capsys):
    """`fly --vehicle lattice --frame degrees` without --speed: the default was 1 degree
    per second (111 km/s: a 300 m route took 4 s, its turns 4 of them); it is 1 m/s
    taken into degrees, so the route takes at least its length over 1 m/s north."""
    code, text, err = run(monkeypatch, capsys, "fly", ZONES, "--boundary", BOX,
                          "--frame", "degrees", "--vehicle", "lattice",
                          "--start=-3.1920,55.9460", "--goal=-3.1890,55.9445", "--json")
    assert code == 0, err
    m = _strict(text)["metrics"]
    assert m["time"] >= m["length"] * 111_000  # degrees over 1/111,341 degrees a second


WALL = ("lat0 55.9, lon0 -3.1\nposX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n"
        "0,0,10,1,500,10\n")  # a wall 2 m thick across the whole boundary box below
WALLED = ["--frame", "ned", "--start", "5,0", "--boundary=-3.1010,55.8995,-3.0990,55.9005"]


@pytest.mark.parametrize("args, status", [
    (["--vehicle", "dubins", "--goal=-5,0"], "no_path"),
    (["--vehicle", "dubins", "--planner", "waypoints", "--goal=-5,0"], "no_path"),
    (["--vehicle", "dubins", "--targets", "TARGETS"], "no_path"),
    (["--vehicle", "lattice", "--goal=-5,0"], "no_path"),
])
def test_a_flight_not_found_says_its_status_and_prints_no_infinity(monkeypatch, capsys,
                                                                   tmp_path, args, status):
    """A goal behind a wall that closes the boundary: the table read "length inf m"
    (and a tour's "greedy bound inf m", "bound inf m" and an empty "order"), and the
    lattice and the waypoints planner gave no status at all, only a why ("no lattice
    route: no_path"). Each now reports its status, in the table and in --json, and the
    table leaves out what a flight not found has no value for (--json: null)."""
    world = tmp_path / "wall.csv"
    world.write_text(WALL)
    targets = tmp_path / "targets.csv"
    targets.write_text("north,east\n20,0\n-20,0\n")  # the second behind the wall
    args = [str(targets) if a == "TARGETS" else a for a in args]
    code, text, err = run(monkeypatch, capsys, "fly", str(world), *WALLED, *args)
    assert code == 1, err
    rows = {line.split("│")[1].strip(): line.split("│")[2].strip()
            for line in text.splitlines() if line.count("│") == 3}
    assert rows["status"] == status and rows["reached"] == "False"
    assert not any(v == "" or "inf" in v.split() for v in rows.values()), rows
    code, text, err = run(monkeypatch, capsys, "fly", str(world), *WALLED, *args, "--json")
    assert code == 1, err
    doc = json.loads(text)
    assert doc["reached"] is False and doc["metrics"]["status"] == status
    assert "length" not in doc["metrics"] or doc["metrics"]["length"] is None
