"""``skyroute plan-world`` end to end: outputs and one-line errors."""

import json

import pytest

from tests.cli.test_cli import run
from tests.conftest import ROOT, SHARED

FCND = str(SHARED / "fcnd" / "colliders.csv")
ZONES = str(SHARED / "ilp2021" / "website" / "buildings" / "no-fly-zones.geojson")
BOX = str(SHARED / "ilp2021" / "testing" / "confinement-zone.geojson")


@pytest.mark.shared_data
def test_fcnd_json_waypoints_geojson_plot(monkeypatch, capsys, tmp_path):
    wp, gj, png = tmp_path / "wp.json", tmp_path / "p.geojson", tmp_path / "p.png"
    code, out, err = run(monkeypatch, capsys, "plan-world", FCND, "--start=-122.397450,37.792480",
                         "--goal=-122.396428,37.795232", "--altitude", "5", "--safety", "5",
                         "--json", "--waypoints", str(wp), "--geojson", str(gj), "--plot",
                         str(png))
    assert code == 0, err
    doc = json.loads(out)
    assert list(doc) == ["status", "cost", "frame", "path", "path_local", "path_lonlat",
                         "expanded", "seconds", "setup_seconds", "algorithm"]
    assert doc["setup_seconds"] > 0  # the graph, apart from the search (a new world)
    assert doc["frame"] == "lonlat" and doc["path"] == doc["path_lonlat"]
    assert doc["status"] == "found" and doc["path_local"][0] == pytest.approx([0, 0], abs=1e-6)
    assert doc["path_lonlat"][-1] == pytest.approx([-122.396428, 37.795232], abs=1e-9)
    waypoints = json.loads(wp.read_text())
    assert waypoints[0][:3] == pytest.approx([0, 0, 5], abs=1e-6) and len(waypoints[0]) == 4
    assert json.loads(gj.read_text())["features"][0]["geometry"]["coordinates"][0] == \
        pytest.approx([-122.397450, 37.792480], abs=1e-9)
    assert png.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.shared_data
def test_local_frame_and_degrees_frame(monkeypatch, capsys):
    code, out, _ = run(monkeypatch, capsys, "plan-world", FCND, "--frame", "local",
                       "--start", "0,0", "--goal", "305.45,90.01", "--altitude", "5",
                       "--safety", "5", "--json")
    assert code == 0 and json.loads(out)["path_local"][-1] == pytest.approx([305.45, 90.01])
    code, out, _ = run(monkeypatch, capsys, "plan-world", ZONES, "--frame", "degrees",
                       "--boundary", BOX, "--start=-3.186874,55.944494",
                       "--goal=-3.1913,55.9455", "--json")
    doc = json.loads(out)
    assert code == 0 and doc["path_local"] == doc["path_lonlat"] and doc["cost"] < 0.01


@pytest.mark.shared_data
@pytest.mark.parametrize("args, words", [
    (["--start=-3.1950,55.944", "--goal=-3.1913,55.9455"], "start (-3.1950000, 55.9440000) lies "
     "outside the map"),
    (["--start=-3.1885,55.9450", "--goal=-3.1913,55.9455"], "lies inside obstacle"),
    (["--start=abc", "--goal=-3.1913,55.9455"], "--start 'abc' must be two numbers LON,LAT"),
    (["--start=-3.186874,55.944494", "--goal=-3.1913,55.9455", "--algorithm", "rrt"],
     "--algorithm 'rrt' is not valid"),
    # options the algorithm does not read were ignored, as skyroute.plan now refuses them
    (["--start=-3.186874,55.944494", "--goal=-3.1913,55.9455", "--samples", "50"],
     "--algorithm visibility does not use --samples (--samples and --seed: prm; "
     "--resolution: the grid algorithms)"),
    (["--start=-3.186874,55.944494", "--goal=-3.1913,55.9455", "--algorithm", "astar",
      "--seed", "3", "--samples", "9"], "--algorithm astar does not use --samples or --seed"),
    (["--start=-3.186874,55.944494", "--goal=-3.1913,55.9455", "--algorithm", "prm",
      "--resolution", "0.001"], "--algorithm prm does not use --resolution"),
])
def test_bad_queries_are_one_line_exit_2(monkeypatch, capsys, tmp_path, args, words):
    png = tmp_path / "p.png"
    code, out, err = run(monkeypatch, capsys, "plan-world", ZONES, "--frame", "degrees",
                         "--boundary", BOX, *args, "--plot", str(png))
    assert code == 2 and err.count("\n") == 1 and words in err and not png.exists()
    assert out == ""


