"""A fleet run's files: tracks on the step grid and on the flight plans, events that
parse back and repeat byte for byte, package rows that agree with the run, GeoJSON near
home that round-trips through ned, pictures only when asked for."""

from __future__ import annotations

import csv
import io
import json
import math

import numpy as np
import pytest

from skyroute.errors import OptionError, SkyrouteError
from skyroute.fleet import report, simulate
from skyroute.fleet.flightplan import gate_position, ground_position
from skyroute.fleet.scenario import preset
from skyroute.fleet.trajectory import position
from skyroute.geo import Home, lonlat_to_ned
from skyroute.io.fleet_out import (
    PACKAGE_HEADER,
    TRACK_PHASES,
    _fixed,
    _lines,
    airborne_samples,
    events_jsonl,
    fleet_geojson,
    package_states,
    packages_csv,
    tracks,
    tracks_csv,
    write_run,
)

GROUND = ("taxi", "takeoff", "landing", "rollout")
FILES = ["report.json", "events.jsonl", "tracks.csv", "packages.csv", "fleet.geojson"]


def fleet_run():
    return simulate.run(preset("seed-3x3"), hours=2, seed=1, scheduler="seed")


@pytest.fixture(scope="module")
def sim():
    return fleet_run()


@pytest.fixture(scope="module")
def rep(sim):
    return report.report(sim)


def flight_of_rows(sim, tr) -> np.ndarray:
    """The index in sim.flights of the flight each row belongs to; fails unless exactly
    one flight of the row's drone spans the row's time."""
    owner = np.full(len(tr["t"]), -1)
    for i, f in enumerate(sim.flights):
        at = ((tr["drone"] == f.plan.drone) & (tr["t"] >= f.plan.depart)
              & (tr["t"] <= f.plan.at_gate))
        assert (owner[at] == -1).all(), "two flights of one drone at one time"
        owner[at] = i
    assert (owner >= 0).all(), "a row outside every flight"
    return owner


@pytest.mark.parametrize("step", [1.0, 2.5])
def test_tracks_rows_are_on_the_grid_within_flights_and_the_run(sim, step):
    tr = tracks(sim, step)
    t = tr["t"]
    k = t / step
    assert np.array_equal(k, np.round(k))
    assert t.min() >= 0 and t.max() <= sim.horizon
    owner = flight_of_rows(sim, tr)
    # sorted by time then drone, one row per drone and time
    key = np.round(k).astype(np.int64) * sim.scenario.drones + tr["drone"]
    assert (np.diff(key) > 0).all()
    # every grid time of every flight (clipped to the run) has its row
    for i, f in enumerate(sim.flights):
        lo, hi = max(f.plan.depart, 0.0), min(f.plan.at_gate, sim.horizon)
        expect = max(0, math.floor(hi / step) - math.ceil(lo / step) + 1)
        assert (owner == i).sum() == expect
    # the run ends with a drone in the air: its rows stop at the horizon
    assert any(f.plan.depart < sim.horizon < f.plan.at_gate for f in sim.flights)


def test_track_altitudes_by_phase(sim):
    tr = tracks(sim)
    assert set(tr["phase"]) <= set(TRACK_PHASES)
    ground = np.isin(tr["phase"], GROUND)
    assert (tr["alt"][ground] == 0).all()
    level = np.isin(tr["phase"], ("cruise", "loiter"))
    assert (tr["alt"][level] >= sim.scenario.airspace.base_altitude).all()
    assert {"taxi", "takeoff", "climb", "cruise", "loiter", "approach",
            "rollout"} <= set(tr["phase"])  # this run has loiter circles


def test_track_positions_are_the_flight_plans(sim):
    tr = tracks(sim)
    owner = flight_of_rows(sim, tr)
    pos = np.column_stack([tr["north"], tr["east"], tr["alt"]])
    air = ~np.isin(tr["phase"], GROUND)
    pieces = sim.pieces()
    for d in range(sim.scenario.drones):  # airborne rows: the run's own pieces
        rows = air & (tr["drone"] == d)
        np.testing.assert_allclose(pos[rows], position(pieces, tr["t"][rows], drone=d),
                                   rtol=0, atol=1e-9)
    for i, f in enumerate(sim.flights):  # ground rows: the plan's ground position
        rows = ~air & (owner == i)
        np.testing.assert_allclose(pos[rows, :2], ground_position(f.plan, tr["t"][rows]),
                                   rtol=0, atol=1e-9)
        # the flight starts at its gate and moves no faster than it cruises
        mine = np.flatnonzero(owner == i)
        if len(mine) > 1:
            step = np.linalg.norm(np.diff(pos[mine], axis=0), axis=1)
            assert step.max() <= sim.scenario.drone.cruise_speed + 1e-6
        if mine.size and tr["t"][mine[0]] == f.plan.depart:
            a = sim.scenario.airport(f.plan.origin)
            np.testing.assert_allclose(pos[mine[0], :2],
                                       gate_position(a, f.plan.origin_gate), atol=1e-9)


