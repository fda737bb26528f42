"""Dispatch rules and the runway/gate timetables, as units: the seed's preferences and its
one-drone-per-gate rule, the optimal assignment against a brute-force minimum over all
assignments, no stranding as packages age, and every operation of a Timetable."""

from __future__ import annotations

import copy
import itertools
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyroute.fleet import dispatch
from skyroute.fleet.timetable import Timetable

# three airports: 2 is near 0, 1 is far from both
TRAVEL = np.array([[0.0, 500.0, 50.0],
                   [500.0, 0.0, 480.0],
                   [50.0, 480.0, 0.0]])


def seed(packages, drones, heading=None):
    return dispatch.seed(packages=packages, drones=drones, travel=TRAVEL,
                         heading={} if heading is None else heading)


# ------------------------------------------------------------------ the seed rule

def test_seed_prefers_the_gate_then_the_airport_then_the_nearest():
    pkg = [(10, 0, 1, 1, 0)]  # at airport 0 gate 1, to airport 1 gate 0
    at_gate, at_airport, near, far = (3, 0, 1), (2, 0, 0), (1, 2, 0), (0, 1, 1)
    assert seed(pkg, [far, near, at_airport, at_gate]) == [(3, 10)]
    assert seed(pkg, [far, near, at_airport]) == [(2, 10)]
    assert seed(pkg, [far, near]) == [(1, 10)]  # 50 s away, not 500
    assert seed(pkg, [far]) == [(0, 10)]


def test_seed_breaks_ties_by_the_lowest_drone_id():
    pkg = [(10, 0, 1, 1, 0)]
    assert seed(pkg, [(7, 0, 1), (4, 0, 1)]) == [(4, 10)]
    assert seed(pkg, [(7, 0, 0), (4, 0, 0)]) == [(4, 10)]
    assert seed(pkg, [(7, 2, 0), (5, 2, 1)]) == [(5, 10)]


def test_seed_serves_packages_first_come_first_served():
    # both want airport 0; the older one gets the drone at its gate's airport
    pkgs = [(1, 0, 0, 1, 0), (2, 0, 1, 2, 1)]
    assert seed(pkgs, [(5, 0, 1)]) == [(5, 1)]
    assert seed(pkgs, [(5, 0, 1), (6, 1, 0)]) == [(5, 1), (6, 2)]


def test_seed_sends_one_drone_to_a_gate_at_a_time():
    drones = [(1, 2, 0), (2, 2, 1), (3, 1, 0)]
    # two packages for one destination gate: the second waits though drones are free
    same_dest = [(1, 0, 0, 1, 1), (2, 0, 1, 1, 1)]
    assert seed(same_dest, drones) == [(1, 1)]
    # a gate a drone is already heading to is nobody else's destination
    assert seed([(1, 0, 0, 1, 1)], drones, heading={(1, 1): 9}) == []
    # ... nor anybody's pickup from elsewhere, but a drone already at its airport may go
    assert seed([(1, 1, 1, 0, 0)], [(1, 2, 0)], heading={(1, 1): 9}) == []
    assert seed([(1, 1, 1, 0, 0)], [(1, 2, 0), (3, 1, 0)], heading={(1, 1): 9}) == [(3, 1)]
    # two packages at one gate with no drone there: one drone flies in, the other waits
    assert seed([(1, 1, 1, 0, 0), (2, 1, 1, 2, 0)], [(1, 2, 0), (2, 2, 1)]) == [(1, 1)]


def test_seed_does_not_touch_its_inputs():
    pkgs = [(1, 0, 0, 1, 1), (2, 0, 1, 1, 1), (3, 1, 1, 2, 0)]
    drones = [(1, 2, 0), (2, 2, 1)]
    heading = {(2, 1): 5}
    before = copy.deepcopy((pkgs, drones, heading))
    seed(pkgs, drones, heading)
    assert (pkgs, drones, heading) == before


# ------------------------------------------------------------------ the optimal rule

def test_optimal_never_strands_an_old_far_package():
    # one drone at airport 0; a package waits at far airport 1 (500 s away) and every
    # 100 s a fresh package spawns beside the drone. Cost = pickup time - w * age: the
    # near ones win while the far one is young, and it wins once w * age reaches 500 s
    far = (0, 1, 0.0)
    due = 500.0 / dispatch.AGE_WEIGHT
    taken = []
    for k in range(1, int(due / 100) + 5):
        now = 100.0 * k
        pairs = dispatch.optimal(now=now, packages=[far, (k, 0, now)],
                                 drones=[(7, 0, now)], travel=TRAVEL)
        assert len(pairs) == 1
        taken.append((now, pairs[0][1]))
        if pairs[0][1] == 0:
            break
    assert taken[-1][1] == 0, "the far package was stranded"
    assert due <= taken[-1][0] <= due + 100.0
    assert all(p != 0 for _, p in taken[:-1])


