"""Hybrid A* for turning-radius vehicles: exact freedom, curvature, lengths, statuses."""

import itertools
import math

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import skyroute
from skyroute.errors import OptionError, QueryError
from skyroute.motion import dubins
from skyroute.motion.arc_kernels import arc_segment_distance, segment_distance
from skyroute.motion.dubins_kernel import free_heading_bound, words
from skyroute.motion.hybrid import path_free, plan, runway_goal
from skyroute.result import Status
from skyroute.world.world import World
from tests.conftest import ROOT

R = 5.0


def make_world(boxes, boundary=(0, 0, 100, 100)) -> World:
    obs = np.array([shapely.box(*b) if not isinstance(b, shapely.Geometry) else b
                    for b in boxes], dtype=object)
    n = len(obs)
    return World(obs, np.full(n, -np.inf), np.full(n, np.inf), (),
                 boundary=shapely.box(*boundary) if boundary else None)


def on_an_edge(world: World, points) -> bool:
    """Whether a point lies on (within 1e-6 of) an obstacle's or the boundary's edge,
    which Hybrid A* refuses."""
    outlines = [shapely.boundary(g) for g in world.obstacles]
    if world.boundary is not None:
        outlines.append(world.boundary.exterior)
    if not outlines:
        return False
    d = shapely.distance(shapely.union_all(outlines), shapely.points(np.asarray(points, float)))
    return bool((d <= 1e-6).any())


def wrap(a):
    return (np.asarray(a) + math.pi) % (2 * math.pi) - math.pi


def check_path(world: World, res, start, goal, radius, *, ds=0.05, reverse=False):
    """Independent checks of a found path: shapely on dense samples (with the chord's
    sagitta as tolerance), curvature and direction from consecutive poses, the ends, and
    the lower bound."""
    assert res.found
    poses = res.sample(ds)
    assert np.allclose(poses[0, :2], start[:2], atol=0, rtol=0)
    assert np.allclose(poses[-1, :2], goal[:2], atol=0, rtol=0)
    if len(start) == 3:
        assert abs(wrap(poses[0, 2] - start[2])) < 1e-12
    if len(goal) == 3:
        assert abs(wrap(poses[-1, 2] - goal[2])) < 1e-12
    # the pieces themselves end at the goal (sample() only pins the last row)
    end = res.segments[-1].end if res.segments else res.start
    assert math.dist(end[:2], goal[:2]) < 1e-6
    if len(goal) == 3:
        assert abs(wrap(end[2] - goal[2])) < 1e-6
    assert reverse or not any(p.reverse for p in res.segments)
    for a, b in zip(res.segments[:-1], res.segments[1:], strict=True):
        assert math.dist(a.end[:2], b.start[:2]) < 1e-6 and abs(wrap(a.end[2] - b.start[2])) \
            < 1e-6
    # free: every sample strictly free, and the polyline (within the sagitta of the arcs)
    # meets no obstacle shrunk by that sagitta, and stays inside the boundary
    assert world.is_free(poses[:, :2]).all()
    sag = radius * (1 - math.cos(ds / (2 * radius))) + 1e-9
    line = shapely.LineString(poses[:, :2]) if len(poses) > 1 else shapely.Point(poses[0, :2])
    for ob in world.obstacles:
        core = ob.buffer(-sag)
        assert core.is_empty or not line.intersects(core)
    if world.boundary is not None:
        assert shapely.Polygon(world.boundary).buffer(sag).contains(line)
    # curvature <= 1/r and motion along the heading
    d = np.diff(poses[:, :2], axis=0)
    chord = np.hypot(*d.T)
    turn = np.abs(wrap(np.diff(poses[:, 2])))
    assert np.all(2 * radius * np.sin(turn / 2) <= chord * (1 + 1e-6) + 1e-6)
    moving = chord > 1e-6  # shorter chords: their direction is rounding noise
    mid = poses[:-1, 2] + wrap(np.diff(poses[:, 2])) / 2
    # the first and last rows are pinned to the poses given, and a piece starts within
    # rounding of where the one before it ends: a chord of c beside such a gap g turns
    # by up to about 2 g / c (a 0.1 mm path of 17 um chords: 1.1e-6 rad)
    first = res.segments[0].start if res.segments else res.start
    gap = max([math.dist(first[:2], poses[0, :2]), math.dist(end[:2], poses[-1, :2])]
              + [math.dist(a.end[:2], b.start[:2])
                 for a, b in zip(res.segments[:-1], res.segments[1:], strict=True)])
    tol = (1e-6 + 2 * gap / np.maximum(chord, 1e-300))[moving]
    off = np.abs(wrap(np.arctan2(d[:, 1], d[:, 0]) - mid))[moving]
    backwards = any(p.reverse for p in res.segments)
    if backwards:  # each chord along the nose or straight behind it
        assert np.all((off < tol) | (off > math.pi - tol))
        if any(p.reverse and p.length > 2 * ds for p in res.segments):
            assert np.any(off > 3)
    else:
        assert np.all(off < tol)
    # at least the lower bound
    if len(start) == 3 and len(goal) == 3:
        lb_dubins = max(math.dist(start[:2], goal[:2]),
                        radius * abs(wrap(goal[2] - start[2]))) if reverse else \
            dubins.shortest_path(start, goal, radius).length
    else:
        lb_dubins = math.dist(start[:2], goal[:2])
    lb_2d = skyroute.plan(world, start[:2], goal[:2]).cost
    assert res.length >= max(lb_dubins, lb_2d) - 1e-9
    assert res.length == pytest.approx(sum(p.length for p in res.segments), abs=1e-9)
    assert abs(res.length - chord.sum()) < 1e-3 * max(1.0, res.length)
    assert path_free(world, res.segments)


