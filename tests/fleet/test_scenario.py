"""Fleet model parameters: the seed's kinematics and scenario files with named errors."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
import yaml

from skyroute.errors import InputFormatError, OptionError
from skyroute.fleet import scenario as sc
from skyroute.fleet.vehicle import (
    rollout_seconds,
    takeoff_distance,
    takeoff_phases,
    taxi_seconds,
)


def test_takeoff_distance_is_the_seed_regression():
    assert takeoff_distance(50.0) == pytest.approx(254.0966 + 3.5519 * 50)
    assert takeoff_distance(150.0) == pytest.approx(254.0966 + 3.5519 * 150)
    assert takeoff_distance(150.001) == pytest.approx(343.0420 + 3.0874 * 150.001)
    with pytest.raises(OptionError, match="from 50 m up"):
        takeoff_distance(40.0)
    roll, roll_s, climb, climb_s = takeoff_phases(100.0, 20.0, 40.0, 50.0)
    assert roll + climb == pytest.approx(takeoff_distance(100.0))
    assert climb == pytest.approx(100.0 / math.tan(math.radians(20.0)))
    assert roll_s == pytest.approx(2 * roll / 40.0)  # even acceleration from rest
    assert climb_s == pytest.approx(math.hypot(climb, 100.0) / 50.0)


def test_rollout_and_taxi():
    # the seed: 192 m from 40 m/s with all brakes -> 4.17 m/s^2, 9.6 s
    assert rollout_seconds(40.0, 192.0) == pytest.approx(9.6)
    assert taxi_seconds(100.0, 20.0) == pytest.approx(80 / 10 + 10 / 3 + 10 / 1)
    assert taxi_seconds(5.0, 20.0) == pytest.approx(5.0)  # all within half a gate width


def test_presets_are_valid_and_round_trip_through_yaml(tmp_path):
    for name, (airports, drones, _, rate) in sc.PRESETS.items():
        s = sc.preset(name)
        assert len(s.airports) == airports and s.drones == drones
        assert s.packages.rate_per_hour == rate
        p = tmp_path / f"{name}.yaml"
        p.write_text(sc.to_yaml(s))
        assert sc.load_scenario(p) == s


def test_toml_scenarios_load(tmp_path):
    p = tmp_path / "s.toml"
    p.write_text('drones = 2\n[[airports]]\nid = "A"\nnorth = 0\neast = 0\n'
                 'landing = {heading_deg = 90}\ntakeoff = {heading_deg = 180}\n'
                 '[[airports]]\nid = "B"\nnorth = 3000\neast = 0\n'
                 'landing = {heading_deg = 0}\ntakeoff = {heading_deg = 270}\n')
    s = sc.load_scenario(p)
    assert s.drones == 2 and s.airport("B").north == 3000 and s.drone.rollout == 192.0


@pytest.mark.parametrize("suffix", [".toml", ".yaml"])
def test_a_scenario_saved_with_a_byte_order_mark_and_crlf_loads(tmp_path, suffix):
    # Notepad's "UTF-8 with BOM": tomllib refused the mark ("not TOML: Invalid statement
    # (at line 1, column 1)"); PyYAML reads past it on its own
    text = ('drones = 2\n[[airports]]\nid = "A"\nnorth = 0\neast = 0\n'
            'landing = {heading_deg = 90}\ntakeoff = {heading_deg = 180}\n'
            '[[airports]]\nid = "B"\nnorth = 3000\neast = 0\n'
            'landing = {heading_deg = 0}\ntakeoff = {heading_deg = 270}\n')
    plain = tmp_path / "s.toml"
    plain.write_text(text)
    want = sc.load_scenario(plain)
    if suffix == ".yaml":
        text = sc.to_yaml(want)
    p = tmp_path / f"bom{suffix}"
    p.write_bytes(b"\xef\xbb\xbf" + text.replace("\n", "\r\n").encode())
    assert sc.load_scenario(p) == want


@pytest.mark.parametrize("edit, words", [
    (lambda y: y.replace("cruise_speed: 50.0", "cruise_sped: 50.0"),
     "drone.cruise_sped: unknown key; did you mean cruise_speed? valid: cruise_speed, "
     "turn_radius, "),
    (lambda y: y.replace("landing_speed: 40.0", "landing_speed: -40.0"),
     "drone.landing_speed: Input should be greater than 0"),
    (lambda y: y.replace("gate_width: 30.0", "gate_width: 0", 1),
     "airports[0].gate_width: Input should be greater than 0"),
    (lambda y: y.replace("heading_deg: 180.0", "heading_deg: 400", 1),
     "airports[0].landing.heading_deg: Input should be less than 360"),
    (lambda y: y.replace("mode: layers", "mode: stacked"),
     "airspace.mode: Input should be 'layers' or 'shared'"),
    # pydantic's own message named the Python class ("instance of Drone")
    (lambda y: re.sub(r"drone:\n(  .*\n)+", "drone: 3\n", y),
     "bad.yaml:40: drone: expected a mapping of fields, not 3"),
    (lambda y: y + "  : [\n", "not YAML"),
    (lambda y: y.replace("cruise_speed: 50.0", "cruise_speed: .inf"),
     "drone.cruise_speed: Input should be a finite number"),
    (lambda y: y.replace("heading_deg: 180.0", "heading_deg: .nan", 1),
     "airports[0].landing.heading_deg: Input should be a finite number"),
    (lambda y: y.replace("north: 273.9", "north: .nan", 1),
     "airports[0].north: Input should be a finite number"),
    # YAML reads yes, on and true as booleans, and pydantic took them for 1: one drone,
    # a cruise at 1 m/s, a corner at (1, 0)
    (lambda y: y.replace("drones: 3", "drones: yes"),
     "drones: True is a boolean, not valid here"),
    (lambda y: y.replace("handover_seconds: 15.0", "handover_seconds: on"),
     "handover_seconds: True is a boolean, not valid here"),
    (lambda y: y.replace("no_fly_zones: []", "no_fly_zones: [{points: [[true, 0], "
                                             "[0, 100], [100, 100]]}]"),
     "no_fly_zones[0].points: True is a boolean, not valid here"),
    # YAML's "\ud800" is half a surrogate pair, no character: the whole run was flown,
    # then its report could not be printed (a traceback) nor a store keep the name.
    # LibYAML's parser refuses the escape itself; PyYAML's own read it, and the field's
    # check names it
    (lambda y: y.replace("name: seed-3x3", 'name: "x\\ud800"'),
     "bad.yaml:1: not YAML: found invalid Unicode character escape code"
     if yaml.__with_libyaml__ else
     "name: 'x\\ud800' holds U+D800, half of a UTF-16 surrogate pair and no character"),
])
def test_bad_scenarios_name_the_field_and_the_file(tmp_path, edit, words):
    p = tmp_path / "bad.yaml"
    p.write_text(edit(sc.to_yaml(sc.preset("seed-3x3"))))
    with pytest.raises(InputFormatError) as info:
        sc.load_scenario(p)
    assert str(info.value).startswith(str(p)) and words in str(info.value)


@pytest.mark.parametrize("edit, words", [
    # PyYAML kept the last of two equal keys silently: a second 'drones: 9' further down
    # overrode the first unseen
    (lambda y: y + "drones: 9\n", "key 'drones' given twice in one mapping"),
    (lambda y: y.replace("  cruise_speed: 50.0\n", "  cruise_speed: 50.0\n  cruise_speed: 60\n"),
     "key 'cruise_speed' given twice in one mapping"),
])
def test_a_key_given_twice_is_refused_naming_its_second_line(tmp_path, edit, words):
    p = tmp_path / "twice.yaml"
    text = edit(sc.to_yaml(sc.preset("seed-3x3")))
    p.write_text(text)
    second = [n for n, row in enumerate(text.splitlines(), start=1)
              if row.strip().startswith(words.split("'")[1] + ":")][-1]
    with pytest.raises(InputFormatError) as err:
        sc.load_scenario(p)
    assert str(err.value) == f"{p}:{second}: not YAML: {words}"


def test_merge_keys_may_still_be_overridden(tmp_path):
    y = sc.to_yaml(sc.preset("seed-3x3"))
    p = tmp_path / "merge.yaml"
    p.write_text(y.replace("\ndrone:\n",
                           "\ndrone:\n  <<: {cruise_speed: 70.0, turn_radius: 300.0}\n", 1))
    drone = sc.load_scenario(p).drone  # the keys below the merge win, as YAML has it
    assert (drone.cruise_speed, drone.turn_radius) == (50.0, 250.0)
    p.write_text(y.replace("  taxi_speed: 10.0\n", "").replace(
        "\ndrone:\n", "\ndrone:\n  <<: {taxi_speed: 12.0}\n", 1))
    assert sc.load_scenario(p).drone.taxi_speed == 12.0  # and the merge fills the rest


@pytest.mark.parametrize("typo, words", [
    ("Airports", "Airports: unknown key; did you mean airports? valid: name, "),
    ("airport", "airport: unknown key; did you mean airports? valid: name, "),
])
def test_a_misspelt_required_key_is_named_not_reported_missing(tmp_path, typo, words):
    # it read "airports: Field required", hiding the typo that caused it
    p = tmp_path / "typo.yaml"
    p.write_text(sc.to_yaml(sc.preset("seed-3x3")).replace("airports:", f"{typo}:", 1))
    with pytest.raises(InputFormatError) as err:
        sc.load_scenario(p)
    assert re.match(rf"{re.escape(str(p))}:\d+: {re.escape(words)}", str(err.value))


def test_airports_closer_than_a_runway_are_refused():
    s = sc.preset("seed-3x3").model_dump()
    s["airports"][1]["north"] = s["airports"][0]["north"] + 100
    s["airports"][1]["east"] = s["airports"][0]["east"]
    with pytest.raises(InputFormatError, match="^s.yaml: airports: A and B are 100 m apart, "
                                               r"closer than a runway \(600 m\)$"):
        sc.parse_scenario(s, "s.yaml")


def _near(data: dict, k: int, north: float, east: float) -> list[float]:
    """A point ``north``, ``east`` metres from airport ``k`` of a scenario's data."""
    a = data["airports"][k]
    return [a["north"] + north, a["east"] + east]


