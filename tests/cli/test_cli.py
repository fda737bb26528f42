"""The CLI through its real entry point: output, exit codes, one-line errors, no partial files."""

import json
import sys
from pathlib import Path

import pytest

from skyroute.cli.app import main

QUERY = ["den312d", "--start", "50,76", "--goal", "60,13"]


def run(monkeypatch, capsys, *args):
    monkeypatch.setattr(sys, "argv", ["skyroute", *args])
    with pytest.raises(SystemExit) as exit_info:
        main()
    out, err = capsys.readouterr()
    return exit_info.value.code, out, err


def test_plan_json_and_files(monkeypatch, capsys, tmp_path):
    png, gj = tmp_path / "out" / "p.png", tmp_path / "p.geojson"
    code, out, err = run(monkeypatch, capsys, "plan", *QUERY, "--json", "--plot", str(png),
                         "--geojson", str(gj))
    assert code == 0, err
    doc = json.loads(out)
    assert list(doc) == ["status", "cost", "path", "expanded", "max_frontier", "los_checks",
                         "seconds", "algorithm"]
    assert doc["status"] == "found" and doc["algorithm"] == "astar"
    assert doc["cost"] == pytest.approx(112.55634918, abs=1e-8)  # den312d.map.scen, last line
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    feature = json.loads(gj.read_text())["features"][0]
    assert feature["geometry"]["type"] == "LineString"
    assert feature["geometry"]["coordinates"][0] == [50.5, 76.5]  # cell centre, metres
    assert feature["properties"]["cost"] == doc["cost"]


@pytest.mark.parametrize("name", ["a[/]b.png", "x[bold]y.png"])
def test_names_print_as_given_not_as_markup(monkeypatch, capsys, tmp_path, name):
    """A file name is data: Rich markup read '[/]' as a closing tag (a MarkupError
    traceback after the picture was written) and dropped '[bold]' from the name shown."""
    png = tmp_path / name
    code, out, err = run(monkeypatch, capsys, "plan", *QUERY, "--plot", str(png))
    assert code == 0, err
    assert png.exists() and name in out and not err


def test_plan_table_and_prune(monkeypatch, capsys):
    import skyroute

    code, out, _ = run(monkeypatch, capsys, "plan", *QUERY, "--algorithm", "theta",
                       "--prune", "los")
    assert code == 0
    r = skyroute.plan(skyroute.load_map("den312d"), (50, 76), (60, 13), algorithm="theta",
                      prune="los")
    rows = {line.split("│")[1].strip(): line.split("│")[2].strip()
            for line in out.splitlines() if line.count("│") == 3}
    assert "den312d.map: theta" in out and rows["status"] == "found"
    assert rows["cost"] == f"{r.cost:.6f} cells" and rows["waypoints"] == str(len(r.path))
    assert rows["expanded"] == f"{r.expanded:,}"
    assert rows["line-of-sight checks"] == f"{r.los_checks:,}"


def test_no_path_exits_1_and_writes_nothing(monkeypatch, capsys, tmp_path):
    np_file = tmp_path / "wall.npy"
    import numpy as np

    a = np.zeros((3, 5))
    a[:, 2] = 1
    np.save(np_file, a)
    png = tmp_path / "p.png"
    code, out, _ = run(monkeypatch, capsys, "plan", str(np_file), "--start", "0,0", "--goal",
                       "4,0", "--json", "--plot", str(png))
    assert code == 1 and json.loads(out)["status"] == "no_path"
    assert not png.exists()


ROOM = "x1,y1,x2,y2\n0,0,20,0\n20,0,20,10\n20,10,0,10\n0,10,0,0\n8,0,8,6\n"