# -- the obstacle-free case is Dubins -----------------------------------------------------

@pytest.mark.parametrize("boundary", [(-500, -500, 500, 500), None])
@pytest.mark.parametrize("start,goal", [
    ((0, 0, 0), (40, 0, 0)),
    ((0, 0, 0), (0, 0, math.pi)),
    ((3, -7, 1.2), (-20, 31, -2.5)),
    ((0, 0, math.pi / 2), (5, 0, -math.pi / 2)),
    ((10, 10, 0.3), (12, 9, 2.9)),
])
def test_empty_world_gives_the_dubins_length(boundary, start, goal):
    world = make_world([], boundary)
    res = plan(world, start, goal, R)
    assert res.found
    assert res.length == pytest.approx(dubins.shortest_path(start, goal, R).length, abs=1e-9)
    check_path(world, res, start, goal, R)


def test_empty_world_free_headings():
    world = make_world([])
    res = plan(world, (10, 10), (70, 50), R)  # no headings: the straight line
    assert res.length == pytest.approx(math.dist((10, 10), (70, 50)), abs=1e-9)
    res = plan(world, (10, 10, math.pi), (70, 50), R)  # turn, then the tangent
    # (floats, as the planner calls it: whole numbers compile another signature)
    assert res.found and res.length == pytest.approx(
        free_heading_bound(10.0, 10.0, math.pi, 70.0, 50.0, R), abs=1e-9)
    check_path(world, res, (10, 10, math.pi), (70, 50), R)
    res = plan(world, (10, 10), (70, 50, 0.5), R)
    assert res.found and res.length < dubins.shortest_path((10, 10, 0), (70, 50, 0.5),
                                                           R).length
    check_path(world, res, (10, 10), (70, 50, 0.5), R)


def test_sampling_past_max_samples_is_an_option_error_naming_step():
    res = plan(make_world([]), (10, 10, 0.0), (70, 50, 0.5), R)
    with pytest.raises(OptionError, match=r"step=1e-12 along a path .* makes more than "
                                          r"10,000,000 poses"):
        res.sample(1e-12)
    assert len(res.sample(1.0)) > res.length - 1


# -- walls, gaps, dead ends, budgets ------------------------------------------------------

def test_wall_with_a_gap_wider_than_2r_is_passed():
    world = make_world([(48, 0, 52, 45), (48, 57, 52, 100)])  # gap 12 m > 2 r
    start, goal = (20, 80, -math.pi / 2), (80, 20, 0.0)
    res = plan(world, start, goal, R)
    check_path(world, res, start, goal, R)
    assert res.length < 1.15 * skyroute.plan(world, start[:2], goal[:2]).cost + 2 * R


def test_closed_wall_gives_no_path():
    world = make_world([(48, 0, 52, 100)])
    res = plan(world, (20, 50, 0.0), (80, 50, 0.0), R)
    assert res.status is Status.NO_PATH and not res.found and res.length == math.inf
    assert res.sample(1.0).shape == (0, 3) and res.segments == ()


def test_dead_end_narrower_than_a_turn_gives_no_path():
    # a corridor 6 m wide (< 2 r) closed at its end; the vehicle faces the closed end
    world = make_world([(20, 44, 60, 47), (20, 53, 60, 56), (17, 44, 20, 56)])
    res = plan(world, (40, 50, math.pi), (80, 80, 0.0), R)
    assert res.status is Status.NO_PATH
    res = plan(world, (40, 50, 0.0), (80, 80, 0.0), R)  # facing out it leaves
    check_path(world, res, (40, 50, 0.0), (80, 80, 0.0), R)


