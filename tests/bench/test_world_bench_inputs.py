"""``bench world`` and ``bench motion``: bad options and files are one line, exit 2, and
refused before any long work (the benchmark functions are replaced by ones that fail)."""

import json

import pytest

from skyroute.bench.motion import ilp_places
from skyroute.errors import InputFormatError
from tests.cli.test_cli import run

HEADER = "posX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ"
HOME = "lat0 37.792480, lon0 -122.397450"


def city(tmp_path, *boxes, name="c.csv"):
    """A small colliders file of ``boxes`` (north, east, up, half sizes)."""
    path = tmp_path / name
    path.write_text("\n".join([HOME, HEADER, *boxes]) + "\n")
    return str(path)


@pytest.fixture
def no_work(monkeypatch):
    """Every long step of both commands fails the test if reached."""
    def fail(*args, **kwargs):
        pytest.fail("the benchmark ran before the options were checked")

    monkeypatch.setattr("skyroute.cli.bench_world_cmd.bench_query", fail)
    monkeypatch.setattr("skyroute.bench.motion.dubins_speed", fail)
    monkeypatch.setattr("skyroute.bench.motion.step_drone_pairs", fail)
    monkeypatch.setattr("skyroute.bench.curvature.run_queries", fail)


def one_line(code, out, err):
    """exit 2 and one line on stderr; that line."""
    assert code == 2 and err.count("\n") == 1 and err.startswith("skyroute: error: "), err
    assert out == ""
    return err


@pytest.mark.parametrize("args, words", [
    (["--altitude", "nan"], "--altitude nan must be a finite number >= 0"),
    (["--altitude", "inf"], "--altitude inf must be a finite number >= 0"),
    (["--altitude", "-5"], "--altitude -5.0 must be a finite number >= 0"),
    (["--seconds", "-1"], "--seconds -1.0 must be a positive finite number"),
    (["--seconds", "0"], "--seconds 0.0 must be a positive finite number"),
    (["--seconds", "nan"], "--seconds nan must be a positive finite number"),
    (["--budget", "inf"], "--seconds inf must be a positive finite number"),
    (["--planners", "PRM,bogus"], "--planners 'bogus' is not valid; choose one of 'PRM'"),
    (["--worlds", "0"], "--worlds 0 and no --city: nothing to run; give --worlds N or --city"),
])
def test_bench_world_bad_options(monkeypatch, capsys, no_work, args, words):
    err = one_line(*run(monkeypatch, capsys, "bench", "world", "--worlds", "1", *args))
    assert words in err


def test_bench_world_altitude_above_every_building(monkeypatch, capsys, no_work, tmp_path):
    c = city(tmp_path, "0,0,100,5,5,100", "50,50,20,5,5,20")  # tops 200 and 40 m
    err = one_line(*run(monkeypatch, capsys, "bench", "world", "--worlds", "0", "--city", c,
                        "--altitude", "300", "--safety", "0"))
    assert "--altitude 300: no building of c.csv reaches 300 m (the tallest is 200 m)" in err
    err = one_line(*run(monkeypatch, capsys, "bench", "world", "--worlds", "0", "--city", c,
                        "--altitude", "1e9"))
    assert "no building of c.csv reaches 1e+09 m (the tallest is 200 m; 205 m with" in err


def test_bench_world_city_with_no_free_pair(monkeypatch, capsys, no_work, tmp_path):
    c = city(tmp_path, "0,0,50,500,500,50")  # one box over everything
    err = one_line(*run(monkeypatch, capsys, "bench", "world", "--worlds", "0", "--city", c,
                        "--planners", ""))
    assert f"--city {c}: no two far free points joined by a path at --altitude 5 with " \
           "--safety 5; try a smaller --safety or another --altitude" in err
    err = one_line(*run(monkeypatch, capsys, "bench", "world", "--worlds", "0", "--city",
                        city(tmp_path, "0,0,50,5,5,50", "90,90,50,5,5,50"), "--safety", "1e6"))
    assert "with --safety 1e+06; try a smaller --safety" in err


