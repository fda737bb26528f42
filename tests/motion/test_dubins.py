"""Dubins paths against OMPL's DubinsStateSpace and published cases."""

import itertools
import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from numba import njit

from skyroute import OptionError
from skyroute.motion import dubins as D  # noqa: N812
from skyroute.motion.dubins_kernel import shortest_length

try:  # OMPL is the reference for the comparison only; every other test runs without it
    import ompl.base as ob
except ImportError:
    ob = None
needs_ompl = pytest.mark.skipif(ob is None, reason="OMPL is not installed (the reference "
                                "DubinsStateSpace; pip install 'skyroute[dev]')")


def ompl_lengths(starts, goals, r):
    space = ob.DubinsStateSpace(r)
    a, b = space.allocState(), space.allocState()
    out = np.empty(len(starts))
    for i, (s, g) in enumerate(zip(starts, goals, strict=True)):
        a.setX(s[0]), a.setY(s[1]), a.setYaw(s[2])
        b.setX(g[0]), b.setY(g[1]), b.setYaw(g[2])
        out[i] = space.distance(a, b)
    return out


@needs_ompl
@pytest.mark.parametrize("radius", [0.5, 1.0, 3.7])
def test_agrees_with_ompl_on_10000_random_queries(radius):
    rng = np.random.default_rng(42)
    n = 10_000
    s = np.c_[rng.uniform(-10, 10, (n, 2)), rng.uniform(-math.pi, math.pi, n)]
    g = np.c_[rng.uniform(-10, 10, (n, 2)), rng.uniform(-math.pi, math.pi, n)]
    np.testing.assert_allclose(D.lengths(s, g, radius), ompl_lengths(s, g, radius),
                               rtol=0, atol=1e-9)


def random_poses(rng, n, span=10.0, turns=1.0):
    """n random start and goal poses in a square of side 2 span, headings within +-turns
    half-turns."""
    def poses():
        return np.c_[rng.uniform(-span, span, (n, 2)),
                     rng.uniform(-turns * math.pi, turns * math.pi, n)]

    return poses(), poses()


@needs_ompl
def test_batch_agrees_with_ompl_on_100000_random_queries():
    s, g = random_poses(np.random.default_rng(0), 100_000)  # as 'bench motion --dubins'
    diff = np.abs(D.lengths(s, g, 1.7) - ompl_lengths(s, g, 1.7))
    assert diff.max() <= 1e-9


@needs_ompl
def test_near_poses_and_wound_headings_agree_with_ompl_and_the_numpy_words():
    # within a few radii (the CCC words compete) and headings wound up to 10 turns (the
    # compiled angle wrapping's slow path); the numpy words are the other reference
    rng = np.random.default_rng(3)
    for span, turns in ((1.5, 1.0), (4.0, 1.0), (10.0, 20.0)):
        s, g = random_poses(rng, 5_000, span, turns)
        ours = D.lengths(s, g, 1.3)
        np.testing.assert_allclose(ours, ompl_lengths(s, g, 1.3), rtol=0, atol=1e-9)
        w = D._words(s, g, 1.3)
        ref = np.where(np.isnan(w[..., 0]), np.inf, w.sum(axis=2)).min(axis=1) * 1.3
        np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-9)


def test_batch_is_the_same_on_one_thread_and_two():
    import numba

    s, g = random_poses(np.random.default_rng(5), 20_000)
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = D.lengths(s, g, 2.0)
        numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        two = D.lengths(s, g, 2.0)
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(one, two)


def test_kernels_are_compiled_without_fastmath():
    # A straight piece is sqrt(p2) with p2 a sum that cancels near 0: reordered or
    # contracted arithmetic can move p2 by ~1e-16 and so the root by ~1e-8 there, past
    # the 1e-9 agreement with OMPL. Measured on 1M random queries: fastmath changed the
    # lengths by 3e-14 and gained 2 %; not worth that risk.
    from skyroute.motion import dubins_batch, dubins_kernel

    for kernel in (dubins_batch.lengths_kernel, dubins_batch._block, dubins_batch._atan2_all,
                   dubins_kernel.shortest_length, dubins_kernel.words):
        assert not kernel.targetoptions.get("fastmath"), kernel


