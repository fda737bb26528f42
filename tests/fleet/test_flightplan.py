"""Flight plans: hand-worked times and points on a straight route, a route with turns
against the Dubins length, loiters, a seed preset, separation of two flights, errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from skyroute.errors import OptionError, QueryError
from skyroute.fleet.flightplan import (
    PHASES,
    gate_position,
    ground_position,
    horizontal_lengths,
    plan_flight,
)
from skyroute.fleet.scenario import Airport, Runway, Scenario, preset
from skyroute.fleet.separation import check
from skyroute.fleet.trajectory import ARC, Pieces, check_continuous, position
from skyroute.fleet.vehicle import takeoff_distance
from skyroute.motion.dubins import shortest_path

TAN20 = math.tan(math.radians(20))
TAN6 = math.tan(math.radians(6))


def two_airports() -> Scenario:
    """A lands northbound and takes off eastbound; B, 5 km east, lands eastbound: the
    flight A -> B climbs out on B's extended centre line (cruise is one straight)."""
    return Scenario(airports=[
        Airport(id="A", north=0, east=0, landing=Runway(heading_deg=0),
                takeoff=Runway(heading_deg=90)),
        Airport(id="B", north=0, east=5000, landing=Runway(heading_deg=90),
                takeoff=Runway(heading_deg=0))])


@pytest.fixture
def straight():
    return plan_flight(two_airports(), 1, "A", "B", depart=0.0, altitude=100.0)


def durations(plan) -> dict[str, float]:
    return {p.name: p.end - p.start for p in plan.phases}


# ------------------------------------------------------------------ a straight route

@pytest.mark.parametrize("gate", [0, 1])
def test_the_runway_times_are_when_the_taxi_passes_the_airport(gate):
    """The simulation books the take-off runway from ``out_at_position`` and the
    landing runway until ``in_at_position``: the drone is at the airport's position then
    (the taxi profile, slow near the gate; 10 m/s all the way put it there 2 s earlier
    and 3.5 s later than booked)."""
    f = plan_flight(two_airports(), 1, "A", "B", depart=5.0, altitude=100.0,
                    origin_gate=gate, destination_gate=gate)
    assert ground_position(f, f.out_at_position) == pytest.approx([0.0, 0.0], abs=1e-9)
    assert ground_position(f, f.in_at_position) == pytest.approx([0.0, 5000.0], abs=1e-9)
    # 15 m from the gate at 1 m/s, then away at 3 m/s: there 15 s after leaving
    assert f.out_at_position - f.depart == pytest.approx(15.0)
    assert f.at_gate - f.in_at_position == pytest.approx(15.0)


def test_phases_in_order_and_times_monotone(straight):
    names = [p.name for p in straight.phases]
    assert names == [n for n in PHASES if n != "loiter"]
    ends = np.array([(p.start, p.end) for p in straight.phases]).ravel()
    assert np.all(np.diff(ends) >= 0)
    for a, b in zip(straight.phases[:-1], straight.phases[1:], strict=True):
        assert a.end == b.start
    assert straight.depart == 0.0 and straight.landing_request == straight.phase("cruise").end
    assert straight.cleared == straight.landing_request == straight.phase("approach").start
    assert straight.touchdown == straight.phase("rollout").start
    assert straight.at_gate == straight.phase("taxi_in").end


def test_hand_worked_durations(straight):
    d = durations(straight)
    # taxi out: gate 15 m north of A, A, threshold 300 m west: 315 m at 1, 3, 10 m/s
    assert d["taxi_out"] == pytest.approx(15 / 1 + 15 / 3 + 285 / 10)
    roll = 609.2866 - 100 / TAN20  # 334.5389 m, from rest to 40 m/s
    assert d["takeoff"] == pytest.approx(2 * roll / 40)
    assert d["climb"] == pytest.approx(math.hypot(100 / TAN20, 100) / 50)
    final = 100 / TAN6  # 951.4364 m
    cruise = (4700 - final) - (-300 + 609.2866)  # climb-out to the approach gate
    assert d["cruise"] == pytest.approx(cruise / 50)
    assert d["approach"] == pytest.approx(math.hypot(final, 100) / 40)
    assert d["landing"] == 0.0
    assert d["rollout"] == pytest.approx(2 * 192 / 40)
    # taxi in: roll-out end 108 m west of B, then 15 m to gate 0: 93 + 15 + 15 m
    assert d["taxi_in"] == pytest.approx(93 / 10 + 15 / 3 + 15 / 1)