def test_a_walls_cell_is_the_same_place_with_any_safety(monkeypatch, capsys, tmp_path):
    """--safety moved the raster's origin: cell (5, 5) at 0.5 m a cell started the path at
    (2.25, 2.25) m, and with --safety 1 at (1.25, 1.25) m."""
    import shapely

    walls = tmp_path / "walls.csv"
    walls.write_text(ROOM)
    paths = {}
    for safety in ("0", "1"):
        gj = tmp_path / f"s{safety}.geojson"
        code, _, err = run(monkeypatch, capsys, "plan", str(walls), "--start", "5,5",
                             "--goal", "30,5", "--resolution", "0.5", "--safety", safety,
                             "--geojson", str(gj))
        assert code == 0, err
        paths[safety] = json.loads(gj.read_text())["features"][0]["geometry"]["coordinates"]
    assert paths["0"][0] == paths["1"][0] == [2.25, 2.25]
    assert paths["0"][-1] == paths["1"][-1] == [14.75, 2.25]
    # the margin holds in metres: no waypoint of the path comes within 1 m of a wall
    segments = shapely.multilinestrings(
        [[[(x1, y1), (x2, y2)] for x1, y1, x2, y2 in
          (map(float, row.split(",")) for row in ROOM.splitlines()[1:])]])
    assert shapely.distance(shapely.points(paths["1"]), segments).min() > 1.0
    assert shapely.distance(shapely.points(paths["0"]), segments).min() < 1.0


@pytest.mark.parametrize("far, option, words", [
    ("0,0,1e9,3", [], "walls.csv:3: the wall (0, 0) - (1e+09, 3) stretches the map to"),
    ("1,1,2,2", ["--resolution", "0"], "error: --resolution 0.0 must be a positive number\n"),
])
def test_a_walls_raster_too_large_names_the_line_or_the_flag(monkeypatch, capsys, tmp_path,
                                                             far, option, words):
    # it was "--resolution 1 over a 1e+09 x 7 extent makes ...; use a coarser resolution",
    # with neither the file nor the line; a zero resolution spoke of "resolution=0.0"
    p = tmp_path / "walls.csv"
    p.write_text(f"0,0,10,0\n0,5,10,5\n{far}\n")
    code, out, err = run(monkeypatch, capsys, "plan", str(p), "--start", "1,1", "--goal",
                         "5,3", *option)
    assert code == 2 and out == "" and err.count("\n") == 1
    assert err.startswith("skyroute: error: ") and words in err


@pytest.mark.parametrize("suffix", [".geojson", ".json"])
def test_a_geojson_world_given_to_plan_points_to_plan_world(monkeypatch, capsys, tmp_path,
                                                            suffix):
    # it said "unknown map type '.geojson'; valid: .map, .csv, ...", naming no way on
    zones = tmp_path / f"no-fly-zones{suffix}"
    zones.write_text('{"type": "FeatureCollection", "features": []}')
    code, out, err = run(monkeypatch, capsys, "plan", str(zones), "--start", "1,1", "--goal",
                         "2,2")
    assert code == 2 and out == "" and err == (
        f"skyroute: error: {zones}: GeoJSON zones ({suffix}), a world, not a grid map (.map, "
        f".csv walls, .npy, an image): plan in it with 'skyroute plan-world {zones} --start "
        "LON,LAT --goal LON,LAT'\n")


def test_a_walls_cell_within_the_margin_is_named_so(monkeypatch, capsys, tmp_path):
    walls = tmp_path / "walls.csv"
    walls.write_text(ROOM)
    code, out, err = run(monkeypatch, capsys, "plan", str(walls), "--start", "5,5", "--goal",
                         "15,5", "--resolution", "0.5", "--safety", "1")
    assert code == 2 and out == "" and err == (
        "skyroute: error: goal (15, 5) is free in walls.csv but within the --safety 1 m "
        "margin of an obstacle; choose a cell farther from it or a smaller --safety\n")