@settings(max_examples=300, deadline=None)
@given(st.floats(-60.0, 60.0))
def test_compiled_angle_wrap_is_the_numpy_one(a):
    from skyroute.motion.dubins_kernel import _m2p

    ours, ref = _m2p(a), float(D._mod2pi(np.float64(a)))
    assert 0.0 <= ours < 2 * math.pi
    gap = abs(ours - ref)
    assert min(gap, 2 * math.pi - gap) <= 1e-12  # 0 and 2 pi - 1e-13 are one angle


def test_published_cases():
    p = D.shortest_path((0, 0, math.pi / 2), (1, 0, -math.pi / 2), 1.0)
    assert p.word == "LRL"
    assert D.shortest_path((0, 0, 0), (10, 0, 0), 2.0).length == pytest.approx(10.0, abs=1e-12)
    half = D.shortest_path((0, 0, 0), (0, 2 * 1.5, math.pi), 1.5)  # a half loop
    assert half.length == pytest.approx(math.pi * 1.5, abs=1e-12) and half.word in ("LSL",
                                                                                      "LRL")
    assert D.shortest_path((3, 4, 1.0), (3, 4, 1.0), 1.0).length == pytest.approx(0, abs=1e-12)
    with pytest.raises(OptionError, match="radius"):
        D.shortest_path((0, 0, 0), (1, 1, 0), -1.0)
    with pytest.raises(OptionError, match="radius"):
        D.lengths([[0, 0, 0]], [[1, 1, 0]], 0.0)


@settings(max_examples=100, deadline=None)
@given(st.floats(0.2, 5.0), st.floats(0.1, 10.0), st.integers(0, 2**31))
def test_length_scales_with_radius(r, k, seed):
    rng = np.random.default_rng(seed)
    s = np.c_[rng.uniform(-5, 5, (20, 2)), rng.uniform(-3, 3, 20)]
    g = np.c_[rng.uniform(-5, 5, (20, 2)), rng.uniform(-3, 3, 20)]
    scale = np.array([k, k, 1.0])
    np.testing.assert_allclose(D.lengths(s * scale, g * scale, r * k), k * D.lengths(s, g, r),
                               rtol=1e-9, atol=1e-9)


@settings(max_examples=200, deadline=None)
@given(st.tuples(*[st.floats(-20, 20)] * 2, st.floats(-4, 4)),
       st.tuples(*[st.floats(-20, 20)] * 2, st.floats(-4, 4)), st.floats(0.3, 4.0))
def test_pieces_fly_to_the_goal_and_samples_end_there(s, g, r):
    p = D.shortest_path(s, g, r)
    end = p.pose_at(p.length)  # integrate the three pieces: independent of the formulas
    assert end[:2] == pytest.approx(g[:2], abs=1e-7)
    assert math.cos(end[2] - g[2]) == pytest.approx(1.0, abs=1e-9)
    assert p.length == pytest.approx(D.lengths([s], [g], r)[0], abs=1e-9)
    step = max(p.length / 50, 0.05)
    poses = p.sample(step)
    np.testing.assert_array_equal(poses[-1], [g[0], g[1], g[2] % (2 * math.pi)])
    np.testing.assert_array_equal(poses[0][:2], s[:2])
    assert np.all(np.hypot(*np.diff(poses[:, :2], axis=0).T) <= step + 1e-9)