def _along(data: dict, k: int, along: float, left: float = 0.0) -> list[float]:
    """A point ``along`` metres from airport ``k`` of a scenario's data along its take-off
    heading and ``left`` metres to the left of that line."""
    h = math.radians(data["airports"][k]["takeoff"]["heading_deg"])
    return _near(data, k, along * math.cos(h) + left * math.sin(h),
                 along * math.sin(h) - left * math.cos(h))


@pytest.mark.parametrize("gates", [
    [(0, 15), (0, -15)],  # where the defaults stand, half a gate width beside the runway
    [(-300, 16), (200, -15.5)],
    [(-316, 0), (0, 40)],  # on the line, behind the threshold: no drone goes there
])
def test_gates_beside_the_take_off_runway_are_allowed(gates):
    data = sc.preset("seed-3x3").model_dump()
    data["airports"][0]["gates"] = [_along(data, 0, *g) for g in gates]
    placed = np.array(sc.parse_scenario(data).airports[0].gates)
    assert placed == pytest.approx(np.array([_along(data, 0, *g) for g in gates]))


def test_the_default_gates_are_what_an_explicit_check_allows():
    """The default gates stand exactly half a gate width from the take-off runway's centre
    line and a gate width apart; given explicitly, with their rounding, they are allowed
    (they were refused as overlapping: 29.999999999999996 m apart)."""
    from skyroute.fleet.flightplan import gate_position

    data = sc.preset("seed-9x9").model_dump()
    s = sc.parse_scenario(data)
    default = [[gate_position(a, g).tolist() for g in (0, 1)] for a in s.airports]
    for k, gates in enumerate(default):
        data["airports"][k]["gates"] = gates
    placed = [a.gates for a in sc.parse_scenario(data).airports]
    assert np.array(placed) == pytest.approx(np.array(default), abs=0)