def test_budget_exhausted_is_its_own_status():
    world = make_world([(48, 0, 52, 100)])
    res = plan(world, (20, 50, 0.0), (80, 50, 0.0), R, max_expansions=50)
    assert res.status is Status.BUDGET_EXHAUSTED and res.expanded == 50 and not res.found
    free = make_world([(48, 0, 52, 80), (48, 92, 52, 100)])  # the way is round the top
    start, goal = (20, 20, 0.0), (80, 20, math.pi)
    res = plan(free, start, goal, R, max_expansions=5)
    assert res.status is Status.BUDGET_EXHAUSTED and res.expanded == 5
    res = plan(free, start, goal, R, max_expansions=0)
    assert res.status is Status.BUDGET_EXHAUSTED and res.expanded == 0
    check_path(free, plan(free, start, goal, R), start, goal, R)


@pytest.mark.parametrize("reverse, per_expansion", [(False, 3), (True, 6)])
def test_the_default_budget_bounds_the_nodes_stored(monkeypatch, reverse, per_expansion):
    # max_expansions=None was no budget at all: r = 0.01 m in this 100 m world filled
    # 10 GB in 5 minutes. The default keeps the nodes stored under MAX_NODES; here it is
    # lowered so that a search which needs more (r = 0.5 m: about 55,000 expansions)
    # runs out, saying why.
    from skyroute.motion import hybrid

    monkeypatch.setattr(hybrid, "MAX_NODES", 6000 * per_expansion, raising=False)
    world = make_world([(45, 0, 55, 60)])
    res = plan(world, (20, 20, 0.0), (80, 20, 0.0), 0.5, reverse=reverse)
    assert res.status is Status.BUDGET_EXHAUSTED and res.expanded == 6000
    assert res.extra["budget"] == 6000 and res.extra["radii_across"] == pytest.approx(200)
    hint = res.extra["hint"]
    assert "6,000 expansions (the default max_expansions)" in hint
    assert "200 turning radii across (radius=0.5)" in hint and "larger max_expansions" in hint
    given = plan(world, (20, 20, 0.0), (80, 20, 0.0), 0.5, max_expansions=7000)
    assert given.status is Status.BUDGET_EXHAUSTED  # a budget given is the budget
    assert "(max_expansions)" in given.extra["hint"] and given.expanded == 7000


def test_the_default_budget_leaves_a_found_path_alone():
    from skyroute.motion import hybrid

    assert hybrid.MAX_NODES // 6 >= 5_000_000  # well above 3,000,000 (docs/architecture.md)
    res = plan(make_world([(45, 0, 55, 60)]), (20, 20, 0.0), (80, 20, 0.0), R)
    assert res.found and "hint" not in res.extra


def test_no_boundary_enclosed_goal_is_no_path():
    ring = shapely.box(30, 30, 70, 70).difference(shapely.box(35, 35, 65, 65))
    world = make_world([ring], None)
    res = plan(world, (0, 0, 0.0), (50, 50, 0.0), R)
    assert res.status is Status.NO_PATH


# -- the runway approach ------------------------------------------------------------------

def test_runway_goal_and_final_approach():
    gate, final = runway_goal((60, 40), math.pi / 2, 20)
    assert gate == pytest.approx((60, 20, math.pi / 2)) and final.kind == "S"
    assert final.end == pytest.approx((60, 40, math.pi / 2))
    world = make_world([])
    start = (10, 10, 0.0)
    res = plan(world, start, (60, 40, math.pi / 2), R, approach=20)
    legs = dubins.runway_approach(start, (60, 40), math.pi / 2, R, final=20)
    assert legs[-1].start == pytest.approx(gate)
    assert res.length == pytest.approx(sum(leg.length for leg in legs), abs=1e-9)
    last = res.segments[-1]
    assert last.kind == "S" and last.length >= 20 - 1e-9
    assert res.sample(1.0)[-1] == pytest.approx((60, 40, math.pi / 2))
    check_path(world, res, start, (60, 40, math.pi / 2), R)
    blocked = make_world([(55, 25, 65, 30)])
    with pytest.raises(QueryError, match=r"goal.*final approach"):
        plan(blocked, start, (60, 40, math.pi / 2), R, approach=20)


# -- property: random rectangle worlds ----------------------------------------------------

rects = st.lists(st.tuples(st.floats(0, 90), st.floats(0, 90), st.floats(3, 25),
                           st.floats(3, 25)), min_size=0, max_size=8)
pose = st.tuples(st.floats(2, 98), st.floats(2, 98), st.floats(-math.pi, math.pi))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(rects, pose, pose, st.sampled_from([3.0, 5.0, 8.0]), st.booleans(), st.booleans(),
       st.booleans(), st.booleans())
