"""What the OMPL comparisons time: the peer's own work, nothing of the bench's, and the
same steps as ours (`bench motion --dubins`, `bench world`, `bench motion --curvature`)."""

import sys
import types

import numpy as np
import pytest
import shapely

from skyroute.bench import curvature as bench_curvature
from skyroute.bench import motion as bench_motion
from skyroute.bench import world as bench_world
from skyroute.motion.dubins import shortest_path
from skyroute.world.world import World

needs_ompl = pytest.mark.skipif(not bench_world.ompl_available(), reason="OMPL is not "
                                "installed (the peer; pip install 'skyroute[bench]')")

L_SHAPE = shapely.Polygon([(0, 0), (100, 0), (100, 40), (40, 40), (40, 100), (0, 100)])


class FakeClock:
    """perf_counter stand-in that advances only when fake work says it worked."""

    def __init__(self):
        self.now = 0.0

    def __call__(self):
        return self.now


def fake_ompl_base(clock: FakeClock, radius_seen: list):
    """An ``ompl.base`` whose DubinsStateSpace charges the fake clock 1 us per state
    setter and 0.5 us per distance(), and answers with skyroute's Dubins length."""

    class State:
        def __init__(self):
            self.pose = [0.0, 0.0, 0.0]

        def _set(self, i, v):
            clock.now += 1e-6
            self.pose[i] = float(v)

        def setX(self, v):  # noqa: N802 (OMPL's names)
            self._set(0, v)

        def setY(self, v):  # noqa: N802
            self._set(1, v)

        def setYaw(self, v):  # noqa: N802
            self._set(2, v)

    class DubinsStateSpace:
        def __init__(self, radius):
            radius_seen.append(radius)
            self.radius = radius

        def allocState(self):  # noqa: N802
            return State()

        def distance(self, a, b):
            clock.now += 0.5e-6
            return shortest_path(tuple(a.pose), tuple(b.pose), self.radius).length

    return types.SimpleNamespace(DubinsStateSpace=DubinsStateSpace)


def test_dubins_peer_time_is_its_distance_calls_alone(monkeypatch):
    clock, radii = FakeClock(), []
    base = fake_ompl_base(clock, radii)
    monkeypatch.setitem(sys.modules, "ompl", types.SimpleNamespace(base=base))
    monkeypatch.setitem(sys.modules, "ompl.base", base)
    monkeypatch.setattr(bench_motion.time, "perf_counter", clock)
    d = bench_motion.dubins_speed(sizes=(300, 1000), threads=(1,), repeats=2, ompl_calls=200)
    assert radii == [1.7]
    for row in d["rows"]:  # 0.5 us of distance() per call; none of the 6 us of setters
        assert row["ompl_us"] == pytest.approx(0.5)
        assert row["skyroute_us"] == 0.0  # lengths() does no fake work
    assert d["max_abs_diff_ompl"] <= 1e-9  # each start still paired with its own goal


@needs_ompl
def test_dubins_bench_agrees_with_ompl():
    d = bench_motion.dubins_speed(sizes=(2000,), threads=(1,), repeats=1, ompl_calls=500)
    assert d["max_abs_diff_ompl"] <= 1e-9
    assert d["rows"][0]["ompl_us"] > 0


def counting_contains(monkeypatch) -> list:
    """Record the geometry of every shapely.contains_xy call."""
    seen, real = [], shapely.contains_xy

    def contains_xy(geom, x, y):
        seen.append(geom)
        return real(geom, x, y)

    monkeypatch.setattr(shapely, "contains_xy", contains_xy)
    return seen


def l_world() -> World:
    box = shapely.box(10, 10, 20, 20)
    return World(np.array([box], dtype=object), np.full(1, -np.inf), np.full(1, np.inf), (),
                 L_SHAPE, "enu", name="L")


class DubinsState:
    def __init__(self, x, y):
        self.x, self.y = x, y

    def getX(self):  # noqa: N802 (OMPL's names)
        return self.x

    def getY(self):  # noqa: N802
        return self.y


