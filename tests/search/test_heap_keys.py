"""The searches' int64 heap keys past f = 2**23 (search/heap.py): each search takes its
unit of f from a bound on every f it can meet, so the largest key still fits and keys
stay in f order; before, the shift wrapped past 2**23 cells of path (a serpentine
on a large grid) and a search popped keys out of order, returning a longer path as
"found"."""

import math

import numpy as np
import pytest
from scipy.sparse.csgraph import dijkstra

import skyroute
from skyroute.bench.random_maps import octile_graph
from skyroute.errors import OptionError
from skyroute.motion.turn_lattice import plan_turns
from skyroute.search import heap
from skyroute.world.grid import MAX_CELLS
from tests.search.checks import assert_grid_path_legal

OLD_LIMIT = 2.0 ** 23  # where today's unit (2**-20) runs out
# the f bound of the largest grid a search takes, with pivots (SearchSpace.f_bound)
LARGEST = 2 * (MAX_CELLS + 2 * 8192) * math.sqrt(2.0)


def _old_key(f: float, g: float) -> int:
    """The layout before: f in units of 2**-20 whatever f, in Python's unbounded ints."""
    return (int(f * 2.0 ** 20 + 0.5) << 20) | ((1 << 20) - 1 - min(int(g * 4.0), (1 << 20) - 1))


def test_today_layout_stands_below_the_old_limit():
    for f in (0.0, 1.0, 1e6, OLD_LIMIT - 1.0):
        assert heap.f_scale(f) == heap.F_SCALE == 2.0 ** 20
        for g in (0.0, f / 3, f):
            assert heap.key(f, g, heap.F_SCALE) == _old_key(f, g)
    assert heap.f_scale(OLD_LIMIT) == 2.0 ** 19  # the old layout's key would need bit 63
    assert heap.f_scale(LARGEST) >= 2.0 ** 15
    for bad in (2.0 ** 43, math.inf, math.nan):
        assert heap.f_scale(bad) == 0.0


@pytest.mark.parametrize("f_max", [OLD_LIMIT - 1.0, OLD_LIMIT, 3 * OLD_LIMIT, LARGEST,
                                   2.0 ** 42])
def test_keys_are_ordered_by_f_up_to_the_bound(f_max):
    fs = heap.f_scale(f_max)
    rng = np.random.default_rng(1)
    f = np.sort(np.r_[0.0, rng.uniform(0.0, f_max, 3000), f_max,
                      [x for x in (OLD_LIMIT - 0.5, OLD_LIMIT, OLD_LIMIT + 0.5) if x <= f_max]])
    g = f * rng.uniform(0.0, 1.0, f.size)
    keys = np.array([heap.key(a, b, fs) for a, b in zip(f, g, strict=True)])
    assert keys.min() >= 0
    top = np.array([int(a * fs + 0.5) for a in f])
    assert np.array_equal(keys >> 20, top)  # f, rounded to 1 / fs, above the tie
    assert np.all(np.abs(top / fs - f) <= 0.5 / fs)
    assert np.all(np.diff(keys)[np.diff(top) > 0] > 0)
    # equal f: the larger g first
    assert heap.key(f_max, 0.25, fs) < heap.key(f_max, 0.0, fs)


def _maze(seed: int = 1) -> tuple[np.ndarray, tuple, tuple]:
    """A 48x48 grid, 25% blocked: many routes of some 80 cells between two corners."""
    blocked = np.random.default_rng(seed).random((48, 48)) < 0.25
    blocked[:3, :3] = blocked[-3:, -3:] = False
    return blocked, (0, 0), (47, 47)


def _optimum(blocked, s, t) -> float:
    w = blocked.shape[1]
    return dijkstra(octile_graph(blocked), directed=False,
                    indices=[s[1] * w + s[0]])[0, t[1] * w + t[0]]


# f in units of 2**-40 must stay below 2**3 = 8 cells, as in units of 2**-20 it had to
# stay below 2**23: a small grid then meets what a serpentine of 16 million cells met
LOW = 2.0 ** 40


