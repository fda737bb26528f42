"""Dubins tours: Held-Karp is exact (against brute force), the local search never beats
it and never loses to nearest-first, and the flown legs are the table's Dubins paths."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import skyroute
from skyroute.motion import dubins
from skyroute.motion.tour_dp import best_headings, held_karp
from tests.motion.test_hybrid import check_path, make_world, on_an_edge


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


# -- among obstacles: every target visited, or no_path ----------------------------------

def _check_tour(world, res, start, targets, radius):
    """Each leg checked as a Hybrid A* path (shapely, curvature, ends), the legs end on
    the targets in ``order``, each target exactly once, the length their sum."""
    assert res.found and sorted(res.order) == list(range(len(targets)))
    pose = tuple(start)
    for k, h, leg in zip(res.order, res.headings, res.legs, strict=True):
        goal = (*targets[k], float(h))
        check_path(world, leg, pose, goal, radius, ds=0.2)
        pose = goal
    assert res.length == pytest.approx(sum(leg.length for leg in res.legs), rel=1e-12)
    poses = res.sample(0.5)
    for p in targets:
        assert np.hypot(*(poses[:, :2] - p).T).min() < 1e-9


def test_a_target_beside_a_wall_is_toured_on_headings_that_get_away():
    """Targets half a metre from a building's faces (r = 10): the table's costs (Dubins
    and the 2D distance) do not see that a target reached heading into the wall is a dead
    end, or one heading away from it reachable from nowhere. The tour flew the table's
    best order and headings and ended in no_path; a leg that cannot be flown now takes
    its arcs out of the table and the tour is solved again."""
    world = make_world([(40, 40, 60, 60)], boundary=(-100, -100, 150, 150))
    start = (-20.0, 0.0, math.pi / 2)
    for targets in ([(39.5, 50), (20, 20), (30, -10), (80, 80)], [(50, 60.5), (39.5, 50)]):
        res = dubins.tour(start, targets, 10.0, world=world)
        _check_tour(world, res, start, np.array(targets, float), 10.0)
        assert res.extra["repairs"] > 0


def test_a_target_walled_off_is_no_path_not_a_tour_of_the_others():
    """A target inside a closed ring of walls: no order has a finite cost. Held-Karp's
    places were then -1, read as the last target: the tour flew to it twice, said found
    and reached, and never visited the walled one (order (-1, -1))."""
    ring = [(30, 30, 70, 35), (30, 65, 70, 70), (30, 35, 35, 65), (65, 35, 70, 65)]
    world = make_world(ring)
    for exact_limit in (12, 0):
        res = dubins.tour((10, 10, 0.0), [(50, 50), (90, 90)], 5.0, world=world,
                          exact_limit=exact_limit)
        assert res.status is skyroute.Status.NO_PATH and not res.found
        assert res.order == () and res.legs == () and res.length == math.inf
        assert res.sample(1.0).shape == (0, 3)


_rect = st.tuples(st.floats(5, 85), st.floats(5, 85), st.floats(3, 20), st.floats(3, 20))
_point = st.tuples(st.floats(2, 98), st.floats(2, 98))


@settings(max_examples=15, deadline=None)
@given(st.lists(_rect, max_size=4), _point, st.floats(-math.pi, math.pi),
       st.lists(_point, min_size=1, max_size=3), st.sampled_from([3.0, 6.0]))
def test_property_a_tour_among_obstacles_is_free_and_visits_every_target(
        boxes, start, heading, targets, radius):
    """Random boxes in a 100 m square: a found tour's legs are free (shapely), turn no
    tighter than the radius, and end on every target once; otherwise the status says
    why, with no legs or a last leg that failed."""
    world = make_world([(x, y, x + w, y + h) for x, y, w, h in boxes])
    assume(world.is_free([start, *targets]).all() and not on_an_edge(world, [start, *targets]))
    s = (*start, heading)
    res = dubins.tour(s, targets, radius, world=world, max_expansions=20_000, headings=8)
    if res.found:
        _check_tour(world, res, s, np.array(targets, float), radius)
    else:
        assert res.status in (skyroute.Status.NO_PATH, skyroute.Status.BUDGET_EXHAUSTED)
        assert res.legs == () or not res.legs[-1].found