def test_property_paths_are_free_curvature_bounded_and_not_too_short(
        boxes, start, goal, radius, start_heading, goal_heading, reverse, across):
    world = make_world([(x, y, x + w, y + h) for x, y, w, h in boxes])
    if across and boxes:  # start and goal either side of the first box, level with its
        # middle: the way is blocked (anywhere, 49 of 60 had a free straight line)
        x, y, w, h = boxes[0]
        mid = min(y + h / 2, 98.0)
        start, goal = (min(start[0], x / 2), mid, start[2]), (max(goal[0], 99 - (99 - x - w) / 2),
                                                            mid, goal[2])
    assume(world.is_free([start[:2], goal[:2]]).all())
    assume(not on_an_edge(world, [start[:2], goal[:2]]))  # refused: a QueryError
    s = start if start_heading else start[:2]
    g = goal if goal_heading else goal[:2]
    res = plan(world, s, g, radius, max_expansions=20_000, reverse=reverse)
    if res.found:
        check_path(world, res, s, g, radius, reverse=reverse)
        assert res.extra["raw_length"] >= res.length - 1e-9  # shortcuts never lengthen
    else:
        assert res.status in (Status.NO_PATH, Status.BUDGET_EXHAUSTED)


def test_rotated_obstacles_and_a_slalom():
    from shapely import affinity

    slab = affinity.rotate(shapely.box(30, 20, 36, 80), 25, origin="centroid")
    world = make_world([slab, (60, 0, 64, 60), (60, 70, 64, 100)])
    start, goal = (10, 90, 0.0), (90, 90, math.pi / 2)
    res = plan(world, start, goal, R)
    check_path(world, res, start, goal, R)


# -- bad inputs ---------------------------------------------------------------------------

def test_bad_inputs_raise_named_errors():
    world = make_world([(40, 40, 60, 60)])
    ok_s, ok_g = (10, 10, 0.0), (90, 90, 0.0)
    with pytest.raises(QueryError, match="start"):
        plan(world, (50, 50, 0.0), ok_g, R)
    with pytest.raises(QueryError, match="goal"):
        plan(world, ok_s, (50, 50), R)
    with pytest.raises(QueryError, match="start"):
        plan(world, (-5, 10, 0.0), ok_g, R)
    with pytest.raises(QueryError, match="goal"):
        plan(world, ok_s, (150, 10), R)
    for bad in [(1,), (1, 2, 3, 4), (1, float("nan")), ("a", 2), (1, 2, None), 5, None,
                (1, 2, float("inf")), (True, 2)]:
        with pytest.raises(QueryError, match="start"):
            plan(world, bad, ok_g, R)
        with pytest.raises(QueryError, match="goal"):
            plan(world, ok_s, bad, R)
    for radius in (-1, 0, float("nan"), float("inf"), "5"):
        with pytest.raises(OptionError, match="radius"):
            plan(world, ok_s, ok_g, radius)
    with pytest.raises(OptionError, match="radius=-1 must be > 0"):
        plan(world, ok_s, ok_g, -1)
    for bins in (3, 0, 4.5, "72"):
        with pytest.raises(OptionError, match="heading_bins"):
            plan(world, ok_s, ok_g, R, heading_bins=bins)
    for step in (0, -1, float("nan"), 100.0):
        with pytest.raises(OptionError, match="step"):
            plan(world, ok_s, ok_g, R, step=step)
    with pytest.raises(OptionError, match="max_expansions"):
        plan(world, ok_s, ok_g, R, max_expansions=-1)
    with pytest.raises(OptionError, match="reverse"):
        plan(world, ok_s, ok_g, R, reverse="yes")
    with pytest.raises(OptionError, match="approach"):
        plan(world, ok_s, ok_g, R, approach=-3)
    with pytest.raises(QueryError, match="goal"):
        plan(world, ok_s, (90, 90), R, approach=10)
    with pytest.raises(OptionError, match="step"):
        plan(world, ok_s, ok_g, R).sample(0)


def test_options_change_the_lattice_not_the_contract():
    world = make_world([(48, 0, 52, 45), (48, 57, 52, 100)])
    start, goal = (20, 80, -math.pi / 2), (80, 20, 0.0)
    for kw in ({"heading_bins": 36}, {"heading_bins": 8}, {"step": 1.0},
               {"smooth": False}, {"seed": 3}):
        res = plan(world, start, goal, R, **kw)
        check_path(world, res, start, goal, R)


# -- the kernels against references -------------------------------------------------------