def test_track_phases_follow_the_flight_order(sim):
    tr = tracks(sim)
    owner = flight_of_rows(sim, tr)
    rank = {p: i for i, p in enumerate(TRACK_PHASES)}
    for i, f in enumerate(sim.flights):
        phases = tr["phase"][owner == i]
        if len(phases) == 0:
            continue
        # taxi out and taxi in are both "taxi": rank the final taxi after the roll-out
        r = np.array([rank[p] for p in phases])
        after = np.flatnonzero(phases == "rollout")
        if len(after):
            r[after[0]:][phases[after[0]:] == "taxi"] = len(TRACK_PHASES)
        assert (np.diff(r) >= 0).all()
        # loiter rows exactly when a loiter circle was flown at a row time of the run
        circling = False
        if f.plan.loiters:
            lp = f.plan.phase("loiter")
            first = math.ceil(lp.start)
            circling = first < lp.end and first <= sim.horizon
        assert ("loiter" in phases) == circling


def test_tracks_csv_is_tracks_in_millimetres(sim):
    tr = tracks(sim, 2.5)
    text = tracks_csv(sim, step=2.5).decode()
    rows = list(csv.reader(io.StringIO(text)))
    assert rows[0] == ["t", "drone", "north", "east", "alt", "phase"]
    body = rows[1:]
    assert len(body) == len(tr["t"])
    assert [r[0] for r in body[:3]] == [f"{x:.1f}" for x in tr["t"][:3]]
    num = np.array([[float(x) for x in r[:5]] for r in body])
    for j, c in enumerate(("t", "drone", "north", "east", "alt")):
        np.testing.assert_allclose(num[:, j], tr[c], rtol=0, atol=5e-4)
    assert [r[5] for r in body] == tr["phase"].tolist()
    assert all(len(r[2].split(".")[1]) == 3 for r in body[:100])


def test_fixed_point_formatting():
    chars = _lines([_fixed([0, -1, 1234567, -5000, 999], 3), _fixed([7, -12, 0, 3, 10], 0)])
    assert chars == b"0.000,7\n-0.001,-12\n1234.567,0\n-5.000,3\n0.999,10\n"


def test_events_jsonl_parses_back_and_repeats_byte_for_byte(sim, tmp_path):
    text = events_jsonl(sim)
    assert [json.loads(line) for line in text.splitlines()] == sim.events
    assert " " not in text and text.endswith("\n")
    again = write_run(fleet_run(), {}, tmp_path / "again")[1]
    assert again.read_bytes() == text.encode()
    other = simulate.run(preset("seed-3x3"), hours=2, seed=2)
    assert events_jsonl(other) != text


def test_packages_csv_agrees_with_the_run(sim):
    rows = list(csv.DictReader(io.StringIO(packages_csv(sim))))
    st, H = sim.stream, sim.horizon
    assert tuple(rows[0]) == PACKAGE_HEADER
    assert [int(r["id"]) for r in rows] == np.flatnonzero(st.t < H).tolist()
    ids = [a.id for a in sim.scenario.airports]
    state = package_states(sim)
    events = {(e["kind"], e.get("package")): e for e in sim.events}
    for r in rows:
        p = int(r["id"])
        assert float(r["spawn_s"]) == pytest.approx(st.t[p], abs=5e-4)
        assert (r["from_airport"], int(r["from_gate"])) == (ids[st.origin[p]],
                                                             int(st.origin_gate[p]))
        assert (r["to_airport"], int(r["to_gate"])) == (ids[st.destination[p]],
                                                        int(st.destination_gate[p]))
        for col, arr in (("assigned_s", sim.assigned), ("pickup_s", sim.pickup),
                         ("delivered_s", sim.delivered)):
            if arr[p] <= H:
                assert float(r[col]) == pytest.approx(arr[p], abs=5e-4)
            else:
                assert r[col] == ""
        assert r["state"] == state[p]
        expect = {"waiting": r["assigned_s"] == "",
                  "assigned": r["assigned_s"] != "" and r["pickup_s"] == "",
                  "carried": r["pickup_s"] != "" and r["delivered_s"] == "",
                  "delivered": r["delivered_s"] != ""}
        assert expect[r["state"]]
        if r["state"] == "waiting":
            assert r["drone"] == ""
        else:  # the assigned drone; from the pickup on it is the carrier
            assert int(r["drone"]) == events[("assign", p)]["drone"]
            if r["state"] in ("carried", "delivered"):
                assert int(r["drone"]) == sim.carrier[p]
    counts = {s: sum(r["state"] == s for r in rows) for s in
              ("waiting", "assigned", "carried", "delivered")}
    assert counts["delivered"] == sum(e["kind"] == "delivered" for e in sim.events)
    assert counts["waiting"] > 0 and counts["delivered"] > 0


