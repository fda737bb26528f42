"""The mission optimiser against brute force over every subset and order of small days."""

from __future__ import annotations

import itertools

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from skyroute.delivery import mission


def tour_cost(tour, cost, back, cust):
    at, total = 0, 0.0
    for i in tour:
        total += cost[at, i]
        at = cust[i]
    return total + (back[at] if tour else 0)


def brute_force(value, cost, back, cust, budget):
    best = 0.0
    n = len(value)
    for k in range(1, n + 1):
        for seq in itertools.permutations(range(n), k):
            if tour_cost(seq, cost, back, cust) <= budget:
                best = max(best, value[list(seq)].sum())
    return best


@st.composite
def days(draw):
    n = draw(st.integers(1, 6))
    m = draw(st.integers(1, 3))  # customer places; origin 0 is home
    cost = np.array(draw(st.lists(st.integers(1, 60), min_size=(m + 1) * n,
                                  max_size=(m + 1) * n)), float).reshape(m + 1, n)
    back = np.array([0.0, *draw(st.lists(st.integers(1, 40), min_size=m, max_size=m))])
    cust = np.array(draw(st.lists(st.integers(1, m), min_size=n, max_size=n)))
    value = np.array(draw(st.lists(st.integers(100, 2000), min_size=n, max_size=n)), float)
    return value, cost, back, cust, draw(st.integers(10, 250))


@settings(max_examples=60, deadline=None)
@given(days())
def test_milp_is_optimal_and_its_circuit_flies_its_arcs(day):
    value, cost, back, cust, budget = day
    chosen, proven = mission.solve(value, cost, back, cust, budget)
    assert proven
    tour = mission.circuit(chosen, cust)
    assert sorted(tour) == sorted(i for i, _ in chosen)
    assert tour_cost(tour, cost, back, cust) == \
        sum(cost[p, i] for i, p in chosen) + (back[cust[tour[-1]]] if tour else 0)
    assert tour_cost(tour, cost, back, cust) <= budget
    assert value[tour].sum() == brute_force(value, cost, back, cust, budget)
    g = mission.greedy(value, cost, back, cust, budget)
    assert tour_cost(g, cost, back, cust) <= budget
    assert value[g].sum() <= value[tour].sum()


def test_order_costs_pick_the_better_shop_order():
    legs = np.array([[0, 10, 2, 5],   # home, shop A, shop B, customer
                     [10, 0, 9, 1],
                     [2, 9, 0, 4],
                     [5, 1, 20, 0]])
    cost, best = mission.order_costs(legs, [0, 3], [([1, 2], 3)])
    # from home: B (2), A (9), customer (1) beats A (10), B (9), customer (4)
    assert best[0][0] == (2, 1) and cost[0, 0] == 2 + 9 + 1 + 3
    # from the customer: A (1), B (9), back (4) beats B (20), A (9), back (1)
    assert best[1][0] == (1, 2) and cost[1, 0] == 1 + 9 + 4 + 3


def test_a_timed_out_solve_is_never_worse_than_the_greedy_tour(monkeypatch):
    """HiGHS out of time may hand back its trivial incumbent, no order at all (a CI under
    load flew an empty day with 60 moves of battery where one order fits): then the
    greedy tour is flown, not nothing, and the answer is not called proven."""
    import scipy.optimize

    value = np.array([500.0, 300.0])
    cost = np.array([[20.0, 40.0], [30.0, 30.0]])
    back = np.array([0.0, 11.0])
    cust = np.array([1, 1])
    real = scipy.optimize.milp

    def out_of_time(c, **kw):
        res = real(c, **kw)
        res.x, res.status = np.zeros_like(res.x), 1  # time limit reached, incumbent 0
        return res

    monkeypatch.setattr(scipy.optimize, "milp", out_of_time)
    chosen, proven = mission.solve(value, cost, back, cust, 60)
    assert not proven
    assert chosen == [(0, 0)] == [(i, 0) for i in mission.greedy(value, cost, back, cust, 60)]
    assert tour_cost([0], cost, back, cust) <= 60