def test_compiled_words_match_the_numpy_words():
    rng = np.random.default_rng(7)
    s = np.c_[rng.uniform(-10, 10, (500, 2)), rng.uniform(-4, 4, 500)]
    g = np.c_[rng.uniform(-10, 10, (500, 2)), rng.uniform(-4, 4, 500)]
    ref = dubins._words(s, g, 1.7) * 1.7
    for i in range(len(s)):
        segs, total = words(*s[i], *g[i], 1.7)
        np.testing.assert_allclose(segs, ref[i], atol=1e-12, equal_nan=True)
        assert total.min() == pytest.approx(dubins.shortest_path(s[i], g[i], 1.7).length,
                                            abs=1e-9)


def test_free_heading_bound_is_the_best_heading():
    rng = np.random.default_rng(8)
    heads = np.linspace(0, 2 * math.pi, 4000, endpoint=False)
    for _ in range(100):
        s = np.r_[rng.uniform(-3, 3, 2), rng.uniform(-4, 4)]
        g = rng.uniform(-4, 4, 2)
        brute = dubins.lengths(np.tile(s, (len(heads), 1)),
                               np.c_[np.tile(g, (len(heads), 1)), heads], 1.0).min()
        b = free_heading_bound(*s, *g, 1.0)
        assert b <= brute + 1e-9
        assert b >= math.dist(s[:2], g) - 1e-12


def test_arc_and_segment_distances_match_shapely():
    rng = np.random.default_rng(9)
    for _ in range(500):
        c, r = rng.uniform(-3, 3, 2), rng.uniform(0.5, 3)
        a0, sweep = rng.uniform(-4, 4), rng.uniform(-math.pi, math.pi)
        a, b = rng.uniform(-5, 5, (2, 2))
        n = 20001
        ang = a0 + sweep * np.linspace(0, 1, n)
        ref = shapely.distance(shapely.LineString(c + r * np.c_[np.cos(ang), np.sin(ang)]),
                               shapely.LineString([a, b]))
        sag = r * (1 - math.cos(abs(sweep) / (n - 1) / 2))
        assert abs(arc_segment_distance(*c, r, a0, sweep, *a, *b) - ref) <= sag + 1e-12
        p, q = rng.uniform(-3, 3, (2, 2))
        assert segment_distance(*p, *q, *a, *b) == pytest.approx(
            shapely.distance(shapely.LineString([p, q]), shapely.LineString([a, b])),
            abs=1e-12)


def test_path_free_is_exact_at_a_corner():
    world = make_world([(40, 40, 60, 60)])
    from numba import types

    from skyroute.motion.arc_kernels import chain_free
    from skyroute.motion.pieces import Piece

    before = set(chain_free.signatures)
    # a straight that passes 1 mm above the box, and one that clips its corner by 1 mm
    assert path_free(world, [Piece("S", (10, 60.001, 0.0), 80, R)])
    assert not path_free(world, [Piece("S", (10, 59.999, 0.0), 80, R)])
    # a half turn whose lowest point is 1 mm above / below the box's top edge
    for dr, ok in ((-1e-3, True), (1e-3, False)):
        rad = 10 + dr
        p = Piece("L", (50 - rad, 70, -math.pi / 2), rad * math.pi, rad)
        assert path_free(world, [p]) is ok
    # pieces of whole numbers are checked by the planner's own (float) kernel: an int
    # start or length was a signature of its own, compiled afresh (15 s cold)
    added = set(chain_free.signatures) - before
    assert not any(t in (types.int64, types.Array(types.int64, 1, "C"))
                   for sig in added for t in (*sig[:3], sig[4], sig[5])), added


# -- smaller contracts --------------------------------------------------------------------

def test_same_start_and_goal():
    world = make_world([(40, 40, 60, 60)])
    res = plan(world, (10, 10, 1.0), (10, 10, 1.0), R)
    assert res.found and res.length == 0 and res.segments == ()
    assert res.sample(1.0).tolist() == [[10, 10, 1.0]]
    res = plan(world, (10, 10, 0.0), (10, 10, math.pi), R)  # turn round: a loop
    check_path(world, res, (10, 10, 0.0), (10, 10, math.pi), R)


def test_a_boxed_in_goal_ends_at_once():
    # the goal faces the boundary 1 m ahead: no forward path can arrive there
    world = make_world([(40, 40, 60, 60)])
    res = plan(world, (10, 10, 0.0), (99, 50, math.pi), R)
    assert res.status is Status.NO_PATH and res.expanded < 20
    assert res.extra["closed"] == "goal" and res.extra["closed_after"] == res.expanded
    # the start faces the boundary: the forward search ends at once too
    res = plan(world, (1, 50, math.pi), (90, 90, 0.0), R)
    assert res.status is Status.NO_PATH and res.expanded < 600
    assert res.extra["closed"] == "start" and res.extra["closed_after"] < 100


