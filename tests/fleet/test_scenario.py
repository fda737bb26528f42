"""Fleet model parameters: the seed's kinematics and scenario files with named errors."""

from __future__ import annotations

import math

import pytest

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


@pytest.mark.parametrize("edit, words", [
    (lambda y: y.replace("cruise_speed: 50.0", "cruise_sped: 50.0"),
     "drone.cruise_sped: Extra inputs are not permitted"),
    (lambda y: y.replace("landing_speed: 40.0", "landing_speed: -40.0"),
     "drone.landing_speed: Input should be greater than 0"),
    (lambda y: y.replace("gate_width: 30.0", "gate_width: 0", 1),
     "airports[0].gate_width: Input should be greater than 0"),
    (lambda y: y.replace("heading_deg: 180.0", "heading_deg: 400", 1),
     "airports[0].landing.heading_deg: Input should be less than 360"),
    (lambda y: y.replace("mode: layers", "mode: stacked"),
     "airspace.mode: Input should be 'layers' or 'shared'"),
    (lambda y: y + "  : [\n", "not YAML"),
])
def test_bad_scenarios_name_the_field_and_the_file(tmp_path, edit, words):
    p = tmp_path / "bad.yaml"
    p.write_text(edit(sc.to_yaml(sc.preset("seed-3x3"))))
    with pytest.raises(InputFormatError) as info:
        sc.load_scenario(p)
    assert str(info.value).startswith(str(p)) and words in str(info.value)


def test_airports_closer_than_a_runway_are_refused():
    s = sc.preset("seed-3x3").model_dump()
    s["airports"][1]["north"] = s["airports"][0]["north"] + 100
    s["airports"][1]["east"] = s["airports"][0]["east"]
    with pytest.raises(InputFormatError, match="airports A and B are 100 m apart, closer "
                                               "than a runway"):
        sc.parse_scenario(s, "s.yaml")
