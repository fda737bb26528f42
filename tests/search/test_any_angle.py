"""Theta* and Lazy Theta*: every segment legal under an independent exact checker, and
the cost never above A*'s."""

import math

import numpy as np
import pytest

import skyroute
from skyroute.world.movingai import read_scen
from tests.search.checks import assert_any_angle_path_legal, segment_legal

ANY_ANGLE = ("theta", "lazy_theta")


def test_checker_knows_squeezes_and_corner_touches():
    c = np.zeros((3, 3), bool)
    c[0, 1] = c[1, 0] = True
    assert not segment_legal(c, (0, 0), (2, 2))  # squeeze through (1, 1)
    d = np.zeros((3, 3), bool)
    d[0, 1] = True
    assert segment_legal(d, (0, 0), (2, 2))  # touching one corner is allowed
    e = np.zeros((3, 5), bool)
    e[1, 2] = True
    assert not segment_legal(e, (0, 1), (4, 1))  # straight through a blocked cell
    assert segment_legal(e, (0, 0), (4, 0))


@pytest.mark.parametrize("algorithm", ANY_ANGLE)
def test_open_field_is_one_straight_segment(algorithm):
    grid = skyroute.Grid(np.zeros((20, 30), bool))
    r = skyroute.plan(grid, (1, 2), (27, 15), algorithm=algorithm)
    assert r.found and len(r.path) == 2
    assert r.cost == pytest.approx(math.hypot(26, 13), rel=1e-12)


@pytest.mark.parametrize("algorithm", ANY_ANGLE)
@pytest.mark.parametrize("seed", range(6))
def test_random_grids_legal_and_not_longer_than_astar(algorithm, seed):
    rng = np.random.default_rng(seed)
    blocked = rng.random((35, 45)) < 0.25
    grid = skyroute.Grid(blocked)
    ys, xs = np.nonzero(~blocked)
    for _ in range(25):
        i, j = rng.integers(len(xs), size=2)
        s, t = (xs[i], ys[i]), (xs[j], ys[j])
        a = skyroute.plan(grid, s, t)
        r = skyroute.plan(grid, s, t, algorithm=algorithm)
        assert r.status is a.status
        if r.found:
            length = assert_any_angle_path_legal(blocked, r.path)
            assert length == pytest.approx(r.cost, rel=1e-9)
            assert r.cost <= a.cost + 1e-9
            assert r.los_checks > 0 or len(r.path) <= 2


@pytest.mark.parametrize("algorithm", ANY_ANGLE)
def test_real_map_legal_and_shorter(algorithm):
    grid = skyroute.load_map("den312d")
    scen = read_scen(skyroute.bundled_maps()["den312d"].with_suffix(".map.scen"))
    for i in range(0, len(scen), 15):
        s, t = tuple(scen.starts[i]), tuple(scen.goals[i])
        r = skyroute.plan(grid, s, t, algorithm=algorithm)
        assert r.found
        assert_any_angle_path_legal(grid.blocked, r.path)
        assert r.cost <= scen.optimal[i] + 1e-6