def test_result_pieces_describe_arcs():
    world = make_world([(48, 0, 52, 45), (48, 57, 52, 100)])
    res = plan(world, (20, 80, -math.pi / 2), (80, 20, 0.0), R)
    assert {p.kind for p in res.segments} <= {"L", "S", "R"}
    for p in res.segments:
        assert p.length > 0 and not p.reverse
        if p.kind == "S":
            assert p.centre is None and p.turn == 0
        else:
            cx, cy = p.centre
            assert math.dist((cx, cy), p.start[:2]) == pytest.approx(R)
            assert math.dist((cx, cy), p.end[:2]) == pytest.approx(R)
            assert p.turn == pytest.approx((1 if p.kind == "L" else -1) * p.length / R)
            a = p.start_angle
            assert (cx + R * math.cos(a), cy + R * math.sin(a)) == pytest.approx(p.start[:2])


# -- reverse gears ------------------------------------------------------------------------

def test_reverse_never_longer_than_dubins_in_an_empty_world():
    world = make_world([], (-200, -200, 200, 200))
    rng = np.random.default_rng(3)
    for _ in range(10):
        start = (*rng.uniform(-30, 30, 2), rng.uniform(-math.pi, math.pi))
        goal = (*rng.uniform(-30, 30, 2), rng.uniform(-math.pi, math.pi))
        res = plan(world, start, goal, R, reverse=True)
        assert res.length <= dubins.shortest_path(start, goal, R).length + 1e-9
        check_path(world, res, start, goal, R, reverse=True)


def test_reverse_backs_out_of_a_dead_end():
    world = make_world([(20, 44, 60, 47), (20, 53, 60, 56), (17, 44, 20, 56)])
    start, goal = (40, 50, math.pi), (80, 80, 0.0)
    assert plan(world, start, goal, R).status is Status.NO_PATH
    res = plan(world, start, goal, R, reverse=True)
    check_path(world, res, start, goal, R, reverse=True)
    assert res.segments[0].reverse  # it backs out first


def test_reverse_parks_beside_where_it_started():
    world = make_world([(0, 0, 100, 40)])  # a kerb below
    start, goal = (30, 45, 0.0), (40, 45, math.pi)  # turn round in a 55 m wide street
    forward = plan(world, start, goal, R)
    res = plan(world, start, goal, R, reverse=True)
    check_path(world, forward, start, goal, R)
    check_path(world, res, start, goal, R, reverse=True)
    assert res.length < forward.length


def test_a_world_past_the_corner_limit_is_refused_before_the_table(monkeypatch):
    from skyroute.motion import corner_distance

    def fail(*_args):
        pytest.fail("the corner table was built")

    monkeypatch.setattr(corner_distance, "MAX_CORNERS", 10)
    monkeypatch.setattr(World, "segments_free", fail)
    world = make_world([(10, 10, 20, 20), (40, 40, 50, 50), (70, 10, 80, 20)], boundary=None)
    with pytest.raises(OptionError) as err:
        corner_distance.corner_graph(world)
    assert str(err.value).endswith(": 12 obstacle corners, over the limit of 10 for Hybrid "
                                   "A*'s corner distances (built over every pair of them); "
                                   "plan with the waypoints planner or another vehicle "
                                   "(lattice, field), or plan at an altitude that keeps "
                                   "fewer obstacles")
    monkeypatch.setattr(World, "merged", fail)  # four apart: refused before the union
    four = make_world([(10 * k, 60, 10 * k + 5, 65) for k in range(4)], boundary=None)
    with pytest.raises(OptionError, match=": at least 12 obstacle corners, over the limit"):
        corner_distance.corner_graph(four)


