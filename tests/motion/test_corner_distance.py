"""Hybrid A*'s 2D bound (:func:`corner_distance.lower_bound`): its sight tests read the
edge grid and its corner scan computes ``hypot`` only for the few candidates, and it
answers what the plain rule answers, a scan of every corner in order of value (ties: the
lower index) with shapely's proper crossings for sight. Half-integer coordinates put
corners, edge ends and query points on bucket sides and make many values tie."""

import math

import numpy as np
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from skyroute.motion import edge_grid
from skyroute.motion.corner_distance import lower_bound
from skyroute.motion.zone_kernels import crosses

coord = st.integers(-12, 12).map(lambda v: v / 2)
point = st.tuples(coord, coord)
edge = st.tuples(coord, coord, coord, coord).filter(lambda e: e[:2] != e[2:])
# corner distances: small whole and half numbers (ties), a few unreachable corners
dist = st.one_of(st.integers(0, 16).map(lambda v: v / 2), st.just(math.inf))


def shapely_sight(q, c, edges):
    """No edge properly crosses segment qc (shapely's ``crosses``)."""
    segs = shapely.linestrings(edges.reshape(-1, 2, 2))
    return tuple(c) == tuple(q) or not shapely.crosses(shapely.LineString([q, c]),
                                                       segs).any()


def scan_sight(q, c, edges):
    """No edge properly crosses qc: the kernel's own predicate on every edge (on floats
    whose orientation tests round, shapely's exact answer may differ from both)."""
    return not any(crosses(*q, *c, *e) for e in edges)


def hypot(x: float, y: float) -> float:
    """C's ``hypot`` (libm's, through numpy), as compiled code calls it; Python's
    ``math.hypot`` is its own algorithm and differs from it in the last bit on some
    inputs (83.0138534, 87.5649817: 120.6603740937265 against 120.66037409372652)."""
    return float(np.hypot(x, y))


def plain_bound(q, t, sees, corners, cdist, edges, tests, sight=shapely_sight):
    """The rule as written: every corner's hypot value, the cheapest first, sight over
    every edge."""
    d = hypot(q[0] - t[0], q[1] - t[1])
    if sees or len(corners) == 0:
        return d
    vals = [hypot(q[0] - c[0], q[1] - c[1]) + D
            for c, D in zip(corners, cdist, strict=True)]
    order = sorted(range(len(vals)), key=lambda c: (vals[c], c))
    for k, c in enumerate(order[:tests + 1]):
        if not vals[c] < math.inf:
            return d
        if k == tests or sight(q, corners[c], edges):
            return max(d, vals[c])
    return d


@st.composite
def cases(draw):
    edges = np.array(draw(st.lists(edge, min_size=1, max_size=25)), dtype=float)
    corners = np.array(draw(st.lists(point, min_size=1, max_size=40)), dtype=float)
    cdist = np.array(draw(st.lists(dist, min_size=len(corners), max_size=len(corners))))
    cell = draw(st.sampled_from([None, 0.5, 1.0, 3.7]))
    return edges, corners, cdist, edge_grid.build(edges, cell)


@settings(max_examples=400, deadline=None)
@given(cases(), point, point, st.booleans(), st.integers(0, 4))
def test_the_bound_is_the_plain_scan_of_every_corner(case, q, t, sees, tests):
    edges, corners, cdist, grid = case
    n = len(corners)
    got = lower_bound(*q, *t, sees, np.ascontiguousarray(corners.T), cdist, edges, *grid,
                      np.empty(n), np.empty(n, np.int64), tests)
    assert got == plain_bound(q, t, sees, corners, cdist, edges, tests)


real = st.floats(-100, 100, allow_nan=False).map(lambda v: round(v, 7))


@st.composite
def float_cases(draw):
    """Coordinates whose squares are not exact: ``sqrt(dx**2 + dy**2)`` and ``hypot``
    differ in the last bits on many corners, and the value returned must be hypot's."""
    corners = np.array(draw(st.lists(st.tuples(real, real), min_size=1, max_size=40)))
    base = draw(st.floats(0, 50))
    cdist = base + np.array(draw(st.lists(st.sampled_from([0.0, 1e-14, 3e-14, math.inf]),
                                          min_size=len(corners), max_size=len(corners))))
    edges = np.array(draw(st.lists(st.tuples(real, real, real, real), min_size=1,
                                   max_size=15)))
    edges = edges[np.any(edges[:, :2] != edges[:, 2:], axis=1)]
    if len(edges) == 0:
        edges = np.array([[500.0, 500.0, 501.0, 500.0]])
    return edges, corners, cdist, edge_grid.build(edges)


@settings(max_examples=400, deadline=None)
@given(float_cases(), st.tuples(real, real), st.tuples(real, real), st.integers(0, 4))
def test_the_bound_is_the_plain_scan_on_inexact_coordinates(case, q, t, tests):
    edges, corners, cdist, grid = case
    n = len(corners)
    got = lower_bound(*q, *t, False, np.ascontiguousarray(corners.T), cdist, edges, *grid,
                      np.empty(n), np.empty(n, np.int64), tests)
    assert got == plain_bound(q, t, False, corners, cdist, edges, tests, scan_sight)