def test_through_waypoints_chains_and_beats_fixed_headings():
    pts = [(0, 0), (10, 0), (10, 10), (0, 10)]
    legs = D.through(pts, 2.0, start_heading=0.0)
    assert len(legs) == 3
    for a, b in itertools.pairwise(legs):
        assert a.goal == b.start
    fixed = sum(D.shortest_path((*pts[i], 0.0), (*pts[i + 1], 0.0), 2.0).length
                for i in range(3))
    assert sum(leg.length for leg in legs) <= fixed


def test_runway_approach_and_loiter():
    legs = D.runway_approach((0, 0, 0), (50, 20), math.pi / 2, 5.0, final=15.0)
    assert legs[-1].goal == (50.0, 20.0, math.pi / 2)
    assert legs[-1].length == pytest.approx(15.0, abs=1e-9)  # straight final approach
    circle = D.loiter((3, 4), 10.0, turns=1.0, step=2.0)
    np.testing.assert_allclose(np.hypot(circle[:, 0] - 3, circle[:, 1] - 4), 10.0)
    # anticlockwise: heading is the radius direction plus 90 degrees
    ang = np.arctan2(circle[:, 1] - 4, circle[:, 0] - 3)
    np.testing.assert_allclose(np.cos(circle[:, 2] - ang - math.pi / 2), 1.0, atol=1e-9)


@pytest.mark.parametrize("turns", [0, 1, -2, 10])
def test_the_start_pose_as_goal_is_length_zero(turns):
    # the batch kernel forms cos(a - b) from sines and cosines: at d = 0 it rounds to
    # 1 - ulp, which once dropped the zero-length word and answered a full circle
    rng = np.random.default_rng(turns + 5)
    th = rng.uniform(-4, 4, 400)
    xy = rng.uniform(-20, 20, (400, 2))
    s = np.c_[xy, th]
    g = np.c_[xy, th + 2 * math.pi * turns]
    for r in (0.3, 1.0, 4.0):
        assert np.all(D.lengths(s, g, r) == 0.0)
        assert D.shortest_path(tuple(s[0]), tuple(g[0]), r).length == pytest.approx(0, abs=1e-9)


def test_a_goal_a_hair_ahead_is_reached_straight():
    # a goal 6e-8 r straight ahead (off the heading line by rounding only) is reached by
    # a near-straight path of about that length, as the numpy words find, not by a loop
    # (a bearing-free variant of the kernel answered 2 pi r here and was not kept)
    r, d = 1.0, 5.960464477539063e-08
    s = (1.0, 1.0, 0.875)
    g = (1.0 + d * math.cos(0.875), 1.0 + d * math.sin(0.875), 0.875)
    w = D._words(np.array([s]), np.array([g]), r)[0]
    ref = np.where(np.isnan(w[:, 0]), np.inf, w.sum(axis=1)).min() * r
    assert ref == pytest.approx(d, rel=1e-6)
    assert D.lengths([s], [g], r)[0] == pytest.approx(ref, rel=1e-6)


def test_a_goal_a_rounding_error_away_with_the_same_heading():
    # hypothesis found it: the goal 1.4e-45 from the start, the same heading; the
    # compiled cos(a - b) (a sum of products) rounded to 1 - ulp and dropped the
    # vanishing LSR word, answering a full circle where the numpy words answer 5e-23
    s = (-1.401298464324817e-45, -1.401298464324817e-45, 2.0)
    g = (-1.401298464324817e-45, 0.0, 2.0)
    w = D._words(np.array([s]), np.array([g]), 1.0)[0]
    ref = np.where(np.isnan(w[:, 0]), np.inf, w.sum(axis=1)).min()
    assert ref < 1e-20
    assert D.lengths([s], [g], 1.0)[0] == pytest.approx(ref, abs=1e-30)
    assert D.shortest_path(s, g, 1.0).length == pytest.approx(ref, abs=1e-30)