def _other_beside_first(d: dict) -> None:
    d["airports"][1]["north"], d["airports"][1]["east"] = _near(d, 0, 0, 100)


@pytest.mark.parametrize("edit, words", [
    # unknown fields, anywhere
    (lambda d: d.update(drone_count=3), "drone_count: unknown key; did you mean drone? "
     "valid: name, home_lat, home_lon, airports, drones, handover_seconds, drone, packages, "
     "airspace, no_fly_zones"),
    (lambda d: d["airports"][1].update(runway={"heading_deg": 0}),
     "airports[1].runway: unknown key; valid: id, north, east, landing, takeoff, "
     "gate_width, gates"),
    (lambda d: d["airports"][0]["landing"].update(lenght=900.0),
     "airports[0].landing.lenght: unknown key; did you mean length? valid: heading_deg, "
     "length"),
    # gates: overlapping, too many, too far, not a point
    (lambda d: d["airports"][0].update(gates=[_near(d, 0, 0, 5), _near(d, 0, 0, -5)]),
     "airports[0].gates: gates overlapping: 10 m apart, closer than gate_width (30 m)"),
    (lambda d: d["airports"][2].update(gate_width=50.0,
                                       gates=[_near(d, 2, 40, 0), _near(d, 2, 0, 0)]),
     "airports[2].gates: gates overlapping: 40 m apart, closer than gate_width (50 m)"),
    (lambda d: d["airports"][0].update(gates=[_near(d, 0, 0, 20)] * 3),
     "airports[0].gates: expected exactly two gates [[north, east], [north, east]], got 3"),
    (lambda d: d["airports"][2].update(gates=[_near(d, 2, 0, 20), _near(d, 2, 400, 400)]),
     "airports[2].gates: gate 1 is 566 m from the airport, farther than 500 m"),
    (lambda d: d["airports"][1].update(gates=[[0.0, 0.0, 5.0], _near(d, 1, 0, 50)]),
     "airports[1].gates[0]: Tuple should have at most 2 items"),
    # a gate on the take-off runway: a drone rolled through it while another stood there
    (lambda d: d["airports"][0].update(gates=[_along(d, 0, -100), _along(d, 0, 0, 40)]),
     "airports[0].gates: gate 0 stands on the take-off runway (0.0 m from its centre line, "
     "200 m from the threshold; less than half gate_width, 15 m): a drone taking off would "
     "roll through a drone at the gate"),
    (lambda d: d["airports"][2].update(gates=[_along(d, 2, 0, 40), _along(d, 2, 250, -5)]),
     "airports[2].gates: gate 1 stands on the take-off runway (5.0 m from its centre line, "
     "550 m from the threshold;"),
    (lambda d: d["airports"][1].update(gates=[_along(d, 1, 0, 40), _along(d, 1, 310, 0)]),
     "airports[1].gates: gate 1 stands on the take-off runway (10.0 m from its centre line, "
     "600 m from the threshold;"),  # past the far end, within half a gate of it
    # negative speeds
    (lambda d: d["drone"].update(cruise_speed=-50.0),
     "drone.cruise_speed: Input should be greater than 0"),
    (lambda d: d["drone"].update(taxi_speed=-10.0),
     "drone.taxi_speed: Input should be greater than 0"),
    # the layout
    (_other_beside_first, "airports: A and B are 100 m apart, closer than a runway (600 m)"),
    (lambda d: d["airports"][2].update(id="A"), "airports: ids must be unique"),
    # over the limits of skyroute.fleet.limits (each exhausted memory or ran for hours)
    (lambda d: d.update(drones=10**9), "drones: 1e+09 drones is over the limit of 1,000"),
    (lambda d: d["packages"].update(rate_per_hour=1e12),
     "packages.rate_per_hour: 1e+12 packages per hour is over the limit of 100,000"),
    (lambda d: d["airports"][2].update(north=1e12),
     "airports[2].north: 1e+12 m from home is over the limit of 100,000 m"),
    (lambda d: d.update(no_fly_zones=[{"points": [[0, 0], [0, 1e6], [1e3, 0]]}]),
     "no_fly_zones[0].points[1][1]: 1e+06 m from home is over the limit of 100,000 m"),
    (lambda d: d.update(airports=d["airports"] * 34),
     "airports: 102 airports is over the limit of 100"),
    # counted before a zone is read: 125,000 zones fit in a 10 MB request to the service
    (lambda d: d.update(no_fly_zones=[{"points": [[0, 0], [0, 9], [9, 0]]}] * 1001),
     "no_fly_zones: 1,001 zones is over the limit of 1,000"),
    (lambda d: d.update(no_fly_zones=[{"points": [[0, 0], [0, 9], [9, 0]] * 20_000},
                                      {"points": [[0, 0], [0, 9], [9, 0]] * 20_000}]),
     "no_fly_zones: 120,000 corners in all is over the limit of 100,000"),
    # a list of every level was made for each flight: a MemoryError traceback
    (lambda d: d["airspace"].update(shared_levels=10**9),
     "airspace.shared_levels: 1e+09 levels is over the limit of 1,000"),
])
def test_bad_scenario_files_give_one_line_naming_the_field(tmp_path, edit, words):
    p, msg = _refused(tmp_path, edit)
    assert re.match(rf"{re.escape(str(p))}:\d+: ", msg) and words in msg and "\n" not in msg