def test_optimal_takes_the_oldest_of_packages_alike():
    pkgs = [(1, 1, 300.0), (2, 1, 100.0), (3, 1, 200.0)]
    assert dispatch.optimal(now=400.0, packages=pkgs, drones=[(7, 0, 400.0)],
                            travel=TRAVEL) == [(7, 2)]
    assert dispatch.optimal(now=400.0, packages=pkgs, drones=[(7, 0, 400.0), (8, 2, 0.0)],
                            travel=TRAVEL) == [(7, 2), (8, 3)]


def brute_force(now, packages, drones, travel, age_weight=dispatch.AGE_WEIGHT):
    """Every complete assignment (each drone one package or each package one drone,
    whichever are fewer) with its cost; the reference for ``dispatch.optimal``."""
    def cost(i, j):
        _, a, r = drones[i]
        _, b, t = packages[j]
        return max(r - now, 0.0) + travel[a, b] - age_weight * (now - t)

    n, m = len(drones), len(packages)
    if n <= m:
        matchings = [list(enumerate(perm)) for perm in itertools.permutations(range(m), n)]
    else:
        matchings = [[(i, j) for j, i in enumerate(perm)]
                     for perm in itertools.permutations(range(n), m)]
    return [(sum(cost(i, j) for i, j in mt), mt) for mt in matchings]


@settings(max_examples=150, deadline=None)
@given(data=st.data(), n=st.integers(1, 4), m=st.integers(1, 4), airports=st.integers(1, 3))
def test_optimal_matches_a_brute_force_minimum(data, n, m, airports):
    seconds = st.floats(0.0, 1000.0, allow_nan=False)
    travel = np.array([[0.0 if i == j else data.draw(seconds) for j in range(airports)]
                       for i in range(airports)])
    now = 1000.0
    packages = [(10 + j, data.draw(st.integers(0, airports - 1)), data.draw(seconds))
                for j in range(m)]
    drones = [(i, data.draw(st.integers(0, airports - 1)),
               data.draw(st.sampled_from([now, now - 5.0, now + 30.0, now + 400.0])))
              for i in range(n)]
    pairs = dispatch.optimal(now=now, packages=packages, drones=drones, travel=travel)
    # only drones ready now are sent, in drone order, each at most once
    assert pairs == sorted(pairs)
    assert len({d for d, _ in pairs}) == len(pairs) == len({p for _, p in pairs})
    ready = {i for i, (_, _, r) in enumerate(drones) if r <= now}
    assert {d for d, _ in pairs} <= {drones[i][0] for i in ready}
    # the pairs sent are those of some minimum-cost assignment
    options = brute_force(now, packages, drones, travel)
    best = min(c for c, _ in options)
    sent = {d: p for d, p in pairs}

    def agrees(mt):
        got = {drones[i][0]: packages[j][0] for i, j in mt if i in ready}
        return got == sent

    consistent = [c for c, mt in options if agrees(mt)]
    assert consistent and min(consistent) == pytest.approx(best, abs=1e-6)


def test_optimal_sends_only_ready_drones_and_handles_nothing_to_do():
    travel = np.array([[0.0, 100.0], [100.0, 0.0]])
    assert dispatch.optimal(now=0.0, packages=[], drones=[(1, 0, 0.0)], travel=travel) == []
    assert dispatch.optimal(now=0.0, packages=[(1, 0, 0.0)], drones=[], travel=travel) == []
    # the soon-ready drone 2 at the package's airport is best: nothing is sent now
    assert dispatch.optimal(now=0.0, packages=[(5, 1, 0.0)],
                            drones=[(1, 0, 0.0), (2, 1, 10.0)], travel=travel) == []
    assert dispatch.optimal(now=0.0, packages=[(5, 1, 0.0)],
                            drones=[(1, 0, 0.0), (2, 1, 500.0)], travel=travel) == [(1, 5)]


LAZY = """
import sys
import numpy as np
import skyroute.fleet.simulate, skyroute.jobs.fleet
from skyroute.fleet import dispatch
print("scipy.optimize" in sys.modules)
print(dispatch.optimal(now=0.0, packages=[(5, 1, 0.0)], drones=[(1, 0, 0.0)],
                       travel=np.array([[0.0, 100.0], [100.0, 0.0]])))
"""


