"""The separation checker on hand-made encounters with values worked out by hand, a
property against dense sampling, a brute-force comparison on a small synthetic fleet,
and its errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from skyroute.errors import OptionError, QueryError
from skyroute.fleet.separation import Conflict, check
from skyroute.fleet.trajectory import Pieces, Trajectory, arc_piece, line_piece, position

TOL = 1e-6


def fleet(*rows) -> Pieces:
    return Pieces.from_rows(rows)


def one(report) -> Conflict:
    assert len(report.conflicts) == 1, report.conflicts
    return report.conflicts[0]


# ------------------------------------------------------------------ straight encounters

def crossing(alt_b: float = 100.0) -> Pieces:
    """1 flies east along north = 0, 2 north along east = 0 one second later than a
    collision course: offset (1020 - 20 t, 20 t - 1000), closest (10, 10) at t = 50.5."""
    return fleet(line_piece(1, 0, 100, (0, -1000, 100), (0, 20, 0)),
                 line_piece(2, 0, 100, (-1020, 0, alt_b), (20, 0, 0)))


def test_crossing_at_one_level_conflicts_at_the_exact_closest_approach():
    r = check(crossing())
    c = one(r)
    # |offset|^2 = 200 + 800 u^2 with u = t - 50.5: below 50^2 while |u| < sqrt(2300/800)
    half = math.sqrt(2300 / 800)
    assert (c.drone_a, c.drone_b) == (1, 2)
    assert c.t_min == pytest.approx(50.5, abs=1e-9)
    assert c.min_horizontal_m == pytest.approx(10 * math.sqrt(2), abs=1e-9)
    assert c.vertical_m_at_min == 0
    assert c.t_start == pytest.approx(50.5 - half, abs=1e-9)
    assert c.t_end == pytest.approx(50.5 + half, abs=1e-9)
    assert r.min_horizontal_m == pytest.approx(10 * math.sqrt(2), abs=1e-9)
    assert r.min_vertical_m == 0
    assert not r.separated and r.pairs_checked == 1


def test_crossing_exactly_sep_vertical_apart_is_no_loss():
    r = check(crossing(alt_b=110.0))
    assert r.separated
    assert r.min_vertical_m == 10.0  # while within 50 m horizontally
    assert r.min_horizontal_m == math.inf  # never closer than 10 m vertically
    assert not check(crossing(alt_b=109.999)).separated


def test_climb_through_a_cruising_drones_level_as_it_passes():
    # 2 climbs at 2 m/s, 4 m below 1's level at t = 50 when both are at (0, 0)
    r = check(fleet(line_piece(1, 0, 100, (0, -1000, 100), (0, 20, 0)),
                    line_piece(2, 0, 100, (-1000, 0, -4), (20, 0, 2))))
    c = one(r)
    half = 50 / (20 * math.sqrt(2))  # |offset| = sqrt(2) |1000 - 20 t| < 50
    assert c.t_min == pytest.approx(50, abs=1e-9)
    assert c.min_horizontal_m == pytest.approx(0, abs=1e-9)
    assert c.vertical_m_at_min == pytest.approx(4, abs=1e-9)
    assert (c.t_start, c.t_end) == pytest.approx((50 - half, 50 + half), abs=1e-9)
    # within 50 m horizontally dz = 104 - 2 t is smallest at the end: 4 - 2 * half
    assert r.min_vertical_m == pytest.approx(4 - 2 * half, abs=1e-9)


@pytest.mark.parametrize("apart, conflict", [(51.0, False), (49.0, True)])
def test_parallel_tracks_head_on(apart, conflict):
    r = check(fleet(line_piece(1, 0, 100, (0, -1000, 100), (0, 20, 0)),
                    line_piece(2, 0, 100, (apart, 1000, 100), (0, -20, 0))))
    assert r.min_horizontal_m == pytest.approx(apart, abs=1e-9)
    assert r.separated is not conflict
    if conflict:
        c = one(r)
        half = math.sqrt(50**2 - apart**2) / 40  # offset (apart, 40 (t - 50))
        assert (c.t_start, c.t_end) == pytest.approx((50 - half, 50 + half), abs=1e-9)
        assert c.min_horizontal_m == pytest.approx(apart, abs=1e-9)


def test_closest_approach_between_samples_is_exact():
    # head-on 30 m apart at a closing speed of 90 m/s, passing at t = 10.37
    f = fleet(line_piece(1, 0, 20, (0, -466.65, 100), (0, 45, 0)),
              line_piece(2, 0, 20, (30, 466.65, 100), (0, -45, 0)))
    seconds = np.arange(21.0)
    sampled = np.linalg.norm(position(f, seconds, drone=1)[:, :2]
                             - position(f, seconds, drone=2)[:, :2], axis=1)
    assert sampled.min() > 44.8  # 1 s sampling sees sqrt(30^2 + 33.3^2) at best
    c = one(check(f))
    assert c.min_horizontal_m == pytest.approx(30, abs=TOL)
    assert c.t_min == pytest.approx(10.37, abs=1e-9)


def test_a_loss_across_a_piece_junction_is_one_event():
    split = fleet(line_piece(1, 0, 50.5, (0, -1000, 100), (0, 20, 0)),
                  line_piece(1, 50.5, 100, (0, 10, 100), (0, 20, 0)),
                  line_piece(2, 0, 100, (-1020, 0, 100), (20, 0, 0)))
    whole = one(check(crossing()))
    c = one(check(split))
    assert c == pytest.approx(whole, abs=1e-9)


# ------------------------------------------------------------------------ arcs

W = 0.05  # rad/s: 15 m/s on the 300 m loiter


def loiter_and_pass(miss: float) -> Pieces:
    """1 loiters clockwise on r = 300 about (0, 0), at angle 0 (due north of the centre,
    heading east at 15 m/s) at t = 100; 2 flies east at 15 m/s along north = miss and is
    due north of the centre at t = 100. With th = W (t - 100) the offset is
    (miss - 300 cos th, 300 (th - sin th)), so the closest approach is miss - 300, at
    t = 100 and only then."""
    return fleet(arc_piece(1, 0, 400, (0, 0), 300, -100 * W, W, 100),
                 line_piece(2, 0, 200, (miss, -1500, 100), (0, 15, 0)))


def loiter_distance(miss: float, t: float) -> float:
    th = W * (t - 100)
    return math.hypot(miss - 300 * math.cos(th), 300 * (th - math.sin(th)))


@pytest.mark.parametrize("miss", [340.0, 350.0, 360.0])
def test_loiter_and_a_straight_pass(miss):
    r = check(loiter_and_pass(miss))
    closest = miss - 300
    # a certified lower bound, at most the tolerance below the truth
    assert closest - TOL <= r.min_horizontal_m <= closest + 1e-9
    if miss == 340:
        c = one(r)
        assert closest - TOL <= c.min_horizontal_m <= closest + 1e-9
        assert c.t_min == pytest.approx(100, abs=1e-2)
        start = brentq(lambda t: loiter_distance(miss, t) - 50, 50, 100)
        end = brentq(lambda t: loiter_distance(miss, t) - 50, 100, 150)
        # the stretch contains the loss and overshoots it by less than TOL metres
        assert c.t_start <= start and c.t_end >= end
        assert loiter_distance(miss, c.t_start) < 50 + TOL
        assert loiter_distance(miss, c.t_end) < 50 + TOL
    elif miss == 360:
        assert r.separated and r.min_vertical_m == math.inf
    else:  # exactly 50 m at the closest: not a loss, though within the tolerance
        assert all(c.min_horizontal_m >= 50 - TOL for c in r.conflicts)


@pytest.mark.parametrize("radius", [300.0, 30.0])
def test_same_circle_same_direction_quarter_turn_apart_keeps_the_chord(radius):
    rate = 15 / radius
    r = check(fleet(arc_piece(1, 0, 200, (500, 500), radius, 0.0, rate, 100),
                    arc_piece(2, 0, 200, (500, 500), radius, math.pi / 2, rate, 100)))
    chord = radius * math.sqrt(2)
    assert chord - TOL <= r.min_horizontal_m <= chord + 1e-9
    if radius == 300:
        assert r.separated
    else:  # 42.4 m apart the whole time: one loss from start to end
        c = one(r)
        assert (c.t_start, c.t_end) == (0, 200)
        assert chord - TOL <= c.min_horizontal_m <= chord + 1e-9


def test_a_drone_crossing_a_loiter_circle():
    # 2 flies north along east = 0 and meets the circle at (-300, 0) at t = 35, just as
    # 1 gets there (angle pi); at its exit (300, 0) at t = 65, 1 is far round the circle
    a0 = math.pi - 35 * W
    f = fleet(arc_piece(1, 0, 100, (0, 0), 300, a0, W, 100),
              line_piece(2, 0, 100, (-1000, 0, 100), (20, 0, 0)))
    r = check(f)
    c = one(r)
    assert (c.drone_a, c.drone_b) == (1, 2)
    assert c.min_horizontal_m == pytest.approx(0, abs=TOL)
    assert c.t_min == pytest.approx(35, abs=1e-3)

    def dist(t):
        th = a0 + W * t
        return math.hypot(300 * math.cos(th) - (-1000 + 20 * t), 300 * math.sin(th))

    start, end = brentq(lambda t: dist(t) - 50, 30, 35), brentq(lambda t: dist(t) - 50, 35, 40)
    assert c.t_start <= start < c.t_start + 1e-6 and c.t_end - 1e-6 < end <= c.t_end
    assert dist(65) > 400


# ------------------------------------------------------- against dense sampling

def _extend(draw, tr: Trajectory, t1: float) -> None:
    """One random piece on ``tr`` until ``t1``: a line or an arc (or a helix)."""
    if draw(st.booleans()):
        tr.line(t1, (draw(st.floats(-40, 40)), draw(st.floats(-40, 40)),
                     draw(st.floats(-2, 2))))
        return
    radius = draw(st.floats(10, 400))
    bearing = draw(st.floats(-math.pi, math.pi))
    speed = draw(st.floats(0, 40))
    rate = draw(st.sampled_from([-1.0, 1.0])) * speed / radius
    centre = tr.position[:2] + radius * np.array([math.cos(bearing), math.sin(bearing)])
    tr.arc(t1, centre, rate, v_alt=draw(st.floats(-2, 2)))


@st.composite
def two_drones(draw):
    """Two drones flying one to three continuous pieces (lines, arcs) over [0, T]; piece
    ends fall halfway between the samples of a 1e4-step grid."""
    T = draw(st.floats(10, 200))
    n = 10_000
    parts = []
    for drone in (1, 2):
        start = (draw(st.floats(-300, 300)), draw(st.floats(-300, 300)), draw(st.floats(0, 30)))
        tr = Trajectory(drone, 0.0, start)
        cuts = sorted(draw(st.sets(st.integers(1, n - 2), max_size=2)))
        for t1 in [*((k + 0.5) * T / n for k in cuts), T]:
            _extend(draw, tr, t1)
        parts.append(tr.pieces())
    return T, n, Pieces.concat(parts)


def _speed(p: Pieces) -> float:
    return float(np.max(np.where(p.kind == 1, p.radius * np.abs(p.rate),
                                 np.hypot(p.v_north, p.v_east))))


@settings(max_examples=150, deadline=None)
@given(two_drones())
def test_never_misses_a_closer_approach_and_is_never_optimistic(case):
    T, n, f = case
    ts = np.linspace(0, T, n + 1)
    a, b = position(f, ts, drone=1), position(f, ts, drone=2)
    h = np.linalg.norm(a[:, :2] - b[:, :2], axis=1)
    dz = np.abs(a[:, 2] - b[:, 2])
    # every time counts vertically: min_horizontal_m is the plain closest approach
    r = check(f, sep_vertical=1e9)
    sampling = (2 * _speed(f)) * (T / n) / 2
    assert r.min_horizontal_m <= h.min() + 1e-9
    assert r.min_horizontal_m >= h.min() - TOL - sampling - 1e-9
    # with the default minima: every sampled loss lies in a reported one
    r = check(f, sep_horizontal=50, sep_vertical=10)
    lost = ts[(h < 50) & (dz < 10)]
    spans = np.array([(c.t_start, c.t_end) for c in r.conflicts]).reshape(-1, 2)
    inside = (lost[:, None] >= spans[:, 0]) & (lost[:, None] <= spans[:, 1])
    assert inside.any(axis=1).all()
    for c in r.conflicts:
        assert c.min_horizontal_m < 50 and c.vertical_m_at_min < 10 + 1e-9
        k = (ts >= c.t_start) & (ts <= c.t_end)
        if k.any():
            assert c.min_horizontal_m <= h[k].min() + 1e-9
    near = h < 50
    if near.any():
        assert r.min_vertical_m <= dz[near].min() + 1e-9


# --------------------------------------------------------------- a small fleet

def synthetic_fleet(drones: int, hours: float, *, seed: int, size: float = 30_000.0,
                    airports: int = 20) -> Pieces:
    """Drones shuttling between random airports in a ``size`` metre square: climb out,
    cruise to a dog-leg turn (an arc), cruise on, a descending loiter helix, final
    descent, a few minutes on the ground; about 20 pieces per drone-hour."""
    rng = np.random.default_rng(seed)
    ports = rng.uniform(0, size, (airports, 2))
    end = hours * 3600.0
    parts = []
    for d in range(drones):
        here = int(rng.integers(airports))
        tr = Trajectory(d, rng.uniform(0, 900), (*ports[here], 0.0))
        while tr.t < end:
            there = (here + int(rng.integers(1, airports))) % airports
            cruise = float(rng.choice([60.0, 90.0, 120.0]))
            speed = rng.uniform(20, 30)
            a, b = ports[here], ports[there]
            u = (b - a) / np.linalg.norm(b - a)
            side = np.array([-u[1], u[0]])
            climb = cruise / 5
            tr.line(tr.t + climb, (*(u * speed), 5.0))
            mid = (a + b) / 2 + side * rng.uniform(-2000, 2000)
            leg = np.linalg.norm(mid - tr.position[:2])
            tr.line_to(tr.t + leg / speed, (*mid, cruise))
            turn = float(rng.choice([-1.0, 1.0]))
            tr.arc(tr.t + rng.uniform(10, 30), mid + side * 200 * turn, turn * speed / 200)
            gate = b - u * 600
            leg = np.linalg.norm(gate - tr.position[:2])
            tr.line_to(tr.t + leg / speed, (*gate, cruise))
            hold = rng.uniform(60, 180)
            tr.arc(tr.t + hold, b - u * 300, turn * speed / 300, v_alt=(30 - cruise) / hold)
            leg = np.linalg.norm(b - tr.position[:2])
            tr.line_to(tr.t + max(leg / speed, 10.0), (*b, 0.0))
            tr.ground(tr.t + rng.uniform(120, 300), (*b, 0.0))
            here = there
        parts.append(tr.pieces())
    return Pieces.concat(parts)


def test_small_fleet_agrees_with_brute_force_sampling():
    f = synthetic_fleet(40, 0.5, seed=3, size=8000.0, airports=5)
    r = check(f)
    assert not r.separated  # a crowded sky: there is something to find
    ts = np.arange(0, 1800, 0.5)
    pos = position(f, ts)  # (drones, times, 3), NaN on the ground
    ids = f.drones
    for x in range(len(ids)):
        h = np.linalg.norm(pos[x, None, :, :2] - pos[x + 1:, :, :2], axis=-1)
        dz = np.abs(pos[x, None, :, 2] - pos[x + 1:, :, 2])
        for y, k in zip(*np.nonzero((h < 50) & (dz < 10)), strict=True):
            a, b = ids[x], ids[x + 1 + y]
            assert any(c.drone_a == a and c.drone_b == b and c.t_start <= ts[k] <= c.t_end
                       for c in r.conflicts), (a, b, ts[k])
    for c in r.conflicts:
        assert c.drone_a < c.drone_b and c.t_start <= c.t_min <= c.t_end
        # the closest may be where the stretch ends, |dz| = 10 exactly (its infimum)
        assert c.min_horizontal_m < 50 and c.vertical_m_at_min <= 10


def test_across_cores_the_report_is_the_same(monkeypatch):
    from skyroute.fleet import separation

    f = synthetic_fleet(30, 0.5, seed=5, size=8000.0, airports=5)
    serial = check(f)
    monkeypatch.setattr(separation, "_SERIAL_BELOW", 0)  # the prange kernels
    assert check(f) == serial


def test_row_order_does_not_change_the_report():
    f = synthetic_fleet(30, 0.5, seed=5, size=8000.0, airports=5)
    perm = np.random.default_rng(0).permutation(len(f))
    g = Pieces(**{k: getattr(f, k)[perm] for k in f.__dataclass_fields__})
    assert check(f) == check(g)


# ------------------------------------------------------------------------ errors

@pytest.mark.parametrize("option, value", [("sep_horizontal", -1.0), ("sep_vertical", -0.5),
                                           ("sep_vertical", math.nan), ("tolerance", 0.0)])
def test_bad_options_name_the_option(option, value):
    with pytest.raises(OptionError, match=option) as err:
        check(crossing(), **{option: value})
    assert err.value.param == option


@pytest.mark.parametrize("value", ["5", True, b"5", None])
def test_options_that_are_not_numbers_are_refused(value):
    # float() read "5" as 5.0 and True as 1.0: every other option of skyroute refuses them
    # (skyroute.errors.real)
    for option in ("sep_horizontal", "sep_vertical", "tolerance"):
        with pytest.raises(OptionError) as err:
            check(crossing(), **{option: value})
        assert str(err.value) == (f"{option}={value!r} must be a number "
                                  f"{'> 0' if option == 'tolerance' else '>= 0'}")
        assert err.value.param == option


def test_numpy_numbers_are_options_as_floats_are():
    assert check(crossing(), sep_horizontal=np.float32(50), sep_vertical=np.array(10),
                 tolerance=np.float64(1e-6)) == check(crossing())


@pytest.mark.parametrize("column, values, shown", [
    ("t0", ["0", "0"], "t0[0]='0'"),  # numpy's float() conversion read these as numbers
    ("alt", [100.0, "100"], "alt[1]='100'"),
    ("drone", [True, False], "drone[0]=True"),
    ("radius", np.array([0, False], dtype=object), "radius[1]=False"),
])
def test_columns_that_are_not_numbers_are_refused(column, values, shown):
    with pytest.raises(QueryError) as err:
        check({**_columns(), column: values})
    assert str(err.value) == f"{shown} must be a number"
    assert err.value.param == column


def test_columns_of_numbers_in_any_container_are_read():
    cols = {k: list(v) for k, v in _columns().items()}
    cols["t1"] = np.array([100, 100], dtype=object)
    cols["drone"] = np.array([1, 2], dtype=np.uint8)
    assert check(cols) == check(crossing())


def _columns(**change):
    cols = {k: np.asarray(getattr(crossing(), k)).copy() for k in crossing().__dataclass_fields__}
    for k, (row, value) in change.items():
        cols[k] = cols[k].astype(float)
        cols[k][row] = value
    return cols


@pytest.mark.parametrize("change, field", [
    ({"t0": (0, math.nan)}, "t0"),
    ({"alt": (1, math.inf)}, "alt"),
    ({"t1": (1, -5.0)}, "t1"),
    ({"kind": (0, 2)}, "kind"),
    ({"kind": (0, 1)}, "radius"),  # an arc with radius 0
    ({"drone": (1, 1)}, "t0"),  # two pieces of drone 1 at once
])
def test_bad_pieces_name_the_field(change, field):
    with pytest.raises(QueryError, match=field) as err:
        check(_columns(**change))
    assert err.value.param == field


def test_unknown_columns_and_other_inputs_are_refused():
    with pytest.raises(QueryError, match="'speed'"):
        check({**_columns(), "speed": np.zeros(2)})
    with pytest.raises(QueryError, match="pieces"):
        check([1, 2, 3])


def test_empty_and_single_drone_fleets():
    r = check(Pieces.from_rows([]))
    assert r.separated and r.min_horizontal_m == math.inf and r.pairs_checked == 0
    r = check(fleet(line_piece(1, 0, 10, (0, 0, 0), (1, 0, 0)),
                    line_piece(1, 10, 20, (10, 0, 0), (1, 0, 0))))
    assert r.separated and r.min_horizontal_m == math.inf and r.pairs_checked == 0