def test_missing_home_line_is_one_line_exit_2(monkeypatch, capsys, tmp_path):
    bad = tmp_path / "c.csv"
    bad.write_text("posX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n1,2,3,4,5,6\n")
    code, _, err = run(monkeypatch, capsys, "plan-world", str(bad), "--start=0,0",
                       "--goal=1,1")
    assert code == 2 and f"{bad}:1: expected 'lat0 <deg>, lon0 <deg>'" in err


@pytest.mark.parametrize("blocks, words", [
    ("1000000000", "--blocks 1000000000 must be a whole number from 1 to 100"),
    ("0", "--blocks 0 must be a whole number from 1 to 100"),
])
def test_synth_city_refuses_a_city_too_large_or_empty(monkeypatch, capsys, tmp_path, blocks,
                                                      words):
    out = tmp_path / "c.csv"
    code, text, err = run(monkeypatch, capsys, "synth-city", str(out), "--blocks", blocks)
    assert code == 2 and text == "" and words in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_a_city_too_large_for_its_planner_is_one_line_naming_it(monkeypatch, capsys,
                                                                tmp_path):
    from skyroute.motion import corner_distance
    from skyroute.roadmap import visibility

    monkeypatch.chdir(tmp_path)
    city = "sub/c.csv"  # named as given, not by its base name only
    code, _, _ = run(monkeypatch, capsys, "synth-city", city, "--blocks", "3")
    assert code == 0
    monkeypatch.setenv("SKYROUTE_CACHE", str(tmp_path))  # not a graph an earlier test kept
    monkeypatch.setattr(visibility, "MAX_CORNERS", 20)  # the city has about 70
    monkeypatch.setattr(corner_distance, "MAX_CORNERS", 20)
    png = tmp_path / "p.png"
    for args, words in (
            (["plan-world"], "over the limit of 20 for the visibility graph (built over every "
                             "pair of them); plan with prm or on a grid (theta, astar)"),
            (["fly", "--vehicle", "dubins"], "over the limit of 20 for Hybrid A*'s corner "
                                             "distances"),
            (["fly", "--vehicle", "dubins", "--planner", "waypoints"], "visibility graph")):
        code, out, err = run(monkeypatch, capsys, *args, city, "--frame", "ned",
                             "--start", "0,0", "--goal", "60,60", "--plot", str(png))
        assert code == 2 and out == "" and err.count("\n") == 1, err
        assert err.startswith("skyroute: error: sub/c.csv: ") and words in err, err
        assert " obstacle corners, " in err and not png.exists()
    # the same city on a grid is planned
    code, _, err = run(monkeypatch, capsys, "plan-world", city, "--frame", "ned",
                       "--start", "0,0", "--goal", "60,60", "--algorithm", "theta")
    assert code == 0, err


def test_a_colliders_file_of_too_many_boxes_is_one_line(monkeypatch, capsys, tmp_path):
    city = tmp_path / "c.csv"
    city.write_text("lat0 37.792480, lon0 -122.397450\nposX,posY,posZ,halfSizeX,halfSizeY,"
                    "halfSizeZ\n" + "1,1,1,1,1,1\n" * 50_001)
    code, out, err = run(monkeypatch, capsys, "plan-world", str(city), "--frame", "ned",
                         "--start", "0,0", "--goal", "60,60", "--algorithm", "prm")
    assert code == 2 and out == ""
    assert err == (f"skyroute: error: {city}: 50,001 boxes, over the limit of 50,000 in a "
                   "colliders file\n")