@pytest.mark.parametrize("checker, state", [
    (bench_world.ompl_checker, lambda x, y: [x, y]),
    (bench_curvature.dubins_checker, DubinsState),
])
def test_checker_skips_only_a_boundary_that_is_the_bounds(monkeypatch, checker, state):
    rect = bench_curvature.curvature_world(0)
    free = next(tuple(p) for p in np.random.default_rng(0).uniform(1, 99, (100, 2))
                if rect.is_free([p])[0])
    assert bench_world.boundary_is_bounds(rect)
    seen = counting_contains(monkeypatch)
    valid = checker(rect)
    assert valid(state(*free))
    assert len(seen) == 1  # the obstacles' union only: no polygon test of the boundary
    if checker is bench_curvature.dubins_checker:  # Dubins curves leave the bounds
        assert not valid(state(-1.0, 50.0)) and not valid(state(50.0, 100.5))
        assert not valid(state(0.0, 50.0))  # strictly inside, as World.inside

    lw = l_world()
    assert not bench_world.boundary_is_bounds(lw)
    valid = checker(lw)
    assert valid(state(5.0, 95.0)) and valid(state(95.0, 5.0))
    assert not valid(state(70.0, 70.0))  # inside the bounds, outside the L
    assert not valid(state(15.0, 15.0))  # in the obstacle
    assert lw.is_free([[5, 95], [95, 5]]).all() and not lw.is_free([[70, 70]])[0]


def test_no_boundary_means_no_boundary_test():
    world = World(np.array([shapely.box(0, 0, 1, 1), shapely.box(5, 5, 6, 6)], dtype=object),
                  np.full(2, -np.inf), np.full(2, np.inf), (), None, "enu")
    assert not bench_world.boundary_is_bounds(world)
    valid = bench_world.ompl_checker(world)
    assert valid([3.0, 3.0]) and not valid([0.5, 0.5])


def test_ompl_rows_time_the_simplified_path_with_its_simplification():
    run = {"runner": "ompl PRM", "seconds": 0.25, "exact": True, "raw": 12.0,
           "simplified": 10.0, "valid": True, "raw_valid": False, "simplify_seconds": 0.5}
    solve, simplified = bench_world.ompl_rows(run)
    assert solve == {"runner": "ompl PRM", "seconds": 0.25, "exact": True, "raw": 12.0,
                     "valid": False}
    assert simplified == {"runner": "ompl PRM, simplified", "seconds": 0.75,
                          "simplify_seconds": 0.5, "simplified": 10.0, "valid": True}
    unsolved = {"runner": "ompl PRM", "seconds": 1.0, "exact": False, "raw": None,
                "simplified": None, "valid": None, "simplify_seconds": None}
    assert bench_world.ompl_rows(unsolved) == [
        {"runner": "ompl PRM", "seconds": 1.0, "exact": False, "raw": None, "valid": None}]


@needs_ompl
def test_ompl_simplification_is_timed(monkeypatch):
    # The fake clock counts validity checks, OMPL's work that runs our Python: the solve's
    # and simplifySolution()'s intervals must hold every check between them.
    world = bench_world.random_rect_world(0)
    start, goal = bench_world.free_pair(world, np.random.default_rng(0), 60.0)
    clock, real = FakeClock(), bench_world.ompl_checker

    def counting_checker(w):
        valid = real(w)

        def counted(state):
            clock.now += 1
            return valid(state)
        return counted

    monkeypatch.setattr(bench_world, "ompl_checker", counting_checker)
    monkeypatch.setattr(bench_world.time, "perf_counter", clock)
    run = bench_world.run_ompl(world, start, goal, "RRTConnect", 5.0)
    assert run["exact"]
    assert run["seconds"] > 0 and run["simplify_seconds"] > 0
    assert run["seconds"] + run["simplify_seconds"] == clock.now
    assert bench_world.ompl_rows(run)[1]["seconds"] == clock.now


def test_tours_report_how_much_longer_nearest_first_is(monkeypatch):
    """greedy_longer_* is nearest-first's length over the exact tour's, minus 1: a greedy
    tour of 150 against an exact 100 is 50 % longer (it read 33 %, the exact tour's
    saving, as 1 - 100/150)."""
    import skyroute.motion.tour as tour_mod

    def fake_tour(start, pts, radius, *, headings, exact_limit=None):
        length = 100.0 if exact_limit is None else 110.0
        return types.SimpleNamespace(length=length, greedy_bound=150.0, seconds=0.0)

    monkeypatch.setattr(tour_mod, "tour", fake_tour)
    t = bench_curvature.tour_benchmark(2, 0)
    assert t["greedy_longer_mean"] == pytest.approx(0.5)
    assert t["greedy_longer_min"] == t["greedy_longer_max"] == pytest.approx(0.5)
    assert t["local_gap_mean"] == pytest.approx(0.1)