def _refused(tmp_path, edit) -> tuple:
    """(file, error) of seed-3x3 edited by ``edit``, written and read back."""
    import yaml

    data = sc.preset("seed-3x3").model_dump()
    edit(data)
    p = tmp_path / "bad.yaml"
    p.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(InputFormatError) as info:
        sc.load_scenario(p)
    return p, str(info.value)


@pytest.mark.parametrize("edit, words", [
    (lambda d: d["drone"].update(cruise_sped=50.0),
     "drone.cruise_sped: unknown key; did you mean cruise_speed?"),
    (lambda d: d["airports"][0].update(gates=[_near(d, 0, 0, 5), _near(d, 0, 0, -5)]),
     "airports[0].gates: gates overlapping"),
    (lambda d: d["drone"].update(cruise_speed=-50.0), "drone.cruise_speed: Input should be"),
    (_other_beside_first, "airports: A and B are 100 m apart, closer than a runway"),
    (lambda d: d["airports"][0].update(gates=[_along(d, 0, -100), _along(d, 0, 0, 40)]),
     "airports[0].gates: gate 0 stands on the take-off runway"),
])
def test_the_command_line_prints_one_line_and_exits_2(tmp_path, monkeypatch, capsys, edit,
                                                      words):
    import sys

    import yaml

    from skyroute.cli.app import main

    data = sc.preset("seed-3x3").model_dump()
    edit(data)
    p = tmp_path / "bad.yaml"
    p.write_text(yaml.safe_dump(data, sort_keys=False))
    monkeypatch.setattr(sys, "argv", ["skyroute", "fleet", "simulate", str(p), "--hours",
                                      "0.1"])
    with pytest.raises(SystemExit) as info:
        main()
    out, err = capsys.readouterr()
    assert info.value.code == 2 and out == ""
    assert err.count("\n") == 1 and re.search(rf"{re.escape(str(p))}:\d+: ", err)
    assert words in err


