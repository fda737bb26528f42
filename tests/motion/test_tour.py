"""Dubins tours: Held-Karp is exact (against brute force), the local search never beats
it and never loses to nearest-first, and the flown legs are the table's Dubins paths."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import skyroute
from skyroute.motion import dubins
from skyroute.motion.tour_dp import best_headings, held_karp


@settings(max_examples=25, deadline=None)
@given(st.integers(1, 6), st.integers(1, 3), st.integers(0, 2**31 - 1))
def test_held_karp_equals_brute_force(n, H, seed):
    rng = np.random.default_rng(seed)
    c0 = rng.uniform(1, 10, n * H)
    C = rng.uniform(1, 10, (n * H, n * H))
    best, places = held_karp(c0, C, n, H)
    brute = min(best_headings(np.array(p), c0, C, H)[0]
                for p in itertools.permutations(range(n)))
    assert best == pytest.approx(brute, rel=1e-12)
    assert sorted(places // H) == list(range(n))
    again, _ = best_headings(places // H, c0, C, H)
    assert again == pytest.approx(best, rel=1e-12)


@pytest.mark.parametrize("seed", range(4))
def test_exact_local_search_and_greedy_in_free_space(seed):
    rng = np.random.default_rng(seed)
    pts = rng.uniform(0, 100, (8, 2))
    exact = dubins.tour((50, 50, 0), pts, 6.0, headings=8)
    local = dubins.tour((50, 50, 0), pts, 6.0, headings=8, exact_limit=0)
    assert exact.method == "exact" and local.method == "local search"
    assert exact.length <= local.length + 1e-9 <= exact.greedy_bound + 1e-9
    assert exact.length == pytest.approx(exact.bound)
    # each leg is the shortest Dubins path between its poses
    pose = (50.0, 50.0, 0.0)
    total = 0.0
    for k, h, leg in zip(exact.order, exact.headings, exact.legs, strict=True):
        goal = (*pts[k], h)
        total += dubins.shortest_path(pose, goal, 6.0).length
        end = leg[-1].end if leg else pose
        assert end[:2] == pytest.approx(tuple(pts[k]), abs=1e-9)
        pose = goal
    assert total == pytest.approx(exact.length, rel=1e-9)
    poses = exact.sample(0.5)
    for p in pts:
        assert np.hypot(*(poses[:, :2] - p).T).min() < 1e-9


def test_near_target_behind_a_turn_is_not_first():
    """The seed's observation: a near target behind the drone is not the quickest first."""
    pts = np.array([[-3.0, 0.0], [40.0, 0.0]])  # 3 m behind, 40 m ahead
    r = dubins.tour((0, 0, 0), pts, 10.0, headings=16)
    assert r.order == (1, 0) and r.length < r.greedy_bound


def test_tour_among_obstacles_flies_free_hybrid_legs():
    from tests.cli.test_fly_dubins_cli import CITY

    world = skyroute.load_world(CITY, altitude=10, safety=2, frame="ned")
    r = dubins.tour((0, 0, 0), [(60, 30), (-60, 60)], 8.0, world=world)
    assert r.found and all(leg.found for leg in r.legs)
    assert r.length >= r.bound - 1e-9
    poses = r.sample(0.5)
    assert poses[0].tolist() == [0.0, 0.0, 0.0]


@pytest.mark.parametrize("kwargs, error, words", [
    ({"radius": 0.0}, skyroute.OptionError, "radius=0.0"),
    ({"targets": []}, skyroute.QueryError, "targets must be"),
    ({"start_pose": (0, 0)}, skyroute.QueryError, "start_pose"),
    ({"headings": 0}, skyroute.OptionError, "headings=0"),
    # a negative seed was taken, where PRM, the fleet runs and the data synthesis refuse it
    ({"seed": -1}, skyroute.OptionError, "^seed=-1 must be an integer from 0 to 4,294,967,295$"),
])
def test_bad_input(kwargs, error, words):
    args = {"start_pose": (0, 0, 0), "targets": [(10, 10)], "radius": 5.0, **kwargs}
    with pytest.raises(error, match=words):
        dubins.tour(args.pop("start_pose"), args.pop("targets"), args.pop("radius"), **args)
