"""Turn-aware planning on a (cell, heading) lattice."""

import math

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import skyroute
from skyroute.motion.turn_lattice import plan_turns, travel_time
from tests.search.checks import assert_any_angle_path_legal, two_indices

SETTINGS = settings(max_examples=60, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow])


@st.composite
def grid_query(draw):
    h, w = draw(st.integers(2, 12)), draw(st.integers(2, 12))
    # every cell drawn (fill=nothing; with a fill most grids were all blocked or all
    # free), a quarter of them blocked (at a half most queries were no_path)
    blocked = draw(arrays(np.bool_, (h, w), elements=st.integers(0, 3).map(lambda v: v == 3),
                          fill=st.nothing()))
    free = np.argwhere(~blocked)
    if len(free) < 2:
        blocked[:] = False
        free = np.argwhere(~blocked)
    i, j = two_indices(draw, len(free))  # start != goal
    return blocked, (int(free[i][1]), int(free[i][0])), (int(free[j][1]), int(free[j][0]))


@SETTINGS
@given(grid_query(), st.floats(0.2, 5.0), st.sampled_from([8, 16]))
def test_never_slower_than_the_distance_optimal_path(q, rate, headings):
    blocked, s, t = q
    grid = skyroute.Grid(blocked)
    a = skyroute.plan(grid, s, t)
    r = plan_turns(grid, s, t, headings=headings, turn_rate=rate)
    assert r.found == a.found
    if a.found:
        assert r.time <= travel_time(a.path, turn_rate=rate) + 1e-9
        assert r.distance >= math.dist(s, t) - 1e-9
        assert_any_angle_path_legal(blocked, r.cells)


@SETTINGS
@given(grid_query())
def test_free_turning_gives_the_octile_optimum_and_16_never_loses(q):
    blocked, s, t = q
    grid = skyroute.Grid(blocked)
    a = skyroute.plan(grid, s, t)
    r8 = plan_turns(grid, s, t, headings=8, turn_rate=1e9)
    if a.found:
        assert abs(r8.time - a.cost) < 1e-6
        r8slow = plan_turns(grid, s, t, headings=8, turn_rate=0.7)
        r16slow = plan_turns(grid, s, t, headings=16, turn_rate=0.7)
        assert r16slow.time <= r8slow.time + 1e-9


def test_turns_cost_time_on_a_real_map():
    grid = skyroute.load_map("den312d")
    a = skyroute.plan(grid, (50, 76), (60, 13))
    r = plan_turns(grid, (50, 76), (60, 13), turn_rate=math.pi / 4)
    assert r.time < travel_time(a.path, turn_rate=math.pi / 4)
    assert r.distance >= a.cost - 1e-9  # the fastest route is never shorter than the shortest


def test_repr_summarises_the_route():
    r = plan_turns(skyroute.load_map("den312d"), (50, 76), (60, 13), turn_rate=math.pi / 4)
    text = repr(r)
    assert text.startswith(f"<LatticeResult found, {r.time:.6g} s over {r.distance:.6g}, "
                           f"{len(r.cells)} cells, {r.expanded} expanded")
    assert "array" not in text


def test_lattice_options_are_checked():
    # "2" was a TypeError, inf a speed, -1 and "5" budgets, NaN a heading
    import pytest

    from skyroute.motion.turn_lattice import plan_turns_world

    grid = skyroute.load_map("den312d")
    for kw in ({"speed": "2"}, {"speed": math.inf}, {"turn_rate": None},
               {"max_expansions": -1}, {"max_expansions": "5"},
               {"start_heading": math.nan}, {"start_heading": "x"}):
        (name, _), = kw.items()
        with pytest.raises(skyroute.OptionError, match=f"{name}="):
            plan_turns(grid, (50, 76), (60, 13), **kw)
    with pytest.raises(skyroute.OptionError, match="speed="):
        travel_time([(0, 0), (1, 0)], speed=0)
    with pytest.raises(skyroute.QueryError):
        travel_time([(0, 0, 0), (1, 0, 0)])
    import shapely

    tower = skyroute.World([shapely.box(1, 1, 3, 3)], [0], [50], ("tower",))
    with pytest.raises(skyroute.OptionError, match="speed="):
        plan_turns_world(tower, (0, 2), (4, 2), speed="1")
    r = plan_turns(grid, (50, 76), (60, 13), speed=np.float32(2), start_heading=np.array(1.0),
                   max_expansions=np.int64(10**6))
    assert r.found