@pytest.mark.parametrize("algorithm", ["dijkstra", "astar", "jps"])
def test_searches_stay_exact_past_the_key_limit(monkeypatch, algorithm):
    blocked, s, t = _maze()
    optimum = _optimum(blocked, s, t)
    assert optimum > 2.0 ** 43 / LOW
    monkeypatch.setattr(heap, "F_SCALE", LOW)
    r = skyroute.plan(skyroute.Grid(blocked), s, t, algorithm=algorithm)
    assert r.found and abs(r.cost - optimum) < 1e-9, (r.cost, optimum)
    assert abs(assert_grid_path_legal(blocked, r.path) - r.cost) < 1e-9
    # the old rule, LOW whatever the bound, goes wrong on this grid: the test sees it
    monkeypatch.setattr(heap, "f_scale", lambda f_max: LOW)
    wrong = skyroute.plan(skyroute.Grid(blocked), s, t, algorithm=algorithm)
    assert not (wrong.found and abs(wrong.cost - optimum) < 1e-9)


@pytest.mark.parametrize("algorithm", ["theta", "lazy_theta"])
def test_any_angle_costs_stand_past_the_key_limit(monkeypatch, algorithm):
    blocked, s, t = _maze()
    before = skyroute.plan(skyroute.Grid(blocked), s, t, algorithm=algorithm)
    monkeypatch.setattr(heap, "F_SCALE", LOW)
    r = skyroute.plan(skyroute.Grid(blocked), s, t, algorithm=algorithm)
    assert r.found and abs(r.cost - before.cost) < 1e-9, (r.cost, before.cost)
    monkeypatch.setattr(heap, "f_scale", lambda f_max: LOW)  # the old rule: longer here
    assert skyroute.plan(skyroute.Grid(blocked), s, t, algorithm=algorithm).cost > \
        before.cost + 1e-9


def test_weighted_astar_keeps_its_bound_past_the_key_limit(monkeypatch):
    blocked, s, t = _maze()
    optimum = _optimum(blocked, s, t)
    monkeypatch.setattr(heap, "F_SCALE", LOW)
    for weight in (1.5, 3.0, 1e6):
        r = skyroute.plan(skyroute.Grid(blocked), s, t, algorithm="astar", weight=weight)
        assert r.found and optimum - 1e-9 <= r.cost <= weight * optimum + 1e-9


def test_a_weight_whose_keys_cannot_fit_is_refused_naming_the_largest():
    # weight=1e13 on a 48x48 grid: f up to 1e15, past what an int64 key holds at 2**-20
    # cells (before: the key wrapped, silently)
    blocked, s, t = _maze()
    grid = skyroute.Grid(blocked)
    with pytest.raises(OptionError) as err:
        skyroute.plan(grid, s, t, algorithm="astar", weight=1e13)
    msg = str(err.value)
    assert err.value.param == "weight" and msg.startswith("weight=1e+13 is too large for this")
    most = int(msg.rsplit(" ", 1)[1].replace(",", ""))
    assert 1e9 < most < 1e13
    assert skyroute.plan(grid, s, t, algorithm="astar", weight=float(most)).found
    with pytest.raises(OptionError):
        skyroute.plan(grid, s, t, algorithm="theta", weight=1e13)


def test_a_slow_turn_lattice_finds_the_same_route_scaled():
    # the lattice's f is seconds: at 1e-6 cells/s a 60-cell route takes some 6e7 s,
    # past 2**23; the fastest route's time scales exactly with 1 / speed
    # (before: keys wrapped and the search returned a slower route)
    blocked, s, t = _maze()
    grid = skyroute.Grid(blocked)
    fast = plan_turns(grid, s, t, speed=1.0, turn_rate=math.pi / 2)
    slow = plan_turns(grid, s, t, speed=1e-6, turn_rate=math.pi / 2 * 1e-6)
    assert fast.found and slow.found
    assert slow.time == pytest.approx(fast.time * 1e6, rel=1e-9)
    with pytest.raises(OptionError) as err:
        plan_turns(grid, s, t, speed=1e-12)
    assert err.value.param == ("speed", "turn_rate") and "are too small for this" in str(err.value)