@pytest.mark.parametrize("args, words", [
    (["plan", "den312d", "--start", "0,0", "--goal", "60,13"], "start (0, 0) is on a blocked"),
    (["plan", "den312d", "--start", "50,76", "--goal", "99,9"], "goal (99, 9) lies outside"),
    # a cell typed (row, column), numpy's order: the swapped cell is free, and the
    # error says so (a lon/lat world says it of (lat, lon)); a cell off the map either
    # way gets no hint (above)
    (["plan", "den312d", "--start", "76,50", "--goal", "60,13"], "error: start (76, 50) lies "
     "outside the 65x81 grid (x in 0..64, y in 0..80); (50, 76) is free: cells are "
     "(x, y) = (column, row)\n"),
    # ... but not when the swapped cell is blocked too: it pointed to (0, 65), a wall
    (["plan", "den312d", "--start", "65,0", "--goal", "60,13"], "error: start (65, 0) lies "
     "outside the 65x81 grid (x in 0..64, y in 0..80)\n"),
    # on a blocked cell, the slip a square map shows: (60, 13) is free
    (["plan", "den312d", "--start", "50,76", "--goal", "13,60"], "error: goal (13, 60) is "
     "on a blocked cell; (60, 13) is free: cells are (x, y) = (column, row)\n"),
    (["plan", "nope.map", "--start", "0,0", "--goal", "1,1"], "nope.map: no such file"),
    # a cell the map has free, blocked by the margin alone: it read "is on a blocked cell"
    (["plan", *QUERY, "--safety", "3"], "error: start (50, 76) is free in den312d.map but "
     "within the --safety 3 m margin of an obstacle; choose a cell farther from it or a "
     "smaller --safety\n"),
    (["plan", "den312d", "--start", "50,70", "--goal", "60,13", "--safety", "3"],
     "error: goal (60, 13) is free in den312d.map but within the --safety 3 m margin"),
    (["plan", "den312d", "--start", "0,0", "--goal", "60,13", "--safety", "3"],
     "error: start (0, 0) is on a blocked cell\n"),
    # an empty MAP read as the folder '.': ".: a folder, not a map file"
    (["plan", "", "--start", "0,0", "--goal", "1,1"], "error: the MAP argument is empty: "
     "give a map file or a bundled map's name (see 'skyroute maps')\n"),
    (["prepare", "", "-o", "x.idx"], "error: the MAP argument is empty"),
    # and an empty WORLD: ".: unknown world type ''"
    (["plan-world", "", "--start", "0,0", "--goal", "1,1"], "error: the WORLD argument is "
     "empty: give a colliders.csv city or a GeoJSON file of zones\n"),
    (["fly", "", "--start", "0,0", "--goal", "1,1"], "error: the WORLD argument is empty"),
    (["plan", *QUERY, "--algorithm", "foo"], "--algorithm 'foo' is not valid"),
    (["plan", "den312d", "--start", "5;x", "--goal", "1,1"], "--start '5;x' must be"),
    (["plan", *QUERY, "--bogus"], "No such option: --bogus"),
    (["plan", *QUERY, "--clearance", "-1"], "--safety -1.0"),
    # option conflicts spoke of Python's keywords beside the flags: "algorithm='jps' needs
    # connectivity=8 and --corner-cutting False" (a switch that takes no value)
    (["plan", *QUERY, "--algorithm", "jps", "--corner-cutting"],
     "error: --algorithm 'jps' needs --connectivity 8 and no corner cutting\n"),
    (["plan", *QUERY, "--algorithm", "bfs", "--connectivity", "8"],
     "error: --algorithm 'bfs' is 4-connected; use --connectivity 4 or --algorithm 'dijkstra'"),
    (["plan", *QUERY, "--algorithm", "dijkstra", "--weight", "2"],
     "error: --algorithm 'dijkstra' takes no weight; use --algorithm 'astar'\n"),
    # a weight whose f overflowed the heap's int64 keys (silently) is refused
    (["plan", *QUERY, "--weight", "1e13"], "error: --weight 1e+13 is too large for this"),
    (["plan", *QUERY, "--algorithm", "bfs", "--heuristic", "octile"],
     "error: --algorithm 'bfs' takes no heuristic option"),
    (["bench", "grid", "--map", "nomap", "--peers", ""], "--map nomap not found"),
    (["bench", "grid", "--algorithms", "astar,zzz", "--peers", ""], "--algorithms 'zzz'"),
    (["bench", "grid", "--per-map", "-3"], "'--per-map': -3 is not in the range x>=0"),
    (["bench", "world", "--worlds", "-1"], "'--worlds': -1 is not in the range x>=0"),
    (["bench", "world", "--city-queries", "-2"], "'--city-queries': -2 is not in the range"),
    (["bench", "world", "--no-path", "-2"], "'--no-path': -2 is not in the range x>=0"),
    (["bench", "motion", "--curvature", "--tours", "-1"], "'--tours': -1 is not in the"),
    (["bench", "motion", "--max-expansions", "0"], "0 is not in the range x>=1"),
    (["bench", "motion", "--curvature", "--budgets", "0,1"], "every budget must be > 0"),
])
def test_bad_input_is_one_line_and_exit_2(monkeypatch, capsys, tmp_path, args, words):
    monkeypatch.chdir(tmp_path)
    code, out, err = run(monkeypatch, capsys, *args, "--plot", "x.png") if args[0] == "plan" \
        else run(monkeypatch, capsys, *args)
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("skyroute: error: ")
    assert words in err
    assert "Traceback" not in err and out == ""
    assert list(tmp_path.iterdir()) == []