def test_corner_table_is_shapely_on_the_merged_obstacles():
    """The corner table (now the world's visibility graph) holds exactly the bitangent
    corner pairs that shapely finds free of the merged obstacles, with their lengths (two
    boxes sharing an edge are one block: no path squeezes between them)."""
    from skyroute.motion import corner_distance
    from skyroute.world.geometry import convex_corners

    # two boxes meeting along y = 20 for x in 20..30: a step of 6 convex corners, and the
    # bitangent (10, 20) -> (40, 20) runs through their shared edge, inside the block
    world = make_world([(10, 10, 30, 20), (20, 20, 40, 30), (50, 40, 60, 70),
                        (20, 50, 35, 60), shapely.Polygon([(70, 10), (90, 15), (80, 30)])])
    g = corner_distance.corner_graph(world)
    corners, prev, nxt = convex_corners(world.merged())
    assert len(corners) == len(g.corners) == 17  # 6 + 4 + 4 + 3
    order = [int(np.flatnonzero((corners == c).all(axis=1))[0]) for c in g.corners]
    corners, prev, nxt = corners[order], prev[order], nxt[order]
    union = shapely.union_all(world.obstacles)

    def tangent(k, d):  # the line along d through corner k leaves both ring edges one side
        a, b = prev[k] - corners[k], nxt[k] - corners[k]
        return (d[0] * a[1] - d[1] * a[0]) * (d[0] * b[1] - d[1] * b[0]) >= 0

    step = [int(np.flatnonzero((g.corners == c).all(axis=1))[0]) for c in ((10, 20), (40, 20))]
    assert g.adjacency[step[0], step[1]] == np.inf
    for i in range(17):
        for j in range(17):
            if i == j:
                continue
            d = corners[j] - corners[i]
            seg = shapely.LineString([corners[i], corners[j]])
            free = tangent(i, d) and tangent(j, -d) and \
                not seg.relate_pattern(union, "T********")
            assert g.adjacency[i, j] == (pytest.approx(seg.length) if free else np.inf), (i, j)


def _tower() -> World:
    return World([shapely.box(1, 1, 3, 3)], [0], [50], ("tower",))


def test_hybrid_takes_0d_arrays_and_numpy_bools():
    # array(0.5) was refused as a radius, np.True_ as reverse
    a = plan(_tower(), (np.array(0.0), np.array(2.0), 0), (5, 2, 0), np.array(0.5),
             step=np.array(0.3), reverse=np.bool_(False))
    b = plan(_tower(), (0, 2, 0), (5, 2, 0), 0.5, step=0.3)
    assert a.found and a.length == b.length


@pytest.mark.parametrize("kw", [{"smooth": "no"}, {"approach": True},
                                {"seed": 1.5}, {"seed": -1}, {"max_expansions": "5"}])
def test_hybrid_names_a_bad_option(kw):
    # smooth="no" and approach=True were taken
    (name, _), = kw.items()
    with pytest.raises(OptionError, match=f"{name}=") as err:
        plan(_tower(), (0, 2, 0), (5, 2, 0), 0.5, **kw)
    assert err.value.param == name


def test_hybrid_refuses_a_negative_seed_as_every_other_seed_is():
    # seed=-1 was taken (and folded to 2**32 - 1 for the shortcutting), where PRM, the
    # fleet runs and the data synthesis refuse it
    with pytest.raises(OptionError) as err:
        plan(_tower(), (0, 2, 0), (5, 2, 0), 0.5, seed=-1)
    assert str(err.value) == "seed=-1 must be an integer from 0 to 4,294,967,295"


def test_runway_goal_names_a_bad_heading():
    with pytest.raises(OptionError, match="runway_heading="):
        runway_goal((0, 0), "x", 1.0)


@pytest.mark.parametrize("start, goal", [
    ((59.25, 142.31, 4.715), (111.79, 130.86)),
    ((-35.7, -168.98), (-81.52, -27.41)),
    ((29.47, 115.24), (77.41, -46.56)),
    ((1.92, 96.63), (-70.38, 91.07)),
    ((-102.51, 165.87), (88.32, -48.34)),
    ((-165.7, -2.73, 4.293), (161.38, -73.67)),
])
def test_a_result_has_no_sliver_piece_and_samples_no_pose_twice(start, goal):
    """Seeded queries on examples/city.csv (radius 8): the result ended with a piece of
    rounding's length (2e-18 to 3e-14 m, the last arc of a Dubins word), so sample()
    gave the goal twice and `fly --vehicle dubins --out` wrote it twice. Slivers are
    dropped where the result is built; the path still joins start and goal exactly."""
    world = skyroute.load_world(ROOT / "examples" / "city.csv", altitude=10, safety=2,
                                frame="enu")
    res = plan(world, start, goal, 8.0, max_expansions=200_000)
    assert res.found
    assert min(p.length for p in res.segments) > 1e-9
    for a, b in itertools.pairwise(res.segments):
        assert math.dist(a.end[:2], b.start[:2]) < 1e-9
        assert abs(wrap(a.end[2] - b.start[2])) < 1e-9
    assert math.dist(res.segments[-1].end[:2], goal[:2]) < 1e-9
    assert res.length == pytest.approx(sum(p.length for p in res.segments))
    poses = res.sample(1.0)
    assert (np.hypot(*np.diff(poses[:, :2], axis=0).T) > 1e-6).all()
    assert poses[0, :2].tolist() == list(start[:2]) and poses[-1, :2].tolist() == list(goal)
    assert path_free(world, res.segments)