def test_roll_plus_climb_is_the_seed_regression(straight):
    roll_start, lift_off = straight.takeoff_roll
    top = straight.pieces.end()[0]  # the climb piece's end
    assert np.allclose(roll_start, [0, -300])
    assert math.hypot(*(top[:2] - roll_start)) == pytest.approx(takeoff_distance(100.0),
                                                                abs=1e-9)
    assert np.allclose(lift_off, [0, -300 + 609.2866 - 100 / TAN20], atol=1e-9)


def test_climb_piece_from_lift_off_to_climb_out(straight):
    p = straight.pieces
    start, end = p.start()[0], p.end()[0]
    assert np.allclose(start, [*straight.takeoff_roll[1], 0.0], atol=1e-9)
    assert np.allclose(end, [0, -300 + 609.2866, 100], atol=1e-9)
    assert p.t0[0] == straight.phase("climb").start and p.t1[0] == straight.phase("climb").end
    speed = math.sqrt(p.v_north[0] ** 2 + p.v_east[0] ** 2 + p.v_alt[0] ** 2)
    assert speed == pytest.approx(50.0)
    assert math.degrees(math.atan2(p.v_alt[0], p.v_east[0])) == pytest.approx(20.0)


def test_approach_gate_is_final_before_the_threshold(straight):
    final = 100 / TAN6
    assert np.allclose(straight.approach_gate, (0, 4700 - final, 100), atol=1e-9)
    p = straight.pieces
    last = len(p) - 1
    assert np.allclose(p.start()[last], straight.approach_gate, atol=1e-9)
    assert np.allclose(p.end()[last], [0, 4700, 0], atol=1e-9)
    assert p.t1[last] == straight.touchdown
    assert np.allclose(straight.rollout_roll, [[0, 4700], [0, 4892]])


def test_straight_cruise_is_one_line(straight):
    assert straight.cruise_path.word == "LSL"
    assert len(straight.pieces) == 3  # climb, cruise, approach
    assert horizontal_lengths(straight.pieces)[1] == pytest.approx(
        4700 - 100 / TAN6 - (-300 + 609.2866), abs=1e-9)


def test_gates_stand_left_and_right_of_the_take_off_heading():
    a = two_airports().airport("A")  # takes off eastbound: left is north
    assert np.allclose(gate_position(a, 0), [15, 0])
    assert np.allclose(gate_position(a, 1), [-15, 0])
    f = plan_flight(two_airports(), 1, "A", "B", depart=0.0, altitude=100.0, origin_gate=1,
                    destination_gate=1)
    assert np.allclose(f.taxi_out_route, [[-15, 0], [0, 0], [0, -300]])
    # B takes off northbound: its gate 1 (right) is east
    assert np.allclose(f.taxi_in_route, [[0, 4892], [0, 5000], [0, 5015]])


# ------------------------------------------------------------------ routes with turns

@pytest.mark.parametrize("origin,destination,altitude", [
    ("B", "A", 120.0), ("A", "B", 160.0), ("B", "A", 50.0)])