@pytest.mark.parametrize("span", [1.0, 10.0])
def test_a_goal_a_micro_radius_ahead_is_not_a_loop(span):
    # goals 1e-6 r ahead along the start heading, off its line by rounding: LSR's and
    # RSL's p^2 was formed as (d^2 - 2) + 2 cos(a - b), whose first sum dropped d^2's
    # digits below 2e-16 (a 2e-4 relative error at d = 1e-6): the S-curve's angle came out
    # a hair negative, a full turn, and 58% of such queries answered 2 pi r instead of d
    d = 1e-6
    rng = np.random.default_rng(7)
    th = rng.uniform(-math.pi, math.pi, 2000)
    s = np.c_[rng.uniform(-span, span, (2000, 2)), th]
    g = np.c_[s[:, 0] + d * np.cos(th), s[:, 1] + d * np.sin(th), th]
    np.testing.assert_allclose(D.lengths(s, g, 1.0), d, rtol=1e-6)
    np.testing.assert_allclose(_scalar_lengths(s, g, 1.0), d, rtol=1e-6)
    w = D._words(s, g, 1.0)
    np.testing.assert_allclose(np.where(np.isnan(w[..., 0]), np.inf, w.sum(axis=2)).min(1),
                               d, rtol=1e-6)
    # the runway's final leg, 1e-6 r long (found by hypothesis: one 2 pi r loop)
    legs = D.runway_approach((0, 0, 0), (0, 1), 1.0, 1.0, final=d)
    assert legs[-1].length == pytest.approx(d, rel=1e-6)

@given(r=st.sampled_from([0.5, 1.0, 2.0, 7.3, 100.0]), k=st.integers(1, 7),
       side=st.sampled_from([1, -1]), th0=st.sampled_from([0.0, 0.3, -math.pi, 2.0]))
@settings(max_examples=150, deadline=None, derandomize=True)
@example(r=1.0, k=1, side=1, th0=0.0)  # 0.79 (a 45-degree left arc) came out 7.07, LRL
@example(r=10.0, k=2, side=-1, th0=0.0)  # a quarter turn right: 15.7, came out 78.5
def test_a_goal_on_the_turning_circle_is_one_arc(r, k, side, th0):
    # the goal exactly where a turn of k x 45 degrees ends: the shortest path is that
    # arc, r x angle (LSL or RSR with no straight). Its p2 = 0 rounded to -1e-16 and the
    # word was dropped for a path round two more circles, 2 pi r longer
    turn = k * math.pi / 4
    s = (3.0, -2.0, th0)
    th1 = th0 + side * turn
    cx, cy = s[0] - side * r * math.sin(th0), s[1] + side * r * math.cos(th0)
    g = (cx + side * r * math.sin(th1), cy - side * r * math.cos(th1), th1)
    want = r * turn
    p = D.shortest_path(s, g, r)
    assert p.length == pytest.approx(want, rel=1e-9)
    mid, end = p.sample_at(np.array([p.length / 2, p.length]))
    assert math.hypot(mid[0] - cx, mid[1] - cy) == pytest.approx(r, rel=1e-9)
    assert math.hypot(end[0] - g[0], end[1] - g[1]) < 1e-9 * r
    assert D.lengths([s], [g], r)[0] == pytest.approx(want, rel=1e-9)
    assert shortest_length(*s, *g, r) == pytest.approx(want, rel=1e-9)
    w = D._words(np.array([s]), np.array([g]), r)[0]
    assert np.nanmin(w.sum(axis=1)) * r == pytest.approx(want, rel=1e-9)


@njit
def _scalar_lengths(s, g, r):
    """The per-node kernel (branches, libm) over a batch, one query at a time."""
    out = np.empty(len(s))
    for i in range(len(s)):
        out[i] = shortest_length(s[i, 0], s[i, 1], s[i, 2], g[i, 0], g[i, 1], g[i, 2], r)
    return out