def test_the_simulation_and_the_jobs_import_the_optimal_rules_solver_when_it_runs():
    """scipy.optimize (about 0.7 s of CPU to import) is not loaded by a process that
    runs the seed rule (the default) or only names the schedulers."""
    done = subprocess.run([sys.executable, "-c", LAZY], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split("\n")[:2] == ["False", "[(1, 5)]"]


# ------------------------------------------------------------------ timetables

def test_timetable_free_and_book_touching_ends_do_not_overlap():
    tt = Timetable("runway A")
    assert tt.free(0.0, 100.0) and len(tt) == 0
    tt.book(10.0, 20.0, owner=1)
    assert tt.free(0.0, 10.0) and tt.free(20.0, 30.0)
    assert not tt.free(5.0, 11.0) and not tt.free(19.0, 25.0) and not tt.free(12.0, 13.0)
    assert not tt.free(0.0, 100.0)  # covers it
    assert not tt.free(15.0, 15.0)  # an instant inside
    assert tt.free(15.0, 30.0, owner=1) and not tt.free(15.0, 30.0, owner=2)
    tt.book(20.0, 30.0, owner=2)  # touching: fine
    with pytest.raises(ValueError, match=r"runway A: .* overlaps another's booking"):
        tt.book(25.0, 35.0, owner=1)
    with pytest.raises(ValueError, match="ends before it starts"):
        tt.book(50.0, 40.0, owner=1)
    assert tt.intervals() == [(10.0, 20.0, 1), (20.0, 30.0, 2)]


def test_timetable_merges_an_owners_overlapping_bookings():
    tt = Timetable("gate A 0")
    tt.book(0.0, 5.0, owner=1)
    tt.book(10.0, 15.0, owner=1)
    tt.book(40.0, 50.0, owner=2)
    tt.book(3.0, 12.0, owner=1)  # bridges the two
    assert tt.intervals() == [(0.0, 15.0, 1), (40.0, 50.0, 2)]
    tt.book(15.0, 18.0, owner=1)  # touching: kept apart, still in order
    tt.book(20.0, 25.0, owner=3)
    assert tt.intervals() == [(0.0, 15.0, 1), (15.0, 18.0, 1), (20.0, 25.0, 3),
                              (40.0, 50.0, 2)]


def test_timetable_holder_and_forget():
    tt = Timetable("runway B")
    tt.book(10.0, 20.0, owner=1)
    tt.book(30.0, 40.0, owner=2)
    assert [tt.holder(t) for t in (5.0, 10.0, 19.9, 20.0, 30.0, 40.0)] == [
        None, 1, 1, None, 2, None]
    tt.forget(19.0)  # the first has not ended yet
    assert len(tt) == 2
    tt.forget(20.0)  # ended at 20: gone
    assert tt.intervals() == [(30.0, 40.0, 2)] and tt.holder(15.0) is None
    tt.forget(100.0)
    assert len(tt) == 0 and tt.free(0.0, 100.0)


def test_timetable_keeps_an_instant_before_an_interval_of_the_same_start():
    # was: [0, 0] went after [0, 1], the ends fell out of order and a later free() missed
    # a booking (here owner 0's [6, 8] when owner 1 asked for [7, 7])
    tt = Timetable("gate")
    tt.book(0.0, 1.0, owner=0)
    tt.book(0.0, 0.0, owner=1)
    assert tt.intervals() == [(0.0, 0.0, 1), (0.0, 1.0, 0)]
    assert tt.free(0.0, 1.0, owner=0)
    tt.book(6.0, 8.0, owner=0)
    tt.book(6.0, 6.0, owner=0)
    assert not tt.free(7.0, 7.0, owner=1)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 40), st.integers(0, 10), st.integers(0, 2)),
                max_size=25), st.integers(0, 50))
def test_timetable_agrees_with_a_plain_list(requests, cut):
    # the reference: a list of (start, end, owner), an owner's overlapping bookings
    # merged, overlap meaning a < e and s < b (touching ends, instants at an end: not)
    tt = Timetable("r")
    plain: list[tuple[float, float, int]] = []

    def clash(a, b, owner):
        return any(o != owner and s < b and a < e for s, e, o in plain)

    for start, length, owner in requests:
        a, b = float(start), float(start + length)
        assert tt.free(a, b, owner=owner) == (not clash(a, b, owner))
        if not clash(a, b, owner):
            tt.book(a, b, owner=owner)
            mine = [p for p in plain if p[2] == owner and p[0] < b and a < p[1]]
            plain = [p for p in plain if p not in mine]
            plain.append((min([a] + [p[0] for p in mine]), max([b] + [p[1] for p in mine]),
                          owner))
    got = tt.intervals()
    assert sorted(got) == sorted(plain)
    assert got == sorted(got, key=lambda x: x[:2])
    for t in np.arange(0.0, 51.0, 0.5):
        inside = {o for s, e, o in plain if s <= t < e}
        assert len(inside) <= 1
        assert tt.holder(t) == (inside.pop() if inside else None)
    tt.forget(float(cut))
    plain = [p for p in plain if p[1] > cut]
    assert sorted(tt.intervals()) == sorted(plain)
    for a, d, o in itertools.product(range(0, 52, 3), (0, 1, 4), range(3)):
        assert tt.free(a, a + d, owner=o) == (not clash(a, a + d, o))