def test_cruise_pieces_join_and_add_up_to_the_dubins_length(origin, destination, altitude):
    f = plan_flight(two_airports(), 4, origin, destination, depart=30.0, altitude=altitude)
    check_continuous(f.pieces, tolerance=1e-6)
    cruise = Pieces.from_columns({k: getattr(f.pieces, k)[1:-1] for k in (
        "drone", "kind", "t0", "t1", "north", "east", "alt", "v_north", "v_east", "v_alt",
        "radius", "angle", "rate")})
    assert horizontal_lengths(cruise).sum() == pytest.approx(f.cruise_path.length, abs=1e-6)
    assert np.all(cruise.alt == altitude) and np.all(cruise.v_alt == 0)
    assert cruise.t0[0] == f.phase("cruise").start and cruise.t1[-1] == f.phase("cruise").end
    assert f.phase("cruise").end - f.phase("cruise").start == pytest.approx(
        f.cruise_path.length / 50)
    # the cruise path is the Dubins path of the climb-out and approach-gate poses
    s = f.cruise_path
    again = shortest_path(s.start, s.goal, 250.0)
    assert again.length == pytest.approx(s.length)
    # every arc turns the way the word says: L anticlockwise (rate < 0), R clockwise
    letters = [w for w, seg in zip(s.word, s.segments, strict=True) if seg > 1e-9]
    kinds = ["S" if k != ARC else ("R" if r > 0 else "L")
             for k, r in zip(cruise.kind, cruise.rate, strict=True)]
    assert kinds == letters
    assert np.all(np.abs(cruise.rate[cruise.kind == ARC]) == pytest.approx(50 / 250))


def test_b_to_a_turns_left_then_right():
    """B takes off northbound from (-300, 5000); A's approach runs northbound to (-300, 0):
    the drone turns left (west), flies straight, and turns right (north) onto final."""
    f = plan_flight(two_airports(), 4, "B", "A", depart=0.0, altitude=120.0)
    assert f.cruise_path.word == "LSR"
    gate = f.approach_gate
    assert np.allclose(gate, (-300 - 120 / TAN6, 0, 120), atol=1e-9)
    # the drone's heading at the approach gate is north
    t = f.landing_request
    ahead = position(f.pieces, [t - 1e-3, t], drone=4)
    assert np.allclose((ahead[1] - ahead[0])[:2] / 1e-3, [50, 0], atol=1e-2)


# ------------------------------------------------------------------ loiters

def test_loiter_is_one_left_hand_circle_through_the_approach_gate(straight):
    t = 1000.0
    c = straight.loiter(t)
    assert len(c) == 1 and c.kind[0] == ARC and c.rate[0] == pytest.approx(-50 / 250)
    assert straight.loiter_seconds == pytest.approx(2 * math.pi * 250 / 50)
    assert c.t1[0] - c.t0[0] == pytest.approx(straight.loiter_seconds) and c.t0[0] == t
    gate = np.array(straight.approach_gate)
    assert np.allclose(c.start()[0], gate, atol=1e-9)
    assert np.allclose(c.end()[0], gate, atol=1e-9)
    # landing eastbound, a left-hand circle lies to the north: half way round, 500 m north
    half = position(c, [t + straight.loiter_seconds / 2], drone=1)[0]
    assert np.allclose(half, gate + np.array([500, 0, 0]), atol=1e-9)
    # leaving the gate eastbound, like the approach
    step = position(c, [t, t + 1e-3], drone=1)
    assert np.allclose((step[1] - step[0]) / 1e-3, [0, 50, 0], atol=1e-2)


def test_right_hand_loiter():
    f = plan_flight(two_airports(), 1, "A", "B", depart=0.0, altitude=100.0,
                    loiter_side="right")
    assert f.loiter_rate == pytest.approx(50 / 250)
    assert np.allclose(f.loiter_centre, [-250, f.approach_gate[1]])


@pytest.mark.parametrize("n", [1, 3])
def test_with_loiters_shifts_the_approach_and_later(straight, n):
    g = straight.with_loiters(n)
    shift = n * straight.loiter_seconds
    assert g.loiters == n and g.landing_request == straight.landing_request
    assert g.cleared == pytest.approx(straight.landing_request + shift)
    assert [p.name for p in g.phases] == [
        "taxi_out", "takeoff", "climb", "cruise", "loiter", "approach", "landing",
        "rollout", "taxi_in"]
    assert g.phase("loiter") == ("loiter", straight.landing_request,
                                 straight.landing_request + shift)
    for name in ("approach", "landing", "rollout", "taxi_in"):
        assert g.phase(name).start == pytest.approx(straight.phase(name).start + shift)
        assert g.phase(name).end == pytest.approx(straight.phase(name).end + shift)
    for name in ("taxi_out", "takeoff", "climb", "cruise"):
        assert g.phase(name) == straight.phase(name)
    assert len(g.pieces) == len(straight.pieces) + n
    check_continuous(g.pieces, tolerance=1e-6)
    # every junction is a junction in time too: lift-off to touchdown without a gap
    assert np.all(g.pieces.t0[1:] == g.pieces.t1[:-1])
    assert g.pieces.t0[0] == g.phase("climb").start and g.pieces.t1[-1] == g.touchdown
    assert straight.with_loiters(0) is straight
    # loiters add up
    twice = straight.with_loiters(1).with_loiters(n - 1) if n > 1 else g
    assert twice.at_gate == pytest.approx(g.at_gate)
    assert len(twice.pieces) == len(g.pieces)
    check_continuous(twice.pieces)