def _degenerate_poses(rng, n):
    """Goals on the start pose, a hair ahead or behind, on the turning circles, with
    headings equal, opposite or a quarter turn apart: where p2 and c sit on 0 and +-1."""
    s = np.c_[rng.uniform(-5, 5, (n, 2)), rng.choice([0.0, math.pi / 2, -math.pi, 0.875], n)]
    kind = rng.integers(0, 5, n)
    dist = np.choose(kind, [np.zeros(n), np.full(n, 6e-8), rng.uniform(0, 4, n),
                            np.full(n, 2.0), np.full(n, 4.0)])
    bearing = s[:, 2] + rng.choice([0.0, math.pi, math.pi / 2, -math.pi / 2], n)
    turn = rng.choice([0.0, math.pi, math.pi / 2, 2 * math.pi, -4 * math.pi], n)
    g = np.c_[s[:, 0] + dist * np.cos(bearing), s[:, 1] + dist * np.sin(bearing),
              s[:, 2] + turn]
    return s, g


@pytest.mark.parametrize("span, turns", [(10.0, 1.0), (1.5, 1.0), (0.01, 1.0), (10.0, 20.0)])
def test_branch_free_batch_kernel_is_the_per_node_kernel(span, turns):
    # the batch runs dubins_batch (own polynomials, all six words, selects, in stages);
    # the search runs shortest_length (libm, branches): one length, to rounding
    s, g = random_poses(np.random.default_rng(17), 50_000, span, turns)
    np.testing.assert_allclose(D.lengths(s, g, 1.0), _scalar_lengths(s, g, 1.0),
                               rtol=0, atol=1e-12)


def test_branch_free_batch_kernel_on_degenerate_poses():
    # against the two references that share our 1e-12 angle snapping (OMPL snaps turns
    # within 5e-7, so it reaches a goal 6e-8 behind straight, where we loop)
    s, g = _degenerate_poses(np.random.default_rng(23), 20_000)
    for r in (0.5, 1.0, 2.0):
        ours = D.lengths(s, g, r)
        np.testing.assert_allclose(ours, _scalar_lengths(s, g, r), rtol=0, atol=1e-9)
        w = D._words(s, g, r)
        ref = np.where(np.isnan(w[..., 0]), np.inf, w.sum(axis=2)).min(axis=1) * r
        np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-9)


@pytest.mark.parametrize("n", [0, 1, 511, 512, 513, 2049])
def test_batch_blocks_cover_every_query(n):
    s, g = random_poses(np.random.default_rng(n), n)
    out = D.lengths(s, g, 1.5)
    assert out.shape == (n,)
    np.testing.assert_allclose(out, _scalar_lengths(s, g, 1.5), rtol=0, atol=1e-12)


def test_batch_takes_strided_and_non_contiguous_poses():
    s, g = random_poses(np.random.default_rng(31), 3000)
    both = np.c_[s, g]  # (N, 6): starts and goals are column slices of one array
    np.testing.assert_array_equal(D.lengths(both[:, :3], both[:, 3:], 1.2),
                                  D.lengths(s, g, 1.2))
    np.testing.assert_array_equal(D.lengths(s[::2], g[::2], 1.2), D.lengths(s, g, 1.2)[::2])


@pytest.mark.parametrize("radius", ["1", [1.0], None, True])
def test_a_bad_radius_is_an_option_error(radius):
    # "1" and None were numpy TypeErrors, True was a radius of 1
    for call in (lambda: D.shortest_path((0, 0, 0), (10, 0, 0), radius),
                 lambda: D.lengths([[0, 0, 0]], [[10, 0, 0]], radius),
                 lambda: D.through([(0, 0), (10, 0)], radius),
                 lambda: D.loiter((0, 0), radius)):
        with pytest.raises(OptionError, match="radius="):
            call()