@pytest.mark.parametrize("home", ["lat0 37.79.2480, lon0 -122.397450", "lat0 ., lon0 ."])
def test_bench_world_bad_home_line(monkeypatch, capsys, no_work, tmp_path, home):
    c = tmp_path / "c.csv"
    c.write_text(f"{home}\n{HEADER}\n0,0,5,5,5,5\n")
    err = one_line(*run(monkeypatch, capsys, "bench", "world", "--worlds", "0", "--city",
                        str(c)))
    assert f"{c}:1: expected 'lat0 <deg>, lon0 <deg>', got {home!r}" in err


@pytest.mark.parametrize("command", [["world", "--worlds", "1"], ["motion", "--dubins"],
                                     ["motion", "--curvature", "--worlds", "1"]])
def test_bad_json_path_is_refused_first(monkeypatch, capsys, no_work, tmp_path, command):
    (tmp_path / "afile").write_text("")
    bad = tmp_path / "afile" / "r.json"
    err = one_line(*run(monkeypatch, capsys, "bench", *command, "--json", str(bad)))
    assert f"{bad}: cannot write: {tmp_path / 'afile'} is not a folder" in err


@pytest.mark.parametrize("args, words", [
    (["--curvature", "--budgets", "nan"], "--budgets 'nan': every budget must be > 0 seconds "
     "and finite"),
    (["--curvature", "--budgets", "1,inf"], "--budgets '1,inf': every budget"),
    (["--curvature", "--budgets", "0"], "--budgets '0': every budget"),
    (["--curvature", "--budgets", "1,,5"], "--budgets '1,,5': item 2 is empty"),
    (["--curvature", "--worlds", "0", "--tours", "0"], "nothing to run"),
    (["--dubins", "--merge", "inf"], "--merge inf must be a positive finite number"),
    (["--dubins", "--data", "/nonexistent", "--merge", "-5"], "--merge -5.0 must be"),
    (["--dubins", "--data", "/nonexistent"], "--data /nonexistent: no such folder"),
    (["--data", "/nonexistent"], "--data /nonexistent: no such folder"),
    (["--data", "/nonexistent", "--merge", "-1"], "--merge -1.0 must be a positive finite"),
])
def test_bench_motion_bad_options(monkeypatch, capsys, no_work, args, words):
    err = one_line(*run(monkeypatch, capsys, "bench", "motion", *args))
    assert words in err


def test_bench_motion_data_folder_missing_a_file(monkeypatch, capsys, no_work, tmp_path):
    err = one_line(*run(monkeypatch, capsys, "bench", "motion", "--data", str(tmp_path)))
    assert f"--data {tmp_path}: no website/buildings/no-fly-zones.geojson in it" in err


def test_bench_motion_city_below_its_altitude(monkeypatch, capsys, no_work, tmp_path):
    c = city(tmp_path, "0,0,4,5,5,4", "50,50,4,5,5,4")  # 8 m tall; the benchmark flies at 10
    err = one_line(*run(monkeypatch, capsys, "bench", "motion", "--curvature", "--worlds",
                        "0", "--tours", "0", "--city", c))
    assert f"--city {c}: the benchmark flies at 10 m, and no building of c.csv reaches 10 m " \
           "(the tallest is 8 m;" in err


@pytest.mark.parametrize("doc, words", [
    ("{", "cannot read"),
    (json.dumps({"type": "FeatureCollection", "features": [{"geometry": None}]}),
     "expected a FeatureCollection of Point features with a name property"),
    (json.dumps({"type": "FeatureCollection", "features": []}), "need 2 or more"),
])
def test_ilp_places_broken_file(tmp_path, doc, words):
    path = tmp_path / "all.geojson"
    path.write_text(doc)
    with pytest.raises(InputFormatError, match=words) as err:
        ilp_places(path)
    assert str(err.value).startswith(f"{path}: ")


def test_bench_world_city_too_large_for_the_visibility_graph(monkeypatch, capsys, no_work,
                                                             tmp_path):
    from skyroute.roadmap import visibility

    monkeypatch.setattr(visibility, "MAX_CORNERS", 7)
    c = city(tmp_path, "0,0,100,5,5,100", "50,50,20,5,5,20")  # 8 corners at 10 m
    err = one_line(*run(monkeypatch, capsys, "bench", "world", "--worlds", "0", "--city", c))
    assert "c.csv: 8 obstacle corners, over the limit of 7 for the visibility graph" in err