@pytest.mark.parametrize("command", [
    ["plan-world", "examples/city.csv", "--frame", "ned", "--start", "0,0", "--goal",
     "120,-180"],
    ["fly", "examples/city.csv", "--frame", "ned", "--vehicle", "lattice", "--start", "0,0",
     "--goal", "120,-180"],
    ["bench", "world", "--city", "examples/city.csv"],
])
def test_a_negative_altitude_is_refused_alike(monkeypatch, capsys, command):
    # bench world refused --altitude -5; plan-world and fly kept no building of the city
    # (they all stand on the ground) and planned straight through them, exit 0
    monkeypatch.chdir(ROOT)
    monkeypatch.setattr("skyroute.cli.bench_world_cmd._bench_world", _no_run)
    code, out, err = run(monkeypatch, capsys, *command, "--altitude", "-5")
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, err
    assert "skyroute: error: --altitude -5.0 must be a finite number >= 0" in err


def _no_run(*_args, **_kwargs):
    raise AssertionError("ran with a negative altitude")


def test_load_world_refuses_a_negative_altitude():
    import skyroute
    from skyroute.errors import OptionError

    with pytest.raises(OptionError, match=r"altitude=-0\.5 must be a finite number >= 0") as info:
        skyroute.load_world(ROOT / "examples" / "city.csv", altitude=-0.5)
    assert info.value.param == "altitude"
    assert len(skyroute.load_world(ROOT / "examples" / "city.csv", altitude=0).obstacles) > 0


@pytest.mark.parametrize("command", [["plan", "examples/city.csv", "--start", "0,0", "--goal",
                                      "5,5"],
                                     ["prepare", "examples/city.csv", "-o", "city.idx"]])
def test_a_colliders_city_given_as_a_grid_map_points_to_plan_world(monkeypatch, capsys,
                                                                   tmp_path, command):
    # it said "examples/city.csv:1: expected 4 columns x1,y1,x2,y2, got 2" and no more
    monkeypatch.chdir(ROOT)
    command = [str(tmp_path / c) if c == "city.idx" else c for c in command]
    code, out, err = run(monkeypatch, capsys, *command)
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, err
    assert err.strip() == (
        "skyroute: error: examples/city.csv:1: a colliders.csv city (line 1 'lat0 ..., lon0 "
        "...'), not wall segments x1,y1,x2,y2: plan in it with 'skyroute plan-world "
        "examples/city.csv --start LON,LAT --goal LON,LAT'")
    assert not (tmp_path / "city.idx").exists()


GRID_MAPS = {  # a grid map given as WORLD: what the error calls it
    "walls.csv": ("x1,y1,x2,y2\n0,0,10,0\n", ":1: wall segments x1,y1,x2,y2 (a grid map)"),
    "commented.csv": ("# walls\n0,0,10,0\n", ":1: wall segments x1,y1,x2,y2 (a grid map)"),
    "bare.csv": ("0,0,10,0\n", ":1: wall segments x1,y1,x2,y2 (a grid map)"),
    "m.map": ("type octile\nheight 1\nwidth 1\nmap\n.\n", ": a grid map (.map), not a world"),
    "m.npy": ("", ": a grid map (.npy), not a world"),
    "m.png": ("", ": a grid map (.png), not a world"),
}


@pytest.mark.parametrize("command", [["plan-world"], ["fly", "--vehicle", "field"]])
@pytest.mark.parametrize("name", [*GRID_MAPS, "den312d"])
def test_a_grid_map_is_sent_to_skyroute_plan(monkeypatch, capsys, tmp_path, command, name):
    # plan sends a colliders city to plan-world; plan-world and fly said "unknown world
    # type '.map'" or "expected 'lat0 <deg>, lon0 <deg>', got 'x1,y1,x2,y2'"
    monkeypatch.chdir(tmp_path)
    text, words = GRID_MAPS.get(name, ("", ": no such file, but the name of a bundled grid map"))
    if name in GRID_MAPS:
        (tmp_path / name).write_text(text)
    code, out, err = run(monkeypatch, capsys, *command[:1], name, *command[1:],
                         "--start", "1,1", "--goal", "2,2")
    assert code == 2 and out == "" and err.count("\n") == 1, err
    assert err.startswith(f"skyroute: error: {name}{words}"), err
    assert err.endswith(f": plan on it with 'skyroute plan {name} --start X,Y --goal X,Y'\n")