def test_a_gate_just_within_500_m_is_allowed():
    data = sc.preset("seed-3x3").model_dump()
    # gate 0 off the take-off runway (it was 6.8 m from its centre line, now refused)
    data["airports"][2]["gates"] = [_along(data, 2, 0, 20), _near(data, 2, 300, -399.9)]
    assert sc.parse_scenario(data).airports[2].gates[1] == tuple(_near(data, 2, 300, -399.9))


def test_explicit_gates_place_the_taxi_routes_and_round_trip(tmp_path):
    from skyroute.fleet.flightplan import gate_position, plan_flight
    from skyroute.fleet.simulate import run
    from skyroute.fleet.trajectory import check_continuous

    base = sc.preset("seed-3x3")
    data = base.model_dump()
    a, b = _near(data, 0, 120, 0), _near(data, 0, 120, 60)
    data["airports"][0]["gates"] = [a, b]
    s = sc.parse_scenario(data)
    A = s.airports[0]
    assert gate_position(A, 0).tolist() == a and gate_position(A, 1).tolist() == b
    # without gates, the derived ones: gate_width apart across the airport's position
    d0, d1 = gate_position(base.airports[0], 0), gate_position(base.airports[0], 1)
    assert math.dist(d0, d1) == pytest.approx(30.0)
    assert (d0 + d1) / 2 == pytest.approx([base.airports[0].north, base.airports[0].east])
    f = plan_flight(s, 0, "A", "B", depart=0.0, altitude=60.0, origin_gate=1)
    back = plan_flight(s, 0, "B", "A", depart=0.0, altitude=60.0, destination_gate=0)
    assert f.taxi_out_route[0].tolist() == b and back.taxi_in_route[-1].tolist() == a
    # the gate 120 m out is a longer taxi than the derived one 15 m out
    plain = plan_flight(base, 0, "A", "B", depart=0.0, altitude=60.0, origin_gate=1)
    assert f.phase("taxi_out").end > plain.phase("taxi_out").end
    p = tmp_path / "gates.yaml"
    p.write_text(sc.to_yaml(s))
    assert sc.load_scenario(p) == s
    sim = run(s, hours=0.5, seed=2)
    assert sim.flights and all(fl.plan.origin_gate in (0, 1) for fl in sim.flights)
    check_continuous(sim.pieces())