def test_whole_flight_is_continuous_from_lift_off_to_touchdown(straight):
    p = straight.pieces
    check_continuous(p, tolerance=1e-6)
    assert np.all(p.t0[1:] == p.t1[:-1])
    assert np.allclose(p.start()[0], [*straight.takeoff_roll[1], 0])
    assert np.allclose(p.end()[-1], [*straight.rollout_roll[0], 0])


# ------------------------------------------------------------------ a seed preset

def test_a_flight_of_the_seed_3x3_preset():
    s = preset("seed-3x3")
    a, b = s.airports[0], s.airports[1]
    f = plan_flight(s, 2, a.id, b.id, depart=100.0, altitude=60.0, destination_gate=1)
    check_continuous(f.pieces, tolerance=1e-6)
    assert np.all(f.pieces.t0[1:] == f.pieces.t1[:-1])
    assert f.depart == 100.0 and f.pieces.drone.tolist() == [2] * len(f.pieces)
    cruise = horizontal_lengths(f.pieces)[1:-1].sum()
    assert cruise == pytest.approx(f.cruise_path.length, abs=1e-6)
    d = durations(f)
    assert d["cruise"] == pytest.approx(f.cruise_path.length / s.drone.cruise_speed)
    assert d["rollout"] == pytest.approx(2 * s.drone.rollout / s.drone.landing_speed)
    # touchdown on B's landing threshold, the approach gate final before it
    h = math.radians(b.landing.heading_deg)
    thr = np.array([b.north, b.east]) - 300 * np.array([math.cos(h), math.sin(h)])
    assert np.allclose(f.pieces.end()[-1], [*thr, 0], atol=1e-9)
    gate = thr - 60 / TAN6 * np.array([math.cos(h), math.sin(h)])
    assert np.allclose(f.approach_gate, (*gate, 60), atol=1e-9)
    assert np.allclose(f.taxi_in_route[-1], gate_position(b, 1))
    times = np.array([(p.start, p.end) for p in f.phases]).ravel()
    assert np.all(np.diff(times) >= 0)


# ------------------------------------------------------------------ separation

def test_two_flights_ten_metres_apart_do_not_conflict():
    """The same route at 100 and 110 m: cruising at once, exactly 10 m apart (no loss);
    whole flights two minutes apart on the runway never meet either."""
    s = two_airports()
    low = plan_flight(s, 1, "B", "A", depart=0.0, altitude=100.0)
    high = plan_flight(s, 2, "B", "A", depart=0.0, altitude=110.0)

    def cruise(f):
        rows = np.flatnonzero((f.pieces.t0 >= f.phase("cruise").start)
                              & (f.pieces.t1 <= f.phase("cruise").end))
        return Pieces(**{k: getattr(f.pieces, k)[rows] for k in (
            "drone", "kind", "t0", "t1", "north", "east", "alt", "v_north", "v_east",
            "v_alt", "radius", "angle", "rate")})

    report = check(Pieces.concat([cruise(low), cruise(high)]))
    assert report.conflicts == () and report.min_vertical_m == pytest.approx(10.0)
    later = plan_flight(s, 2, "B", "A", depart=120.0, altitude=110.0)
    assert check(Pieces.concat([low.pieces, later.pieces])).conflicts == ()