def test_geojson_is_near_home_and_round_trips_through_ned(sim):
    s = sim.scenario
    gj = fleet_geojson(sim)
    assert json.loads(json.dumps(gj)) == gj
    feats = gj["features"]
    kinds = [f["properties"]["kind"] for f in feats]
    assert kinds.count("airport") == len(s.airports)
    assert kinds.count("gate") == 2 * len(s.airports)
    assert kinds.count("landing") == kinds.count("takeoff") == len(s.airports)
    tracks_ = [f for f in feats if f["properties"]["kind"] in ("reposition", "delivery")]
    assert len(tracks_) == sum(f.plan.pieces.t0.min() < sim.horizon for f in sim.flights)
    home = Home(lon=s.home_lon, lat=s.home_lat)
    for f in feats:
        c = np.atleast_2d(np.array(f["geometry"]["coordinates"], dtype=float))
        assert np.abs(c[:, 0] - s.home_lon).max() < 0.05
        assert np.abs(c[:, 1] - s.home_lat).max() < 0.05
    for f in feats[:len(s.airports)]:  # airports: back to their metres
        a = s.airport(f["properties"]["id"])
        lon, lat = f["geometry"]["coordinates"]
        ned = lonlat_to_ned(lon, lat, 0.0, home)[0]
        np.testing.assert_allclose(ned[:2], [a.north, a.east], atol=0.02)
    first = next(f for f in sim.flights if f.plan.pieces.t0.min() < sim.horizon)
    _, pos = airborne_samples(first.plan, 2.0, sim.horizon)
    c = np.array(tracks_[0]["geometry"]["coordinates"])
    ned = lonlat_to_ned(c[:, 0], c[:, 1], c[:, 2], home)
    np.testing.assert_allclose(ned[:, :2], pos[:, :2], atol=0.02)
    np.testing.assert_allclose(c[:, 2], pos[:, 2], atol=0.006)
    assert tracks_[0]["properties"]["drone"] == first.plan.drone


def test_write_run_writes_whole_files_and_no_pictures(sim, rep, tmp_path):
    rep = {**rep, "min_vertical_m": None}  # no pair came within sep_horizontal: null
    out = tmp_path / "new" / "run"
    paths = write_run(sim, rep, out)
    assert paths == [out / name for name in FILES]
    assert sorted(p.name for p in out.iterdir()) == sorted(FILES)  # no temporary files
    text = (out / "report.json").read_text()
    back = json.loads(text)
    assert back == rep and list(back) == list(rep)
    assert '"min_vertical_m": null' in text and text.startswith('{\n  "offered": ')
    assert (out / "events.jsonl").read_text() == events_jsonl(sim)
    assert (out / "tracks.csv").read_bytes() == tracks_csv(sim)
    assert (out / "packages.csv").read_text() == packages_csv(sim)
    assert json.loads((out / "fleet.geojson").read_text()) == fleet_geojson(sim)


def test_write_run_with_plots(sim, rep, tmp_path):
    paths = write_run(sim, rep, tmp_path, track_step=5.0, plot=True)
    assert [p.name for p in paths] == [*FILES, "map.png", "timeline.png"]
    for p in paths[-2:]:
        data = p.read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 30_000
    t = np.loadtxt(paths[2], delimiter=",", skiprows=1, usecols=0)
    assert np.array_equal(t % 5.0, np.zeros_like(t))
    # nothing drawn reaches the image's edge: the legend beside the map (runways, gates)
    # was cut off on the right, its border and "landing runway" label clipped
    from PIL import Image

    for p in paths[-2:]:
        img = np.asarray(Image.open(p).convert("L"))
        edges = np.concatenate([img[:2].ravel(), img[-2:].ravel(), img[:, :2].ravel(),
                                img[:, -2:].ravel()])
        assert (edges == 255).all(), p.name