def test_limits_are_inclusive_and_toml_floats_count_as_drones(tmp_path):
    from skyroute.fleet.limits import MAX_DRONES, MAX_RATE

    data = sc.preset("seed-3x3").model_dump()
    data.update(drones=MAX_DRONES, packages={"rate_per_hour": MAX_RATE})
    s = sc.parse_scenario(data)
    assert s.drones == MAX_DRONES and s.packages.rate_per_hour == MAX_RATE
    p = tmp_path / "s.toml"
    p.write_text("drones = 1e9\n" + _toml_airports(data))  # TOML reads 1e9 as a float
    with pytest.raises(InputFormatError, match=r"s.toml: drones: 1e\+09 drones is over"):
        sc.load_scenario(p)


def _toml_airports(data: dict) -> str:
    lines = []
    for a in data["airports"]:
        lines += ["[[airports]]", f'id = "{a["id"]}"', f"north = {a['north']}",
                  f"east = {a['east']}",
                  f"landing = {{heading_deg = {a['landing']['heading_deg']}}}",
                  f"takeoff = {{heading_deg = {a['takeoff']['heading_deg']}}}"]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("kwargs, param, words", [
    ({"airports": 3, "drones": -1}, "drones", "drones=-1 must be 1 to 1,000"),
    ({"airports": 3, "drones": 1001}, "drones", "drones=1001 must be 1 to 1,000"),
    ({"airports": 1, "drones": 3}, "airports", "airports=1 must be 2 to 100"),
    ({"airports": 101, "drones": 3}, "airports", "airports=101 must be 2 to 100"),
    ({"airports": 3, "drones": 3, "area_km": 1e12}, "area_km", "area_km=1e+12 must be"),
    ({"airports": 3, "drones": 3, "rate_per_hour": 1e12}, "rate_per_hour", "<= 100,000"),
])
def test_generate_names_the_one_bad_argument(kwargs, param, words):
    from skyroute.errors import OptionError

    with pytest.raises(OptionError) as info:
        sc.generate(**kwargs)
    assert info.value.param == param and words in str(info.value)


# ------------------------------------------------------------------ runways and ground rolls

def _roll(h: float) -> float:
    return takeoff_phases(h, 20.0, 40.0, 50.0)[0]


@pytest.mark.parametrize("edit, words", [
    # 150 m strips: the take-off roll to the lowest level (294 m) and the roll-out (192 m)
    # ran off their ends, silently
    (lambda d: d["airports"][1]["takeoff"].update(length=150.0),
     f"airports[1].takeoff.length: 150 m is shorter than the take-off roll ({_roll(50):.0f}"
     " m to climb to the lowest level, 50 m)"),
    (lambda d: d["airports"][2]["landing"].update(length=150.0),
     "airports[2].landing.length: 150 m is shorter than the roll-out (drone.rollout, "
     "192 m)"),
    # too shallow a climb leaves no roll: it failed mid-run naming a --climb-angle-deg
    # flag that does not exist, and no file
    (lambda d: d["drone"].update(climb_angle_deg=5.0),
     "drone.climb_angle_deg: 5 degrees is too shallow: the climb to 50 m alone is longer "
     "than the seed's take-off distance"),
])
def test_runways_must_hold_the_ground_rolls(tmp_path, edit, words):
    p, msg = _refused(tmp_path, edit)
    assert re.fullmatch(rf"{re.escape(str(p))}:\d+: {re.escape(words)}", msg)