def test_a_radius_far_larger_than_the_world_is_planned_at_once():
    """A turning radius of 1,000 km round a 100 m block without a boundary: the way past
    the block is a loop of about 2 pi r. Each primitive (r pi / 9 long) was tested chunk
    by chunk at the edge buckets' size (1.6 m) also far outside the world: radius 1e6
    took 95 s, and this one (1e9) would take about a day; the chunks that cannot reach
    the world are skipped, so it takes well under a second."""
    world = make_world([(40, 40, 60, 60)], boundary=None)
    r = 1e9
    res = plan(world, (0, 0), (100, 100), r, max_expansions=20_000)
    assert res.found and res.length == pytest.approx(2 * math.pi * r, rel=1e-3)
    assert all(p.radius == r for p in res.segments)
    assert path_free(world, res.segments)
    line = shapely.LineString(res.sample(r / 1e4)[:, :2])
    assert not line.intersects(world.obstacles[0])


def test_a_start_or_goal_on_an_edge_is_refused_naming_it():
    """A point on an obstacle's edge is free in the world, but every piece from it meets
    the edge: the search ended in no_path after 572 expansions. And two boxes touching
    along x = 50 are one block whose outline alone the pieces were tested against: from
    a start to a goal on the face they share the path ran 16 m through the block
    (found, length 16). Both are refused, naming the point: the shared face is inside
    the block's union (as the world now tests it), an outer edge is on the edge."""
    block = make_world([(40, 40, 50, 60), (50, 40, 60, 60)])
    with pytest.raises(QueryError, match=r"^start \(50.00, 42.00\) lies inside obstacle "
                       r"'obstacle 0'; nearest free point \(50.00, 39.99\)$"):
        plan(block, (50, 42, math.pi / 2), (50, 58, math.pi / 2), R)
    with pytest.raises(QueryError, match=r"^goal \(50.00, 58.00\) lies inside obstacle"):
        plan(block, (20, 20), (50, 58), R)
    with pytest.raises(QueryError, match=r"^start \(60.00, 50.00\) lies on the edge"):
        plan(block, (60, 50, 0.0), (90, 90), R)  # facing away from the east face
    # a hair off it, the way out is found (and the same flight a hair further off)
    res = plan(block, (60.01, 50, 0.0), (90, 90), R)
    check_path(block, res, (60.01, 50, 0.0), (90, 90), R)


# -- Ctrl-C -------------------------------------------------------------------------------

def _interrupted(monkeypatch, handler):
    """The 0.5 m query of the default budget's test (about 55,000 expansions) with
    ``handler`` as SIGINT's and a SIGINT as its forward search starts (the second, after
    the 500 expansions the other way): tests/search/sigint.py."""
    from skyroute.motion import hybrid_search
    from tests.search.sigint import interrupted

    world = make_world([(45, 0, 55, 60)])
    query = (world, (20, 20, 0.0), (80, 20, 0.0), 0.5)
    plan(*query, max_expansions=5000)  # compiled, and the same tables built
    out = interrupted(monkeypatch, hybrid_search, lambda: plan(*query), handler, at=2)
    return out, query


def test_ctrl_c_stops_a_long_search_inside_the_compiled_loop_and_frees_it(monkeypatch):
    """Hybrid A*'s default budget is 10,000,000 expansions (minutes), in one compiled
    call that Ctrl-C could not stop: the signal's handler ran when it returned. It polls
    every 4,096 expansions and returns; the handler runs after, from Python, so nothing
    of the search stays allocated (skyroute.search.interrupt)."""
    from skyroute.result import BUDGET_EXHAUSTED
    from skyroute.search.interrupt import INTERRUPTED

    class SigintError(Exception):
        pass

    def handler(signum, frame):
        raise SigintError

    (out, statuses, (allocs, frees)), _ = _interrupted(monkeypatch, handler)
    assert isinstance(out, SigintError)
    assert statuses == [BUDGET_EXHAUSTED, INTERRUPTED]  # stopped inside, not at its end
    assert allocs > 0 and frees == allocs


def test_a_sigint_handler_that_does_not_raise_lets_the_search_end(monkeypatch):
    from skyroute.result import BUDGET_EXHAUSTED, FOUND
    from skyroute.search.interrupt import INTERRUPTED

    calls = []
    (out, statuses, _), query = _interrupted(monkeypatch, lambda signum, frame: calls.append(1))
    assert calls == [1]
    assert statuses == [BUDGET_EXHAUSTED, INTERRUPTED, FOUND]
    alone = plan(*query)
    assert out.found and (out.length, out.expanded) == (alone.length, alone.expanded)
    assert out.segments == alone.segments
