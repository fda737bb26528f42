"""PRM: reproducible for a seed (in one process and across processes), honest statistics."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import skyroute
from skyroute.bench.world import random_rect_world
from skyroute.roadmap.prm import PRM
from tests.roadmap.test_visibility import assert_free, brute_force, rect_world, rect_worlds

QUERY = ((5.0, 5.0), (95.0, 95.0))


def plan_twice(seed: int) -> tuple:
    world = random_rect_world(11)
    a = skyroute.plan(world, *QUERY, algorithm="prm", samples=400, seed=seed)
    b = skyroute.plan(world, *QUERY, algorithm="prm", samples=400, seed=seed)  # cached map
    c = skyroute.plan(random_rect_world(11), *QUERY, algorithm="prm", samples=400, seed=seed)
    return a, b, c


def test_same_seed_same_path_on_every_call():
    a, b, c = plan_twice(4)
    assert a.found
    np.testing.assert_array_equal(a.path, b.path)  # second query on the same roadmap
    np.testing.assert_array_equal(a.path, c.path)  # a new world, a new roadmap
    other = plan_twice(5)[0]
    assert not np.array_equal(a.path, other.path)  # the seed matters


def test_same_seed_same_path_in_another_process():
    code = ("import json, skyroute; from skyroute.bench.world import random_rect_world; "
            f"r = skyroute.plan(random_rect_world(11), {QUERY[0]}, {QUERY[1]}, "
            "algorithm='prm', samples=400, seed=4); print(json.dumps(r.path.tolist()))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    np.testing.assert_array_equal(json.loads(out), plan_twice(4)[0].path)


def test_max_expansions_is_refused_and_expanded_counts_settled_nodes():
    world = random_rect_world(11)
    with pytest.raises(skyroute.OptionError, match="max_expansions"):
        skyroute.plan(world, *QUERY, algorithm="prm", samples=200, max_expansions=10)
    rm = PRM(world, samples=300, seed=1)
    near = rm.plan(np.array([5.0, 5.0]), np.array([6.0, 5.0]))
    far = rm.plan(np.array([5.0, 5.0]), np.array([95.0, 95.0]))
    assert near.found and far.found
    # Dijkstra settles the nodes no farther than the goal: few for a near goal
    assert 0 < near.expanded < far.expanded <= 302
    with pytest.raises(skyroute.OptionError, match="seed"):
        PRM(world, samples=300, seed=-1)


def _square() -> skyroute.World:
    import shapely

    return skyroute.World([shapely.box(1, 1, 3, 3)], [0], [50], ("tower",))


@pytest.mark.parametrize("option", [{"samples": "50"}, {"samples": 50.5},
                                    {"samples": float("nan")}, {"samples": [50]},
                                    {"neighbours": 5.5}, {"neighbours": True},
                                    {"neighbours": "5"}, {"prm_star": "yes"},
                                    {"seed": [1]}, {"samples": 10**12}])
def test_bad_prm_options_name_themselves(option):
    # a TypeError from a comparison or the roadmap cache before; 5.5 neighbours and
    # prm_star="yes" were taken
    (name, _), = option.items()
    with pytest.raises(skyroute.OptionError, match=f"{name}=") as err:
        skyroute.plan(_square(), (0, 2), (4, 2), algorithm="prm", **option)
    assert err.value.param == name


def test_prm_takes_numpy_integers():
    r = skyroute.plan(_square(), (0, 2), (4, 2), algorithm="prm", samples=np.int64(60),
                      neighbours=np.int64(6), seed=np.int64(2))
    same = skyroute.plan(_square(), (0, 2), (4, 2), algorithm="prm", samples=60,
                         neighbours=6, seed=2)
    assert r.found and r.cost == same.cost


@pytest.mark.parametrize("algorithm, option", [
    ("visibility", {"heuristic": "octile"}), ("visibility", {"weight": 2.0}),
    ("visibility", {"seed": 3}), ("visibility", {"resolution": 0.5}),
    ("prm", {"resolution": 0.5}), ("prm", {"connectivity": 4}),
    ("astar", {"samples": 50}), ("theta", {"seed": 1})])
def test_options_the_world_planner_does_not_read_are_refused(algorithm, option):
    # they were ignored: plan(world, ..., heuristic="octile") ran the visibility graph
    (name, _), = option.items()
    with pytest.raises(skyroute.OptionError, match=f"{name}=.*algorithm='{algorithm}'"):
        skyroute.plan(_square(), (0, 2), (4, 2), algorithm=algorithm, **option)


@pytest.mark.parametrize("zones, start, goal", [
    # one triangular no-fly zone between start and goal, no boundary: the way lies
    # beyond the zone's bounds, where PRM drew no sample (no_path for every seed)
    ([[(0, 0), (10, 0), (5, 8)]], (5, -1), (5, 9)),
    # two walls spanning their bounds, start and goal outside them
    ([[(0, 0), (1, 0), (1, 10), (0, 10)], [(5, 0), (6, 0), (6, 10), (5, 10)]],
     (-1, 5), (7, 5)),
])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_way_round_every_obstacle_is_in_the_roadmap(zones, start, goal, seed):
    import shapely

    world = skyroute.World([shapely.Polygon(z) for z in zones], 0.0, 50.0, ())
    exact = skyroute.plan(world, start, goal)
    r = skyroute.plan(world, start, goal, algorithm="prm", samples=300, seed=seed)
    assert r.found, r
    assert world.segments_free(r.path[:-1], r.path[1:]).all()
    assert exact.cost <= r.cost == pytest.approx(
        np.hypot(*np.diff(r.path, axis=0).T).sum(), rel=1e-12)


def test_a_world_with_nothing_in_the_way_is_the_straight_segment():
    """No boundary and no obstacle left at the altitude: no extent to sample, and
    nothing to go round (as the visibility graph answers)."""
    from tests.conftest import ROOT

    world = skyroute.load_world(ROOT / "examples" / "city.csv", altitude=1000)
    assert len(world.obstacles) == 0 and world.boundary is None
    a, b = (-3.1890, 55.9456), (-3.1850, 55.9432)
    r = skyroute.plan(world, a, b, algorithm="prm", samples=300, seed=3)
    want = skyroute.plan(world, a, b, algorithm="visibility")
    assert r.found and r.path.tolist() == [list(a), list(b)] == want.path.tolist()
    assert r.cost == want.cost
    same = skyroute.plan(world, a, a, algorithm="prm")
    assert same.found and same.path.tolist() == [list(a)] and same.cost == 0.0
    assert PRM(skyroute.World([], [], [], ())).edge_segments().shape == (0, 2, 2)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(rect_worlds(), st.integers(0, 2**16))
def test_a_prm_path_never_crosses_an_obstacle_and_is_never_shorter_than_the_optimum(case, seed):
    # the invariants on random rectangle worlds, checked with shapely and the brute-force
    # visibility graph of test_visibility (scipy), nothing of skyroute's geometry
    boxes, s, t = case
    world = rect_world(boxes)
    union = shapely.unary_union(world.obstacles)
    assume(not union.contains(shapely.Point(s)) and not union.contains(shapely.Point(t)))
    r = skyroute.plan(world, s, t, algorithm="prm", samples=150, seed=seed)
    optimum = brute_force(boxes, s, t)
    if not r.found:
        assert r.status is skyroute.Status.NO_PATH and r.path.shape == (0, 2)
        return
    assert np.isfinite(optimum)  # no path found where none exists
    np.testing.assert_array_equal(r.path[[0, -1]], [s, t])
    assert_free(boxes, r.path)
    length = np.hypot(*np.diff(r.path, axis=0).T).sum()
    assert r.cost == pytest.approx(length, rel=1e-12)
    assert r.cost >= optimum - 1e-9


@pytest.mark.parametrize("samples", [2, 3, 4])
def test_fewer_samples_than_the_ring_still_plan_round_the_obstacle(samples):
    # without a boundary the roadmap's first nodes are the 4 corners of the grown bounds,
    # joined in a ring; with samples=2 or 3 the ring was cut to that many and its edges
    # named the missing corners: IndexError from plan(..., algorithm="prm", samples=2)
    world = rect_world([(0, 0, 2, 2)])
    r = skyroute.plan(world, (-1, 1), (3, 1), algorithm="prm", samples=samples)
    assert r.found
    assert_free([(0, 0, 2, 2)], r.path)
    assert r.cost >= skyroute.plan(world, (-1, 1), (3, 1)).cost - 1e-9
