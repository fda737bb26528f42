"""sin, cos, atan2 and acos compiled without libm calls, so that a loop of them vectorises.

numba calls glibc one value at a time; a loop that calls it cannot be turned into SIMD
code. These are the fdlibm polynomials (sin/cos kernels, atan with its table of
atan(0.5), atan(1) and their low parts) with every branch written as a select, so LLVM
can run 4 queries per AVX2 instruction. Accurate to a few ulp (absolute error within
4.5e-16, 2 ulp of pi; tests against :mod:`math`); for finite arguments only.
"""

from __future__ import annotations

import math

from numba import njit

# pi / 2 in three parts (fdlibm's pio2_1, pio2_2, pio2_3: 33 bits each), so that
# x - n pi/2 is exact for the small n met here
_PIO2_1 = 1.57079632673412561417e+00
_PIO2_2 = 6.07710050630396597660e-11
_PIO2_3 = 2.02226624871116645580e-21
_INV_PIO2 = 6.36619772367581382433e-01

_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, \
    -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, \
    1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, \
    2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, \
    -1.13596475577881948265e-11

_AT = (3.33333333333329318027e-01, -1.99999999998764832476e-01,
       1.42857142725034663711e-01, -1.11111104054623557880e-01,
       9.09088713343650656196e-02, -7.69187620504482999495e-02,
       6.66107313738753120669e-02, -5.83357013379057348645e-02,
       4.97687799461593236017e-02, -3.65315727442169155270e-02,
       1.62858201153657823623e-02)
_ATANHI_0, _ATANLO_0 = 4.63647609000806093515e-01, 2.26987774529616870924e-17  # atan(1/2)
_ATANHI_1, _ATANLO_1 = 7.85398163397448278999e-01, 3.06161699786838301793e-17  # atan(1)
_PI = 3.14159265358979311600e+00
_PI_2 = 1.57079632679489655800e+00


@njit(cache=True, inline="always", error_model="numpy")
def sincos(x):
    """(sin x, cos x) for |x| up to a few thousand radians (Cody-Waite reduction by
    pi / 2; the callers pass angles in [0, 2 pi))."""
    n = math.floor(x * _INV_PIO2 + 0.5)
    r = ((x - n * _PIO2_1) - n * _PIO2_2) - n * _PIO2_3
    z = r * r
    v = z * r
    s = r + v * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))))
    cr = z * z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * _C6)))))
    hz = 0.5 * z
    w = 1.0 - hz
    c = w + (((1.0 - w) - hz) + cr)
    q = n - 4.0 * math.floor(n * 0.25)  # quadrant 0..3
    odd = (q == 1.0) | (q == 3.0)
    sn = c if odd else s
    cs = s if odd else c
    sn = -sn if q >= 2.0 else sn
    cs = -cs if (q == 1.0) | (q == 2.0) else cs
    return sn, cs


@njit(cache=True, inline="always", error_model="numpy")
def atan2(y, x):
    """The angle of (x, y) in [-pi, pi], as :func:`math.atan2` (signed zeros included).

    The smaller of |x|, |y| over the larger is reduced as fdlibm's atan does on [0, 1]
    (to within 7/16 of 0, 1/2 or 1), in one division, then the quadrant is restored."""
    ax, ay = abs(x), abs(y)
    hi = max(ax, ay)
    lo = min(ax, ay)
    # keep 2 hi + lo finite and the quotient's inputs normal: scale by powers of two
    f = 2.0 ** -600 if hi > 2.0 ** 1000 else (2.0 ** 600 if hi < 2.0 ** -900 else 1.0)
    hi *= f
    lo *= f
    k0 = (lo >= 0.4375 * hi) & (hi > 0.0)  # t = lo / hi >= 7/16 (and not 0 / 0)
    k1 = (lo >= 0.6875 * hi) & (hi > 0.0)  # t >= 11/16
    num = (lo - hi) if k1 else ((2.0 * lo - hi) if k0 else lo)
    den = (lo + hi) if k1 else ((2.0 * hi + lo) if k0 else hi)
    t = num / (den if hi > 0.0 else 1.0)
    ah = _ATANHI_1 if k1 else (_ATANHI_0 if k0 else 0.0)
    al = _ATANLO_1 if k1 else (_ATANLO_0 if k0 else 0.0)
    z = t * t
    w = z * z
    s1 = z * (_AT[0] + w * (_AT[2] + w * (_AT[4] + w * (_AT[6] + w * (_AT[8] + w * _AT[10])))))
    s2 = w * (_AT[1] + w * (_AT[3] + w * (_AT[5] + w * (_AT[7] + w * _AT[9]))))
    at = ah - ((t * (s1 + s2) - al) - t)  # atan(lo / hi) in [0, pi / 4]
    at = (_PI_2 - at) if ay > ax else at
    at = (_PI - at) if math.copysign(1.0, x) < 0.0 else at
    return math.copysign(at, y)


@njit(cache=True, inline="always", error_model="numpy")
def acos(c):
    """arccos of c in [-1, 1], as the angle of (c, sqrt((1 - c)(1 + c)))."""
    return atan2(math.sqrt((1.0 - c) * (1.0 + c)), c)
