"""Trajectory pieces: the angle convention, positions, the builder, continuity, checks."""

from __future__ import annotations

import math

import numpy as np
import pytest

from skyroute.errors import QueryError
from skyroute.fleet.trajectory import (
    ARC,
    LINE,
    Pieces,
    Trajectory,
    arc_piece,
    check_continuous,
    jumps,
    line_piece,
    position,
)


def test_arc_angles_are_clockwise_from_north_and_positive_rate_turns_right():
    p = Pieces.from_rows([arc_piece(1, 0, 10, (100, 200), 50, 0.0, math.pi / 20, 30)])
    # angle 0: due north of the centre; a quarter turn later (t = 10): due east
    assert p.at([0, 0], [0.0, 10.0]) == pytest.approx(np.array([[150, 200, 30],
                                                                 [100, 250, 30]]))
    # heading east at angle 0 (clockwise seen from above): a right turn
    ahead = p.at(0, 1e-6)[:2] - p.at(0, 0.0)[:2]
    assert ahead[1] > 0 and abs(ahead[0]) < 1e-9


def test_line_position_and_altitude_rate():
    p = Pieces.from_rows([line_piece(4, 10, 20, (1, 2, 3), (0.5, -1, 2))])
    assert position(p, [10, 15, 20], drone=4) == pytest.approx(
        np.array([[1, 2, 3], [3.5, -3, 13], [6, -8, 23]]))


def test_position_is_nan_on_the_ground_and_takes_the_later_piece_at_a_junction():
    tr = (Trajectory(2, 0.0, (0, 0, 0)).line(10, (10, 0, 1))
          .ground(50, (500, 0, 0)).line(60, (0, 10, 1)))
    p = tr.pieces()
    out = position(p, [5.0, 10.0, 30.0, 50.0, 55.0, 61.0], drone=2)
    assert out[0] == pytest.approx([50, 0, 5]) and out[1] == pytest.approx([100, 0, 10])
    assert np.isnan(out[2]).all() and np.isnan(out[5]).all()
    assert out[3] == pytest.approx([500, 0, 0]) and out[4] == pytest.approx([500, 50, 5])
    both = position(Pieces.concat([p, Trajectory(9, 0, (0, 0, 0)).hold(100).pieces()]), [5.0])
    assert both.shape == (2, 1, 3)


def test_builder_chains_continuous_pieces():
    tr = (Trajectory(3, 0.0, (0, 0, 0))
          .line(10, (20, 0, 5))
          .arc(10 + math.pi / 0.1, (200, 100), 0.1, v_alt=1.0)
          .line_to(60, (0, 0, 80))
          .hold(70))
    p = tr.pieces()
    assert p.kind.tolist() == [LINE, ARC, LINE, LINE]
    assert p.radius[1] == pytest.approx(100) and p.angle[1] == pytest.approx(-math.pi / 2)
    assert max(j.distance for j in jumps(p)) < 1e-9
    check_continuous(p)
    assert tr.t == 70 and tr.position.tolist() == [0, 0, 80]


def test_a_jump_is_found():
    p = Pieces.from_rows([line_piece(1, 0, 10, (0, 0, 0), (1, 0, 0)),
                          line_piece(1, 10, 20, (10.5, 0, 0), (1, 0, 0)),
                          line_piece(1, 30, 40, (99, 0, 0), (1, 0, 0))])  # after landing
    (j,) = jumps(p)
    assert (j.drone, j.before, j.after, j.t) == (1, 0, 1, 10.0)
    assert j.distance == pytest.approx(0.5)
    with pytest.raises(QueryError, match=r"jumps 0\.5 m at t=10") as err:
        check_continuous(p)
    assert err.value.param == "pieces"
    check_continuous(p, tolerance=0.6)


def test_columns_are_copies_and_read_only():
    t0 = np.array([0.0])
    p = Pieces.from_columns({"drone": [1], "kind": [0], "t0": t0, "t1": [5.0]})
    t0[0] = 99
    assert p.t0[0] == 0 and p.radius[0] == 0
    with pytest.raises(ValueError):
        p.t1[0] = 1


@pytest.mark.parametrize("call, param", [
    (lambda: Trajectory(1, 0, (0, 0, 0)).line(-1, (1, 0, 0)), "t1"),
    (lambda: Trajectory(1, 0, (0, 0, 0)).arc(5, (0, 0), 0.1), "centre"),
    (lambda: Trajectory(1, 0, (0, 0)).line(1, (1, 0, 0)), "position"),
    (lambda: Trajectory(1, math.nan, (0, 0, 0)), "t"),
    (lambda: line_piece(1, 0, 1, (0, 0, 0), (1, 0)), "velocity"),
    (lambda: Pieces.from_columns({"drone": [1], "kind": [0], "t0": [0.0]}), "t1"),
    (lambda: Pieces.from_columns({"drone": [1.5], "kind": [0], "t0": [0.0], "t1": [1.0]}),
     "drone"),
    (lambda: Pieces.from_columns({"drone": [1, 2], "kind": [0], "t0": [0.0], "t1": [1.0]}),
     "kind"),
    (lambda: position(Pieces.from_rows([]), [0.0], drone=1), "drone"),
])
def test_bad_input_names_the_parameter(call, param):
    with pytest.raises(QueryError) as err:
        call()
    assert err.value.param == param