def test_malformed_map_names_file_and_line(monkeypatch, capsys, tmp_path):
    bad = tmp_path / "bad.map"
    bad.write_text("type octile\nheight 2\nwidth 3\nmap\n...\n.?.\n")
    code, _, err = run(monkeypatch, capsys, "plan", str(bad), "--start", "0,0", "--goal", "2,0")
    assert code == 2 and f"{bad}:6: unknown terrain '?' at column 1" in err


def test_maps_lists_bundled(monkeypatch, capsys):
    code, out, _ = run(monkeypatch, capsys, "maps")
    assert code == 0 and "den312d" in out and "65x81" in out


def test_bench_grid_runs_and_reports_missing_peers(monkeypatch, capsys, tmp_path):
    import skyroute.bench.grid as grid_mod

    real = grid_mod.available
    monkeypatch.setattr(grid_mod, "available", lambda p: p != "pathfinding" and real(p))
    out_json = tmp_path / "bench.json"
    code, out, err = run(monkeypatch, capsys, "bench", "grid", "--map", "den312d",
                         "--per-map", "4", "--algorithms", "astar,jps,dijkstra",
                         "--peers", "pathfinding,networkx", "--json", str(out_json))
    assert code == 0, err
    assert "peer pathfinding is not installed" in err
    assert "pip install 'skyroute[bench]'" in " ".join(err.split())  # markup took [bench]
    doc = json.loads(out_json.read_text())
    rows = {r["runner"]: r for r in doc["maps"][0]["rows"]}
    for a in ("astar", "jps", "dijkstra"):
        assert rows[a]["matched"] == 4 and rows[a]["mean_cost_ratio"] == pytest.approx(1.0)
    if "networkx" in rows:  # installed with skyroute[bench]: same rule, so optimal too
        assert rows["networkx"]["matched"] == 4
        assert rows["astar"]["speedup_vs"]["networkx"] == pytest.approx(
            rows["networkx"]["median_ms"] / rows["astar"]["median_ms"])
    assert doc["settings"]["missing_peers"] == ["pathfinding"] + (
        [] if "networkx" in rows else ["networkx"])
    assert "den312d" in out


@pytest.mark.early_process("-m", "skyroute", "plan", "den312d", "--start", "0,0", "--goal",
                           "1,1")
