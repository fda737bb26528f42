"""The compiled sin, cos, atan2 and acos of :mod:`skyroute.motion.trig` against libm."""

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from numba import njit

from skyroute.motion import trig

finite = st.floats(allow_nan=False, allow_infinity=False)


@njit
def _atan2_many(y, x):
    out = np.empty(len(y))
    for i in range(len(y)):
        out[i] = trig.atan2(y[i], x[i])
    return out


@njit
def _sincos_many(x):
    s, c = np.empty(len(x)), np.empty(len(x))
    for i in range(len(x)):
        s[i], c[i] = trig.sincos(x[i])
    return s, c


@njit
def _acos_many(c):
    out = np.empty(len(c))
    for i in range(len(c)):
        out[i] = trig.acos(c[i])
    return out


def _same_angle(ours, ref, tol=4.5e-16):
    return abs(ours - ref) <= max(tol, 2.3e-16 * abs(ref))


@settings(max_examples=500, deadline=None)
@given(finite, finite)
def test_atan2_is_libm_atan2_in_every_quadrant_and_at_any_ratio(y, x):
    ours = float(_atan2_many(np.array([y]), np.array([x]))[0])
    ref = math.atan2(y, x)
    assert _same_angle(ours, ref), (y, x, ours, ref)
    assert math.copysign(1.0, ours) == math.copysign(1.0, ref)


def test_atan2_signed_zeros_axes_and_extremes_exactly():
    cases = [(0.0, 0.0), (-0.0, 0.0), (0.0, -0.0), (-0.0, -0.0), (0.0, -1.0), (-0.0, -1.0),
             (1.0, 0.0), (-1.0, 0.0), (1.0, -0.0), (5e-324, 1.0), (1.0, 5e-324),
             (1e308, -1e308), (-1e-320, -1e-320), (1e-300, 1e300), (1e300, -1e-300)]
    y, x = np.array(cases).T
    ours = _atan2_many(y, x)
    for (yi, xi), o in zip(cases, ours, strict=True):
        ref = math.atan2(yi, xi)
        assert _same_angle(o, ref) and math.copysign(1, o) == math.copysign(1, ref), (yi, xi)
    assert _atan2_many(np.array([0.0, 1.0]), np.array([1.0, 1.0])).tolist() == [
        0.0, math.pi / 4]


def test_atan2_on_a_million_random_points_and_near_the_reduction_bounds():
    rng = np.random.default_rng(11)
    y = rng.standard_normal(1_000_000) * 10.0 ** rng.uniform(-20, 20, 1_000_000)
    x = rng.standard_normal(1_000_000) * 10.0 ** rng.uniform(-20, 20, 1_000_000)
    assert np.abs(_atan2_many(y, x) - np.arctan2(y, x)).max() <= 4.5e-16
    t = np.concatenate([np.nextafter(v, [-1, 1]) for v in (7 / 16, 11 / 16, 1.0)]
                       + [np.array([7 / 16, 11 / 16, 1.0])])
    assert np.abs(_atan2_many(t, np.ones_like(t)) - np.arctan(t)).max() <= 2.3e-16


@settings(max_examples=500, deadline=None)
@given(st.floats(-100.0, 100.0))
def test_sincos_is_libm_sin_and_cos(x):
    s, c = _sincos_many(np.array([x]))
    assert abs(s[0] - math.sin(x)) <= 2.3e-16 and abs(c[0] - math.cos(x)) <= 2.3e-16


def test_sincos_on_the_angles_the_kernel_passes():
    x = np.r_[np.linspace(0, 2 * math.pi, 200_001), np.arange(9) * math.pi / 4,
              np.nextafter(2 * math.pi, 0), 1e-300, 5e-324]
    s, c = _sincos_many(x)
    assert np.abs(s - np.sin(x)).max() <= 2.3e-16
    assert np.abs(c - np.cos(x)).max() <= 2.3e-16
    assert s[-1] == 5e-324 and c[-1] == 1.0


@settings(max_examples=300, deadline=None)
@given(st.floats(-1.0, 1.0))
def test_acos_is_libm_acos(c):
    assert _same_angle(float(_acos_many(np.array([c]))[0]), math.acos(c))


def test_acos_at_the_ends():
    c = np.array([-1.0, 1.0, 0.0, -0.0, np.nextafter(1, 0), np.nextafter(-1, 0)])
    ours = _acos_many(c)
    assert ours[0] == math.pi and ours[1] == 0.0
    assert np.abs(ours - np.arccos(c)).max() <= 4.5e-16
