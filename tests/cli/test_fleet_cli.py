"""skyroute fleet simulate | scenario | sweep and bench fleet, as a user runs them."""

from __future__ import annotations

import json

import pytest
import yaml

from skyroute.bench.fleet import bench_case
from skyroute.cli.fleet_cmd import parse_seeds
from skyroute.errors import OptionError
from skyroute.fleet.report import FIELDS
from skyroute.fleet.scenario import load_scenario
from skyroute.jobs.fleet import mean_ci
from tests.cli.test_cli import out_blocked_by, run


def test_simulate_json_and_files(monkeypatch, capsys, tmp_path):
    code, out, err = run(monkeypatch, capsys, "fleet", "simulate", "--preset", "seed-3x3",
                         "--hours", "1", "--seed", "3", "--scheduler", "optimal",
                         "--airspace", "shared", "--out", str(tmp_path), "--json")
    assert code == 0, err
    rep = json.loads(out)
    assert list(rep)[:len(FIELDS)] == list(FIELDS)
    assert rep["conflicts"] == 0 and rep["lost"] == 0
    assert rep["settings"]["scheduler"] == "optimal" and rep["settings"]["seed"] == 3
    assert json.loads((tmp_path / "report.json").read_text())["offered"] == rep["offered"]
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "events.jsonl", "fleet.geojson", "packages.csv", "report.json", "tracks.csv"]


def test_simulate_table_and_separation_override(monkeypatch, capsys):
    code, out, err = run(monkeypatch, capsys, "fleet", "simulate", "--airports", "3",
                         "--drones", "2", "--area-km", "3", "--hours", "0.5",
                         "--sep-horizontal", "80", "--rate", "30")
    assert code == 0, err
    assert "conflicts" in out and "2 drones, 3 airports" in out
    # each least distance says the other minimum it was taken within: "98.3 m
    # horizontally; 20.0 m vertically within 50 m" read as if the closest pair were 98 m
    # apart yet another came within 50 m
    assert "horizontally within 10 m vertically" in out, out
    assert "vertically within 80 m horizontally" in out, out


@pytest.mark.parametrize("args, words", [
    (["--preset", "seed-3x3", "--plot"], "--plot needs --out"),
    (["--preset", "seed-3x3", "--airports", "3"], "exactly one of SCENARIO"),
    (["--preset", "seed-3x3", "--hours", "0"], "--hours 0"),
    (["--preset", "seed-3x3", "--scheduler", "fifo"], "--scheduler 'fifo'"),
    (["--preset", "seed-3x3", "--sep-vertical", "-1"], "--sep-vertical -1"),
    (["--airports", "3"], "--airports needs --drones"),
])
def test_bad_simulate_options_are_one_line_and_exit_2(monkeypatch, capsys, args, words):
    code, _, err = run(monkeypatch, capsys, "fleet", "simulate", *args)
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1, err


def test_scenario_writes_a_loadable_file(monkeypatch, capsys, tmp_path):
    code, out, err = run(monkeypatch, capsys, "fleet", "scenario", "--airports", "4",
                         "--drones", "5", "--area-km", "5", "--seed", "2", "--rate", "33")
    assert code == 0, err
    p = tmp_path / "s.yaml"
    p.write_text(out)
    s = load_scenario(p)
    assert len(s.airports) == 4 and s.drones == 5 and s.packages.rate_per_hour == 33
    assert yaml.safe_load(out)["airspace"]["sep_horizontal"] == 50.0