def test_module_entry_point_has_no_traceback(early_process):
    # The one test of the real 'python -m skyroute' process: exit code 2 and a single
    # line on stderr, nothing else (no traceback, no warning at start or exit).
    code, out, err, _ = early_process
    assert code == 2 and out == ""
    assert err == "skyroute: error: start (0, 0) is on a blocked cell\n"


def test_bench_malformed_scen_names_file_and_line(monkeypatch, capsys, tmp_path):
    (tmp_path / "tiny.map").write_text("type octile\nheight 2\nwidth 3\nmap\n...\n...\n")
    scen = tmp_path / "tiny.map.scen"
    scen.write_text("version 1\n0\ttiny.map\t3\t2\t0\t0\t2\t1\t2.41421356\n"
                    "0\ttiny.map\t3\t2\t0\t0\t2\n")
    out_json = tmp_path / "out.json"
    code, out, err = run(monkeypatch, capsys, "bench", "grid", "--maps", str(tmp_path),
                         "--peers", "", "--json", str(out_json))
    assert code == 2 and f"{scen}:3: expected 9 tab-separated columns, got 7" in err
    assert err.count("\n") == 1 and not out_json.exists() and out == ""


def out_blocked_by(tmp_path, blocker: str):
    """An --out folder under ``tmp_path`` that cannot be written: ``"file"`` makes it a
    regular file, any other name a folder of that name inside it (where a file must go)."""
    out = tmp_path / "out"
    if blocker == "file":
        out.write_text("keep me")
    else:
        (out / blocker).mkdir(parents=True)
    return out


_CITY = [str(Path(__file__).parents[2] / "examples" / "city.csv"), "--frame", "ned",
         "--start", "0,0", "--goal", "120,-180"]


@pytest.mark.parametrize("args, first, bad, words", [
    (["plan", *QUERY], "--geojson", ["--plot", "{blocked}/p.png"], "--plot {blocked}/p.png"),
    (["plan", *QUERY], "--geojson", ["--plot", "p.jpg"],
     "--plot p.jpg: pictures are PNG files; name it .png"),
    (["plan-world", *_CITY], "--waypoints", ["--plot", "{blocked}/p.png"],
     "--plot {blocked}/p.png"),
    (["plan-world", *_CITY], "--geojson", ["--waypoints", "{blocked}/w.json"],
     "--waypoints {blocked}/w.json"),
    (["fly", *_CITY, "--vehicle", "field"], "--out", ["--plot", "{blocked}/f.png"],
     "--plot {blocked}/f.png"),
    (["fly", *_CITY, "--vehicle", "field"], "--out", ["--plot", "f.svg"],
     "--plot f.svg: pictures are PNG files"),
])
def test_an_output_that_cannot_be_written_is_refused_before_any_is(monkeypatch, capsys,
                                                                   tmp_path, args, first,
                                                                   bad, words):
    """Exit 2 writes no file (docs/cli.md): every output is checked before the work. The
    first file was written and then the second failed ('plan --geojson p.geojson --plot
    /proc/p.png': exit 2 with p.geojson left); '--plot p.jpg' wrote PNG bytes into it."""
    monkeypatch.chdir(tmp_path)
    blocked = tmp_path / "file"
    blocked.write_text("a file where a folder must be")
    written = tmp_path / "first.json"
    bad = [a.format(blocked=blocked) for a in bad]
    code, _, err = run(monkeypatch, capsys, *args, first, str(written), *bad)
    assert code == 2 and words.format(blocked=blocked) in err, err
    assert len(err.strip().splitlines()) == 1
    assert not written.exists() and not (tmp_path / bad[1]).exists()


def test_a_store_folder_that_cannot_be_made_is_exit_2(monkeypatch, capsys, tmp_path):
    (tmp_path / "taken").write_text("a file, not a folder\n")
    code, out, err = run(monkeypatch, capsys, "db", "init", "--db",
                         f"sqlite:///{tmp_path / 'taken' / 'sub' / 'x.db'}")
    assert code == 2 and out == "" and "cannot make the store's folder" in err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