def test_two_flights_at_one_altitude_leaving_together_conflict():
    s = two_airports()
    one = plan_flight(s, 1, "B", "A", depart=0.0, altitude=100.0)
    two = plan_flight(s, 2, "B", "A", depart=0.0, altitude=100.0)
    report = check(Pieces.concat([one.pieces, two.pieces]))
    assert len(report.conflicts) == 1
    c = report.conflicts[0]
    assert (c.drone_a, c.drone_b) == (1, 2) and c.min_horizontal_m == pytest.approx(0.0)


# ------------------------------------------------------------------ errors

@pytest.mark.parametrize("kwargs,param", [
    ({"destination": "A"}, "destination"),
    ({"altitude": 49.0}, "altitude"),
    ({"altitude": math.nan}, "altitude"),
    ({"depart": math.inf}, "depart"),
    ({"origin_gate": 2}, "origin_gate"),
    ({"destination_gate": -1}, "destination_gate"),
    ({"loiter_side": "up"}, "loiter_side"),
])
def test_bad_flights_raise_option_errors_naming_the_parameter(kwargs, param):
    args = {"destination": "B", "depart": 0.0, "altitude": 100.0} | kwargs
    with pytest.raises(OptionError) as err:
        plan_flight(two_airports(), 1, "A", args.pop("destination"), **args)
    assert err.value.param == param


def test_same_airport_and_unknown_airport_are_refused():
    with pytest.raises(OptionError, match="is the origin"):
        plan_flight(two_airports(), 1, "B", "B", depart=0.0, altitude=100.0)
    with pytest.raises(OptionError, match="no airport 'C'; airports: A, B"):
        plan_flight(two_airports(), 1, "A", "C", depart=0.0, altitude=100.0)


def test_bad_loiter_count_and_phase_name(straight):
    with pytest.raises(OptionError) as err:
        straight.with_loiters(-1)
    assert err.value.param == "n"
    with pytest.raises(OptionError, match="choose one of 'taxi_out'"):
        straight.phase("loiter")


# ------------------------------------------------------------------ on the ground

def test_ground_position_hand_worked(straight):
    t_roll = straight.phase("takeoff")
    t_out = straight.phase("rollout")
    t_in = straight.phase("taxi_in")
    roll = 609.2866 - 100 / TAN20
    g = ground_position(straight, [
        0.0,  # gate 0 of A
        15.0,  # half a gate width at 1 m/s: A itself
        20.0,  # then 15 m at 3 m/s: 15 m west of A
        30.0,  # then 10 s at 10 m/s: 115 m west of A
        t_roll.start + (t_roll.end - t_roll.start) / 2,  # a quarter of the roll
        t_roll.end,  # lift-off
        t_out.start,  # touchdown
        t_out.start + 4.8,  # half the roll-out time: three quarters of 192 m
        t_in.end - 15.0,  # half a gate width from the gate: B itself
        t_in.end,  # gate 0 of B: B takes off northbound, so its left gate is 15 m west
        straight.phase("cruise").start,  # airborne
        -1.0,  # not yet
    ])
    expect = [[15, 0], [0, 0], [0, -15], [0, -115], [0, -300 + roll / 4],
              [0, -300 + roll], [0, 4700], [0, 4700 + 144], [0, 5000], [0, 4985]]
    assert np.allclose(g[:10], expect, atol=1e-9)
    assert np.isnan(g[10:]).all()


def test_a_take_off_roll_longer_than_the_runway_is_refused():
    # the roll grows with the level (the seed's regression less a fixed-angle climb):
    # 294 m to 50 m, 326 m to 90 m; a 320 m runway takes the first, not the second
    s = two_airports()
    data = s.model_dump()
    data["airports"][0]["takeoff"]["length"] = 320.0
    s = Scenario.model_validate(data)
    assert plan_flight(s, 1, "A", "B", depart=0.0, altitude=50.0).phase("climb")
    with pytest.raises(QueryError) as err:
        plan_flight(s, 1, "A", "B", depart=0.0, altitude=90.0)
    assert str(err.value) == ("airport A's take-off runway (320 m) is shorter than the "
                              "take-off roll to climb to 90 m (326 m)")