def test_load_world_names_load_map_for_a_grid_map(tmp_path):
    import skyroute
    from skyroute.errors import GridNotWorldError

    (tmp_path / "w.csv").write_text("x1,y1,x2,y2\n0,0,10,0\n")
    with pytest.raises(GridNotWorldError, match=r"w.csv:1: wall segments .*: load it with "
                                                r"skyroute.load_map$"):
        skyroute.load_world(tmp_path / "w.csv")


@pytest.mark.parametrize("command", [["plan-world"], ["fly", "--vehicle", "dubins"],
                                     ["fly", "--vehicle", "field"]])
@pytest.mark.parametrize("point, words", [
    ("38,50", "start (38.00, 50.00) lies outside obstacle 'box at line 3' but within its "
              "--safety 5 m margin; nearest free point (34.99, 50.00)"),
    ("45,50", "start (45.00, 50.00) lies inside obstacle 'box at line 3'; nearest free "
              "point (34.99, 50.00)"),
])
def test_a_point_blocked_only_by_the_safety_margin_says_so(monkeypatch, capsys, tmp_path,
                                                           command, point, words):
    """A start 2 m south of a building (N 40-60, E 40-60) with --safety 5 read "lies
    inside obstacle 'box at line 3'", as if the building stood there; inside the
    building itself the words stay."""
    city = tmp_path / "city.csv"
    city.write_text("lat0 37.792480, lon0 -122.397450\n"
                    "posX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n50,50,20,10,10,20\n",
                    encoding="utf-8")
    code, out, err = run(monkeypatch, capsys, *command[:1], str(city), *command[1:],
                         "--frame", "ned", "--safety", "5", "--start", point,
                         "--goal", "100,100")
    assert code == 2 and out == ""
    assert err == f"skyroute: error: {words}\n"


def test_a_target_blocked_only_by_the_safety_margin_says_so(monkeypatch, capsys, tmp_path):
    city, targets = tmp_path / "city.csv", tmp_path / "targets.csv"
    city.write_text("lat0 37.792480, lon0 -122.397450\n"
                    "posX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n50,50,20,10,10,20\n",
                    encoding="utf-8")
    targets.write_text("0,50\n50,62\n", encoding="utf-8")
    code, out, err = run(monkeypatch, capsys, "fly", str(city), "--vehicle", "dubins",
                         "--frame", "ned", "--safety", "5", "--start", "0,0",
                         "--targets", str(targets))
    assert code == 2 and out == ""
    assert err == ("skyroute: error: targets.csv: target 2 (50.00, 62.00) lies outside "
                   "obstacle 'box at line 3' but within its --safety 5 m margin; nearest "
                   "free point (50.00, 65.01)\n")


ROOM = ("lat0 37.792480, lon0 -122.397450\nposX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n"
        "-11,0,10,1,12,10\n11,0,10,1,12,10\n0,-11,10,10,1,10\n"
        "-5.25,11,10,4.75,1,10\n5.25,11,10,4.75,1,10\n")  # a room, a 1 m door east


def test_a_prm_that_misses_a_path_says_one_may_still_exist(monkeypatch, capsys, tmp_path):
    # the table said only "no_path" (exit 1) where the visibility graph finds 44.4 m:
    # 1,000 samples missed 5 of 44 random pairs of the FCND city so
    room = tmp_path / "room.csv"
    room.write_text(ROOM)
    common = [str(room), "--frame", "ned", "--start=5,-5", "--goal=-20,30", "--altitude", "5"]
    code, out, _ = run(monkeypatch, capsys, "plan-world", *common, "--algorithm", "prm",
                       "--samples", "20")
    assert code == 1 and "no_path" in out
    words = " ".join(out.replace("│", " ").split())  # the table's folded cell, one line
    assert ("why the roadmap of 20 samples (seed 0) joins no path from start to goal; one "
            "may still exist: more --samples, another --seed, or --algorithm visibility "
            "(exact) may find it") in words, out
    code, out, _ = run(monkeypatch, capsys, "plan-world", *common)
    assert code == 0 and "44.405277 m" in out and "why" not in out