@pytest.mark.parametrize("step", [0, -1.0, math.nan, "1s"])
def test_a_bad_track_step_writes_nothing(sim, rep, tmp_path, step):
    with pytest.raises(OptionError, match="track_step") as err:
        write_run(sim, rep, tmp_path / "out", track_step=step)
    assert err.value.param == "track_step"
    assert not (tmp_path / "out").exists()


def test_a_report_that_is_not_json_is_an_option_error(sim, tmp_path):
    with pytest.raises(OptionError, match="rep cannot be written") as err:
        write_run(sim, {"served_share": {1, 2}}, tmp_path / "out")
    assert err.value.param == "rep"
    assert not (tmp_path / "out").exists()


def test_a_nan_in_the_report_is_written_null(sim, tmp_path):
    """As every JSON skyroute writes (io/json_text.py): null, not NaN (no JSON); it
    was refused as the report above is."""
    write_run(sim, {"served_share": math.nan}, tmp_path / "out")
    assert (tmp_path / "out" / "report.json").read_text() == '{\n  "served_share": null\n}\n'


@pytest.mark.parametrize("blocker", ["tracks.csv", "fleet.geojson", "timeline.png"])
def test_a_file_that_cannot_be_written_writes_none(sim, rep, tmp_path, blocker):
    (tmp_path / blocker).mkdir()
    with pytest.raises(SkyrouteError, match=f"{blocker}: cannot write: it is a folder"):
        write_run(sim, rep, tmp_path, plot=True)
    assert [p.name for p in tmp_path.iterdir()] == [blocker]


@pytest.fixture(scope="module")
def late_run():
    """A run holding a flight planned to leave after its end (113 flights, 112 flown)."""
    sim = simulate.run(preset("seed-9x9"), hours=1, seed=0, scheduler="seed")
    return sim, report.report(sim)


def test_plot_titles_give_the_numbers_the_command_prints(late_run, tmp_path, monkeypatch):
    """map.png counted every planned flight (1770 against the table's 1767) and
    timeline.png the whole run's packages (192 of 246) where the table gives the
    measured window's (182 of 219)."""
    import skyroute.io.plot as plot_mod
    from skyroute.io.fleet_out import plot_map, plot_timeline

    sim, rep = late_run
    assert len(sim.flights) != rep["flights"]  # the case this test is about
    figures = []
    real = plot_mod.save_figure
    monkeypatch.setattr(plot_mod, "save_figure",
                        lambda fig, path, **kw: figures.append(fig) or real(fig, path, **kw))
    plot_map(sim, tmp_path / "map.png")
    plot_timeline(sim, tmp_path / "timeline.png")
    fleet_map, timeline = (f.axes[0] for f in figures)
    assert fleet_map.get_title().endswith(f", {rep['flights']} flights")
    assert (f"\n{rep['delivered']} of {rep['offered']} packages delivered after the 6 min "
            "warm-up; ") in timeline.get_title()
    # airport names: one each, none on another
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.text import Text

    canvas = FigureCanvasAgg(figures[0])
    canvas.draw()
    names = [t for t in fleet_map.texts if t.get_text() in {a.id for a in sim.scenario.airports}]
    assert sorted(t.get_text() for t in names) == sorted(a.id for a in sim.scenario.airports)
    boxes = [Text.get_window_extent(t, canvas.get_renderer()) for t in names]
    assert not any(a.overlaps(b) for i, a in enumerate(boxes) for b in boxes[:i])


def test_durations_read_in_their_unit():
    from skyroute.io.fleet_out import _duration

    assert [_duration(s) for s in (30, 240, 720, 8640, 86400)] == [
        "30 s", "4 min", "12 min", "2.4 h", "24 h"]


def test_a_run_without_plots_removes_an_earlier_runs_maps(sim, rep, tmp_path, monkeypatch):
    # a folder written with --plot, then again without: map.png and timeline.png of the
    # first run stayed beside the second run's files, read as its maps
    from tests.rename_failures import failing_rename

    write_run(sim, rep, tmp_path, track_step=5.0, plot=True)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    # a rename that fails (a full disk) leaves the folder as it was, maps included
    with monkeypatch.context() as m:
        failing_rename(m, 3)
        with pytest.raises(SkyrouteError, match="No space left on device"):
            write_run(sim, {**rep, "offered": -1}, tmp_path, track_step=5.0)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    write_run(sim, rep, tmp_path, track_step=5.0)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(FILES)
    (tmp_path / "map.png").mkdir()  # not a file a run wrote: left alone
    write_run(sim, rep, tmp_path, track_step=5.0)
    assert (tmp_path / "map.png").is_dir()
