"""The 2D bounds through the corner table, Hybrid A*'s (:func:`corner_distance.
lower_bound`, which gives up after a few blocked corners) and the step drone's
(:func:`move_search.distance`, which tries corners until one is in sight): their sight
tests read the edge grid and their corner scans compute ``hypot`` only for the few
candidates, and they answer what the plain rule answers, a scan of every corner in order
of value (ties: the lower index) with shapely's proper crossings for sight. Half-integer
coordinates put corners, edge ends and query points on bucket sides and make many values
tie."""

import math

import numpy as np
import shapely
from hypothesis import example, given, settings
from hypothesis import strategies as st

from skyroute.motion import edge_grid, move_search
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


def hypot(x, y) -> float:
    """The C library's hypot, which the compiled kernel calls (numpy's is the same).
    Python's ``math.hypot`` is its own algorithm since 3.8 and differs from it in the last
    bit on about 1 in 200 pairs: the plain scan written with it failed on such pairs."""
    return float(np.hypot(x, y))


def plain_bound(q, t, sees, corners, cdist, edges, tests, sight=shapely_sight):
    """The rule as written: every corner's hypot value, the cheapest first, sight over
    every edge; after ``tests`` blocked corners the next one's value (None: no limit)."""
    d = hypot(q[0] - t[0], q[1] - t[1])
    if sees or len(corners) == 0:
        return d
    if tests is None:
        tests = len(corners)
    vals = [hypot(q[0] - c[0], q[1] - c[1]) + D
            for c, D in zip(corners, cdist, strict=True)]
    order = sorted(range(len(vals)), key=lambda c: (vals[c], c))
    for k, c in enumerate(order[:tests + 1]):
        if not vals[c] < math.inf:
            return d
        if k == tests or sight(q, corners[c], edges):
            return max(d, vals[c])
    return d


def kernel(q, t, sees, corners, cdist, edges, grid, tests):
    """Hybrid A*'s bound giving up after ``tests`` blocked corners, or with ``tests``
    None the step drone's."""
    n = len(corners)
    cols = np.ascontiguousarray(corners.T)
    if tests is None:
        return move_search.distance(*q, sees, *t, cols, cdist, edges, *grid, np.empty(n),
                                    np.empty(n, np.int64))
    return lower_bound(*q, *t, sees, cols, cdist, edges, *grid, np.empty(n),
                       np.empty(n, np.int64), tests)


tests_or_none = st.one_of(st.none(), st.integers(0, 4))


@st.composite
def cases(draw):
    edges = np.array(draw(st.lists(edge, min_size=1, max_size=25)), dtype=float)
    corners = np.array(draw(st.lists(point, min_size=1, max_size=40)), dtype=float)
    cdist = np.array(draw(st.lists(dist, min_size=len(corners), max_size=len(corners))))
    cell = draw(st.sampled_from([None, 0.5, 1.0, 3.7]))
    return edges, corners, cdist, edge_grid.build(edges, cell)


@settings(max_examples=400, deadline=None)
@given(cases(), point, point, st.booleans(), tests_or_none)
def test_the_bound_is_the_plain_scan_of_every_corner(case, q, t, sees, tests):
    edges, corners, cdist, grid = case
    got = kernel(q, t, sees, corners, cdist, edges, grid, tests)
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


def _case(edges, corners, cdist):
    edges = np.array(edges, dtype=float)
    return edges, np.array(corners, dtype=float), np.array(cdist), edge_grid.build(edges)


@settings(max_examples=400, deadline=None)
@given(float_cases(), st.tuples(real, real), st.tuples(real, real), tests_or_none)
# pairs where Python's math.hypot and the C library's differ in the last bit (found by
# hypothesis): the distance to the target, and the value of the candidate returned
@example(case=_case([[500, 500, 501, 500]], [[0, 0]], [0]), q=(1.5387996, -24.5420822),
         t=(43.8791853, 22.4127685), tests=0)
@example(case=_case([[-1, 75, 2, 1]], [[0, 51], [0, -23], [52.2922444, 0], [0, 0]],
                    [0, 0, 0, math.inf]), q=(0.0, 50.1695025), t=(0.0, 0.0), tests=1)
# two corners in sight whose values and approximations are in opposite orders: the
# step drone's heap of approximations takes the second first, and must go on to the first
@example(case=_case([[500, 500, 501, 500]], [[-65.5405188, 18.1601727],
                                             [-8.2453711, 44.6217592]],
                    [0, 22.63276680954487]), q=(0.0, 0.0), t=(1.0, 0.0), tests=None)
def test_the_bound_is_the_plain_scan_on_inexact_coordinates(case, q, t, tests):
    edges, corners, cdist, grid = case
    got = kernel(q, t, False, corners, cdist, edges, grid, tests)
    assert got == plain_bound(q, t, False, corners, cdist, edges, tests, scan_sight)