@pytest.mark.parametrize("pose", [(0, 0), (0, 0, 0, 0), "000", None, (math.nan, 0, 0)])
def test_a_bad_pose_is_a_query_error(pose):
    # a numpy reshape ValueError before (an OptionError for NaN)
    from skyroute import QueryError

    with pytest.raises(QueryError, match="start"):
        D.shortest_path(pose, (10, 0, 0), 1.0)
    with pytest.raises(QueryError, match="starts"):
        D.lengths([pose], [(10, 0, 0)], 1.0)


def test_lengths_refuse_nan_poses():
    # NaN came back as a length
    from skyroute import QueryError

    with pytest.raises(QueryError, match="goals must be finite"):
        D.lengths([[0, 0, 0]], [[math.nan, 0, 0]], 1.0)


@pytest.mark.parametrize("kw", [{"step": 0}, {"step": -1.0}, {"step": math.nan},
                                {"turns": -1.0}, {"turns": math.inf}, {"turns": "2"},
                                {"start_angle": math.nan}, {"step": 1e-12}])
def test_loiter_names_a_bad_option(kw):
    # step=0 was a ZeroDivisionError, -1 one pose, turns=inf "Maximum allowed size"
    (name, _), = kw.items()
    with pytest.raises(OptionError, match=f"{name}="):
        D.loiter((0, 0), 5.0, **kw)


@pytest.mark.parametrize("headings", [0, -3, "36", True, 2.5])
def test_through_names_a_bad_headings(headings):
    # 0 was "argmin of an empty sequence", True and 2.5 were taken
    with pytest.raises(OptionError, match="headings="):
        D.through([(0, 0), (10, 0)], 1.0, headings=headings)


def test_dubins_takes_numpy_numbers():
    p = D.shortest_path(np.float32([0, 0, 0]), (10, 0, 0), np.array(2.0))
    assert p.length == D.shortest_path((0, 0, 0), (10, 0, 0), 2.0).length
    assert len(D.through([(0, 0), (10, 0)], np.float32(1.0), headings=np.int64(8))) == 1
    assert p.sample(np.float32(1.0)).shape == p.sample(1.0).shape


@pytest.mark.parametrize("radius", [np.int64(2), np.float32(2.0), np.array(2.0)])
def test_tour_takes_numpy_radius_and_headings(radius):
    # refused as "radius=np.float32(2.0) must be > 0"
    r = D.tour((0, 0, 0), [(10, 0), (10, 10)], radius, headings=np.int64(8))
    assert r.found and r.length == D.tour((0, 0, 0), [(10, 0), (10, 10)], 2.0,
                                          headings=8).length


@pytest.mark.parametrize("kw", [{"radius": True}, {"headings": True},
                                {"exact_limit": "8"}, {"exact_limit": -1},
                                {"exact_limit": 2.5}])
def test_tour_names_a_bad_option(kw):
    kw = {"radius": 2.0, **kw}
    name = next(k for k in kw if k != "radius") if len(kw) > 1 else "radius"
    with pytest.raises(OptionError, match=f"{name}="):
        D.tour((0, 0, 0), [(10, 0)], **kw)


def test_a_dubins_path_says_found_as_every_result_does():
    assert D.shortest_path((0, 0, 0), (10, 0, 0), 1.0).found is True


def test_sampling_past_max_samples_is_an_option_error_naming_step():
    # a step of 1e-12 along 250 m asked numpy for 2.5e14 poses: a MemoryError (or, at
    # 1e-7, gigabytes of memory before it), never a message
    p = D.shortest_path((0, 0, 0), (250, 0, 0), 1.0)
    with pytest.raises(OptionError, match=r"step=1e-12 along a path 250 long makes more "
                                          r"than 10,000,000 poses; take a step >= 2\.5e-05"):
        p.sample(1e-12)
    assert len(p.sample(0.5)) == 501
    t = D.tour((0, 0, 0), [(250, 0), (250, 50)], 1.0)
    with pytest.raises(OptionError, match=r"step=1e-12 along a path"):
        t.sample(1e-12)
    assert np.allclose(t.sample(1.0)[-1, :2], (250, 50))