def test_runways_just_long_enough_are_allowed():
    data = sc.preset("seed-3x3").model_dump()
    data["airports"][0]["takeoff"]["length"] = math.ceil(_roll(50.0) * 1000) / 1000
    data["airports"][0]["landing"]["length"] = 192.0
    s = sc.parse_scenario(data)
    assert s.airports[0].landing.length == 192.0


@pytest.mark.parametrize("kwargs, name", [
    ({"airports": "3", "drones": 3}, "airports"), ({"airports": 3, "drones": "3"}, "drones"),
    ({"airports": 3, "drones": 3.5}, "drones"), ({"airports": 3, "drones": True}, "drones"),
    ({"airports": 3, "drones": 3, "area_km": "4"}, "area_km"),
    ({"airports": 3, "drones": 3, "seed": "1"}, "seed"),
    ({"airports": 3, "drones": 3, "seed": -1}, "seed"),
    ({"airports": 3, "drones": 3, "rate_per_hour": "60"}, "rate_per_hour")])
def test_generate_names_a_bad_type(kwargs, name):
    # TypeErrors, a pydantic ValidationError for 3.5 drones, numpy's for the seed; True
    # drones made a scenario named "3xTrue"
    with pytest.raises(OptionError, match=f"{name}=") as err:
        sc.generate(**kwargs)
    assert err.value.param == name


def test_generate_takes_numpy_numbers():
    import numpy as np

    a = sc.generate(np.int64(3), np.int64(3), area_km=np.float32(4.0), seed=np.int64(2))
    assert a == sc.generate(3, 3, area_km=4.0, seed=2)


SCENARIO_WITH_LINES = """\
name: hand-written
airports:
  - id: A
    north: 0
    east: 0
    landing: {heading_deg: 0}
    takeoff: {heading_deg: 90}
  - id: B
    north: 0
    east: 3000
    landing:
      heading_deg: 90
      length: 600
    takeoff:
      heading_deg: 0
      length: 600
drones: 2
drone:
  cruise_speed: 50
airspace:
  mode: layers
"""


@pytest.mark.parametrize("old, new, line, words", [
    ("drones: 2", "drones: 0", 17, "drones: Input should be greater than or equal to 1"),
    ("      heading_deg: 90\n", "      heading_deg: 360\n", 12,
     "airports[1].landing.heading_deg: Input should be less than 360"),
    ("  cruise_speed: 50", "  cruise_sped: 50", 19, "drone.cruise_sped: unknown key; did "
     "you mean cruise_speed?"),
    ("  mode: layers", "  mode: stacked", 21, "airspace.mode: Input should be 'layers' or"),
    # a check of several fields names its field first; the line is that field's
    ("      length: 600\n    takeoff", "      length: 100\n    takeoff", 13,
     "airports[1].landing.length: 100 m is shorter than the roll-out"),
    # a field left out: the line of the mapping it is missing from
    ("    takeoff: {heading_deg: 90}\n", "", 3, "airports[0].takeoff: Field required"),
    ("    east: 3000", "    east: 300", 2, "airports: A and B are 300 m apart"),
])
def test_a_yaml_scenarios_errors_name_the_line_of_the_field(tmp_path, old, new, line, words):
    # a hand-written scenario's errors named the field but not the line, though its YAML
    # syntax errors did
    p = tmp_path / "mine.yaml"
    assert SCENARIO_WITH_LINES.count(old) == 1
    p.write_text(SCENARIO_WITH_LINES.replace(old, new))
    with pytest.raises(InputFormatError) as err:
        sc.load_scenario(p)
    assert str(err.value).startswith(f"{p}:{line}: {words}")
    assert err.value.line == line
    sc.parse_scenario(__import__("yaml").safe_load(SCENARIO_WITH_LINES))  # itself valid


def test_a_toml_scenarios_errors_name_the_field_without_a_line(tmp_path):
    p = tmp_path / "mine.toml"
    p.write_text('drones = 0\n[[airports]]\nid = "A"\n')
    with pytest.raises(InputFormatError) as err:
        sc.load_scenario(p)
    assert str(err.value).startswith(f"{p}: ") and err.value.line is None