def test_sweep_rows_with_confidence_intervals(monkeypatch, capsys):
    code, out, err = run(monkeypatch, capsys, "fleet", "sweep", "--preset", "seed-3x3",
                         "--scheduler", "seed,optimal", "--airspace", "shared",
                         "--rates", "20", "--seeds", "0-2", "--hours", "1", "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["seeds"] == [0, 1, 2] and len(doc["rows"]) == 2
    for row in doc["rows"]:
        assert row["runs"] == 3 and row["conflicts"] == 0 and row["lost"] == 0
        assert row["rate_per_hour"] == 20 and row["delivered_per_hour_ci95"] >= 0


def test_sweep_option_errors(monkeypatch, capsys):
    code, _, err = run(monkeypatch, capsys, "fleet", "sweep", "--preset", "seed-3x3",
                       "--seeds", "5-2")
    assert code == 2 and "--seeds '5-2'" in err
    code, _, err = run(monkeypatch, capsys, "fleet", "sweep", "--preset", "seed-3x3",
                       "--airspace", "layers,open")
    assert code == 2 and "--airspace 'open'" in err


def test_seed_lists_and_confidence_intervals():
    assert parse_seeds("0-3,7,2") == [0, 1, 2, 3, 7]
    m, ci = mean_ci([1.0, 2.0, 3.0])
    # mean 2, sd 1, t(0.975, 2) = 4.302652729911275 (tables): half-width 4.3027 / sqrt 3
    assert m == 2.0 and ci == pytest.approx(4.302652729911275 / 3 ** 0.5)


def test_bench_case_times_and_checks_a_small_fleet():
    row = bench_case(4, 6, 4.0, 0.5, 40.0)
    assert row["conflicts"] == 0 and row["lost"] == 0 and row["flights"] > 0
    assert row["sim_seconds"] > 0 and row["check_seconds"] > 0
    assert row["sim_seconds_per_wall_second"] == pytest.approx(1800 / row["wall_seconds"])


def _no_run(*_args, **_kwargs):
    raise AssertionError("the fleet was simulated before its output files were checked")


@pytest.mark.parametrize("blocker, extra, words", [
    ("tracks.csv", [], "tracks.csv: cannot write: it is a folder"),
    ("report.json", [], "report.json: cannot write: it is a folder"),
    ("fleet.geojson", [], "fleet.geojson: cannot write: it is a folder"),
    ("timeline.png", ["--plot"], "timeline.png: cannot write: it is a folder"),
    ("file", [], "is not a folder"),  # --out names a regular file
])
def test_bad_out_fails_before_simulating(monkeypatch, capsys, tmp_path, blocker, extra,
                                         words):
    monkeypatch.setattr("skyroute.fleet.simulate.run", _no_run)
    out = out_blocked_by(tmp_path, blocker)
    before = sorted(p.name for p in tmp_path.rglob("*"))
    code, _, err = run(monkeypatch, capsys, "fleet", "simulate", "--preset", "seed-3x3",
                       "--hours", "0.1", "--out", str(out), *extra)
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1, err
    assert sorted(p.name for p in tmp_path.rglob("*")) == before  # nothing left behind


def test_bad_out_without_the_plots_is_not_checked_for_them(monkeypatch, capsys, tmp_path):
    (tmp_path / "map.png").mkdir()
    code, _, err = run(monkeypatch, capsys, "fleet", "simulate", "--preset", "seed-3x3",
                       "--hours", "0.1", "--out", str(tmp_path), "--json")
    assert code in (0, 1), err
    assert (tmp_path / "tracks.csv").is_file() and (tmp_path / "map.png").is_dir()


@pytest.mark.parametrize("args", [
    ("synth-city", "{tmp}/c.csv", "--seed", "-1"),
    ("fleet", "simulate", "--preset", "seed-3x3", "--hours", "0.1", "--seed", "-1"),
    ("fleet", "scenario", "--airports", "3", "--drones", "3", "--seed", "-1"),
    ("fleet", "sweep", "--preset", "seed-3x3", "--seeds", "-1", "--hours", "0.1"),
    ("fleet", "sweep", "--preset", "seed-3x3", "--seeds", "1,-2", "--hours", "0.1"),
])
def test_negative_seeds_are_one_line_errors(monkeypatch, capsys, tmp_path, args):
    args = [a.format(tmp=tmp_path) for a in args]
    code, _, err = run(monkeypatch, capsys, *args)
    assert code == 2 and "--seed" in err and len(err.strip().splitlines()) == 1, err
    assert "Traceback" not in err and not (tmp_path / "c.csv").exists()


def test_parse_seeds_refuses_negatives():
    with pytest.raises(OptionError, match="-1 is not in the range 0<=x<=4294967295"):
        parse_seeds("3,-1")


def _scenario_file(tmp_path, edit) -> str:
    from skyroute.fleet.scenario import preset

    data = preset("seed-3x3").model_dump()
    edit(data)
    p = tmp_path / "big.yaml"
    p.write_text(yaml.safe_dump(data, sort_keys=False))
    return str(p)


@pytest.mark.parametrize("args, words", [
    # a scenario file past a limit: named by file, line and field
    (["{drones}"], "big.yaml:38: drones: 1e+09 drones is over the limit of 1,000"),
    (["{rate}"], "big.yaml:51: packages.rate_per_hour: 1e+12 packages per hour is over the "
                 "limit of 100,000"),
    (["{far}"], "big.yaml:28: airports[2].north: 1e+12 m from home is over the limit of "
                "100,000 m"),
    # options past a limit
    (["--preset", "seed-3x3", "--hours", "1e9"], "--hours 1e+09 is over the limit of 168"),
    (["--preset", "seed-3x3", "--rate", "1e12"], "--rate 1e+12 is over the limit of 100,000"),
    (["--preset", "seed-3x3", "--drones", "1000000000"], "--drones 1000000000 must be 1 to "
                                                         "1,000"),
    (["--airports", "101", "--drones", "3"], "--airports 101 must be 2 to 100"),
    (["--airports", "3", "--drones", "3", "--area-km", "1e12"], "--area-km 1e+12 must be"),
    # the work they multiply to
    (["--preset", "seed-3x3", "--rate", "1e5", "--hours", "8"],
     "--rate 100000 with --hours 8 would spawn about 8e+05 packages (limit 100,000); lower "
     "one of them"),
    (["{busy}", "--hours", "24"],
     "--hours 24 at the scenario's 10000 packages/h would spawn about 2.4e+05 packages"),
    (["--preset", "seed-3x3", "--hours", "8", "--track-step", "1e-6", "--out", "{tmp}/o"],
     "--track-step 1e-06 with --hours 8 and 3 drones would write up to 8.6e+10 track rows "
     "(limit 20,000,000); raise the step"),
])
def test_huge_values_are_refused_before_simulating(monkeypatch, capsys, tmp_path, args,
                                                   words):
    monkeypatch.setattr("skyroute.fleet.simulate.run", _no_run)
    files = {"drones": lambda d: d.update(drones=10**9),
             "rate": lambda d: d["packages"].update(rate_per_hour=1e12),
             "far": lambda d: d["airports"][2].update(north=1e12),
             "busy": lambda d: d["packages"].update(rate_per_hour=1e4)}
    names = {}
    for k, edit in files.items():
        (tmp_path / k).mkdir()
        names[k] = _scenario_file(tmp_path / k, edit)
    args = [a.format(tmp=tmp_path, **names) for a in args]
    code, out, err = run(monkeypatch, capsys, "fleet", "simulate", *args)
    assert code == 2 and out == "" and words in err, err
    assert len(err.strip().splitlines()) == 1 and not (tmp_path / "o").exists()


@pytest.mark.parametrize("args, words", [
    (["--airports", "5", "--drones", "-1"], "--drones -1 must be 1 to 1,000"),
    (["--airports", "5", "--drones", "1001"], "--drones 1001 must be 1 to 1,000"),
    (["--airports", "1", "--drones", "3"], "--airports 1 must be 2 to 100"),
    (["--airports", "3", "--drones", "3", "--rate", "1e12"],
     "--rate 1000000000000.0 must be a number >= 0 and <= 100,000"),
])
def test_scenario_names_the_bad_option(monkeypatch, capsys, args, words):
    code, out, err = run(monkeypatch, capsys, "fleet", "scenario", *args)
    assert code == 2 and out == "" and words in err and len(err.strip().splitlines()) == 1
    assert "--airports" not in err or "--airports" in words  # --drones was named --airports


@pytest.mark.parametrize("args, words", [
    (["--seeds", "0-999999999"], "--seeds '0-999999999': 0-999999999 is 1,000,000,000 "
                                 "seeds, over the limit of 1,000"),
    (["--seeds", "0-500,1000-1999"], "over the limit of 1,000"),
    (["--rates", "30,1e12"], "--rates '30,1e12': 1e+12 is over the limit of 100,000"),
    (["--rates", "1e5", "--hours", "4"], "--rates 100000 with --hours 4 would spawn about "
                                         "4e+05 packages"),
    (["--hours", "1e9"], "--hours 1e+09 is over the limit of 168"),
    # an empty item was passed over: 20,,60 swept two rates, not the three meant
    (["--rates", "20,,60"], "--rates '20,,60': item 2 is empty (a stray comma?)"),
    (["--rates", "20,60,"], "--rates '20,60,': item 3 is empty"),
    (["--seeds", "0,,4"], "--seeds '0,,4': item 2 is empty"),
    (["--scheduler", "seed,,optimal"], "--scheduler 'seed,,optimal': item 2 is empty"),
    (["--airspace", ",shared"], "--airspace ',shared': item 1 is empty"),
    # every seed and rate within its limit, their product not
    (["--seeds", "0-999", "--rates", "10,20,30"], "2 scheduler(s) x 2 airspace(s) x 3 rate(s) "
     "x 1,000 seed(s) is 12,000 runs, over the limit of 10,000 in one sweep; give fewer "
     "--seeds, --rates, --scheduler or --airspace"),
])
def test_sweep_refuses_huge_values_before_running(monkeypatch, capsys, args, words):
    monkeypatch.setattr("skyroute.jobs.fleet.sweep", _no_run)
    code, out, err = run(monkeypatch, capsys, "fleet", "sweep", "--preset", "seed-3x3", *args)
    assert code == 2 and out == "" and words in err and len(err.strip().splitlines()) == 1


def test_parse_seeds_refuses_a_long_range_before_making_it():
    assert parse_seeds("0-999") == list(range(1000))
    with pytest.raises(OptionError, match="over the limit of 1,000"):
        parse_seeds("5-1005")
    with pytest.raises(OptionError, match="1,000,000,000,000 seeds"):
        parse_seeds("1-1000000000000")


def test_bench_fleet_checks_its_json_path_before_running(monkeypatch, capsys, tmp_path):
    monkeypatch.setattr("skyroute.cli.bench_fleet_cmd.bench_case", _no_run)
    (tmp_path / "file").write_text("keep me")
    code, _, err = run(monkeypatch, capsys, "bench", "fleet", "--case", "1", "--json",
                       str(tmp_path / "file" / "rows.json"))
    assert code == 2 and "rows.json: cannot write: " in err and "file is not a folder" in err
    assert len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("edit, field", [
    (lambda d: d["drone"].update(turn_radius=1e12), "drone.turn_radius"),
    (lambda d: d["drone"].update(cruise_speed=0.001, landing_speed=0.0005),
     "drone.cruise_speed"),
])
def test_a_flight_too_long_to_sample_names_the_file_and_field(monkeypatch, capsys, tmp_path,
                                                              edit, field):
    monkeypatch.setattr("skyroute.fleet.simulate.run", _no_run)  # refused when read
    monkeypatch.setattr("skyroute.jobs.fleet.sweep", _no_run)
    path = _scenario_file(tmp_path, edit)
    for command in ("simulate", "sweep"):
        code, out, err = run(monkeypatch, capsys, "fleet", command, path, "--hours", "0.1")
        assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, err
        assert err.startswith(f"skyroute: error: {path}: {field}: a flight "), err
        assert "h with its loiters, over the limit of 12 h" in err


def test_more_drones_flying_too_high_is_one_line(monkeypatch, capsys, tmp_path):
    # one drone cruises at base_altitude; the 1,000th would climb 1e10 m to its layer, a
    # take-off roll no runway holds (the 12 h airborne check skips levels not flown)
    path = _scenario_file(tmp_path, lambda d: (d.update(drones=1), d["airspace"].update(
        layer_step=1e7, shared_levels=1)))
    code, out, err = run(monkeypatch, capsys, "fleet", "simulate", path, "--drones", "1000",
                         "--hours", "0.1")
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, err
    assert "shorter than the take-off roll to climb to 9.99e+09 m" in err
    assert err.rstrip().endswith("drone 999's level in layers; fly shared, fewer drones or a "
                                 "longer runway")


def test_a_package_csv_past_the_limit_is_one_line(monkeypatch, capsys, tmp_path):
    # every row after the horizon: the old code read them all, dropped them and ran empty
    (tmp_path / "p.csv").write_text("t,from_airport,from_gate,to_airport,to_gate\n"
                                    + "1e9,A,0,B,1\n" * 100_001)
    path = _scenario_file(tmp_path, lambda d: d["packages"].update(csv="p.csv"))
    code, out, err = run(monkeypatch, capsys, "fleet", "simulate", path, "--hours", "0.1")
    assert code == 2 and out == ""
    assert err == (f"skyroute: error: {tmp_path / 'p.csv'}:100002: more than 100,000 "
                   "packages, the limit of one run; split the file\n")


def _short_strip(d: dict) -> None:
    d["airports"][2]["takeoff"]["length"] = 320.0  # holds the roll to 50 m, not to 90 m
    d["drones"] = 5


@pytest.mark.parametrize("command", [["simulate", "--out", "OUT"], ["sweep", "--seeds", "0"]])
def test_a_level_whose_roll_overruns_a_runway_is_one_line_before_any_work(
        monkeypatch, capsys, tmp_path, command):
    path = _scenario_file(tmp_path, _short_strip)
    out_dir = tmp_path / "run"
    args = [str(out_dir) if a == "OUT" else a for a in command]
    code, out, err = run(monkeypatch, capsys, "fleet", args[0], path, *args[1:],
                         "--hours", "0.1", "--airspace", "layers")
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, err
    # the file is named, as for every other scenario error
    assert err.startswith(f"skyroute: error: {path}: airport C's take-off runway (320 m) is "
                          "shorter than the take-off roll to climb to 90 m (326 m), drone "
                          "4's level in layers"), err
    assert not out_dir.exists()


def test_an_airport_no_cruise_can_reach_is_one_line_before_any_work(monkeypatch, capsys,
                                                                     tmp_path):
    # a ring of no-fly zones round C failed mid-run, when C was first flown, with the
    # planner's raw status and no file
    from tests.fleet.test_nofly import RING_ERROR, ringed

    monkeypatch.setattr("skyroute.fleet.simulate.run", _no_run)
    monkeypatch.setattr("skyroute.jobs.fleet.sweep", _no_run)
    path = tmp_path / "ring.yaml"
    path.write_text(yaml.safe_dump(ringed(), sort_keys=False))
    for command in ("simulate", "sweep"):
        code, out, err = run(monkeypatch, capsys, "fleet", command, str(path), "--hours", "0.1")
        assert code == 2 and out == "", err
        assert err == f"skyroute: error: {path}: {RING_ERROR}\n"


def test_nothing_offered_has_no_served_share(monkeypatch, capsys):
    # a run offered no package reported "served 100.0%" (served_share 1.0)
    base = ["--preset", "seed-3x3", "--hours", "0.2"]
    code, out, err = run(monkeypatch, capsys, "fleet", "simulate", *base, "--rate", "0",
                         "--json")
    assert code == 0, err
    rep = json.loads(out)
    assert rep["offered"] == 0 and rep["served_share"] is None
    code, out, err = run(monkeypatch, capsys, "fleet", "simulate", *base, "--rate", "0")
    assert code == 0 and "0 (0.0/h, served -)" in out, err
    sweep = ["fleet", "sweep", *base, "--scheduler", "seed", "--airspace", "layers",
             "--rates", "0", "--seeds", "0-1"]
    code, out, err = run(monkeypatch, capsys, *sweep, "--json")
    assert code == 0, err
    (row,) = json.loads(out)["rows"]
    assert row["served_share"] is None and row["served_share_ci95"] is None
    code, out, err = run(monkeypatch, capsys, *sweep)
    assert code == 0, err
    (line,) = [x for x in out.splitlines() if " layers " in x]
    cells = [c.strip() for c in line.strip(" \u2502").split("\u2502")]
    assert cells[2:5] == ["0", "0.0 \u00b10.0", "-"], out  # offered, delivered/h, served %


def test_bench_fleet_json_keeps_its_options(monkeypatch, capsys, tmp_path):
    """Every bench report keeps its options under ``settings``; this one had only
    ``machine`` and ``rows``."""
    row = {"rate_per_hour": 600.0, "flights": 1, "sim_seconds": 1.0, "check_seconds": 0.1,
           "sim_seconds_per_wall_second": 10.0, "delivered_per_hour": 1.0, "conflicts": 0,
           "lost": 0}
    monkeypatch.setattr("skyroute.cli.bench_fleet_cmd.bench_case", lambda *a, **k: row)
    out = tmp_path / "rows.json"
    code, _, err = run(monkeypatch, capsys, "bench", "fleet", "--case", "2", "--scheduler",
                       "seed", "--airspace", "layers", "--seed", "4", "--json", str(out))
    assert code == 0, err
    doc = json.loads(out.read_text())
    assert doc["settings"] == {"case": [2], "scheduler": "seed", "airspace": "layers",
                               "seed": 4}
    assert doc["machine"]["skyroute"] and len(doc["rows"]) == 1
