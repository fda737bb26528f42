"""Which orders to fly, in what order, and each order's shop order: the most money within
a budget of moves, over a table of leg costs.

The drone carries one order at a time, so a day is a tour home -> order -> order ... ->
home where an order, entered from the place the drone last stopped at (home or a
customer), costs its legs and hovers to its shops and customer, and leaves the drone at
its customer. The cost of an order depends only on where it is entered from, so the tour
is an Eulerian circuit on a handful of place nodes, and choosing it is a small integer
program solved exactly (HiGHS through scipy):

- x[i, p] = 1 when order i is flown entered from place p; z[u] = 1 when the drone goes
  home from customer u; each order at most once;
- flow balance at every place; at most one departure from home;
- the moves of every chosen arc within the budget;
- connected to home: a cut for each group of customers the solution visits without a
  way in from outside, added as found; when three rounds of cuts have not closed the
  tour (small budgets tempt it into many little loops), a single-commodity flow from
  home joins in and settles it in one more solve. If time runs out first, the greedy
  tour is returned (and the result is marked not proven).

Any Euler circuit of the chosen arcs flies the same moves. ``greedy`` (the course's
usual best-value-per-move insertion) is kept for comparison in the benchmarks.
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass

import numpy as np

HOVER_MOVES = 1  # a hover costs one move of the battery
CUT_ROUNDS = 3  # rounds of connectivity cuts before the flow formulation joins in


@dataclass(frozen=True)
class Plan:
    """Orders (indices) in flying order, each with its shops in pick-up order."""

    orders: tuple[int, ...]
    shops: tuple[tuple[int, ...], ...]
    moves: int  # by the leg table
    value: int
    optimal: bool


def order_costs(legs: np.ndarray, origins: list[int], stops: list[tuple[list[int], int]]
                ) -> tuple[np.ndarray, np.ndarray]:
    """(len(origins), n) moves to fly order i entered from origins[p] (legs, hovers), and
    (len(origins), n, k) the best shop order's place indices. ``stops[i]`` = (shop
    places, customer place); infinite where a leg has no flight."""
    n = len(stops)
    cost = np.full((len(origins), n), np.inf)
    best = [[None] * n for _ in origins]
    for i, (shops, cust) in enumerate(stops):
        for p, o in enumerate(origins):
            for perm in itertools.permutations(shops):
                seq = [o, *perm, cust]
                legs_ = [legs[a, b] for a, b in itertools.pairwise(seq)]
                if min(legs_) < 0:
                    continue
                c = sum(legs_) + HOVER_MOVES * (len(perm) + 1)
                if c < cost[p, i]:
                    cost[p, i], best[p][i] = c, perm
    return cost, best


def solve(value: np.ndarray, cost: np.ndarray, back: np.ndarray, cust: np.ndarray,
          budget: int, *, time_limit: float = 2.0) -> tuple[list[tuple[int, int]], bool]:
    """Chosen arcs (order, origin index) of the best tour, origin 0 = home, and whether
    HiGHS proved it optimal. ``cost`` (P, n) from :func:`order_costs`, ``back`` (P,) moves
    from each origin home, ``cust[i]`` the origin index order i leaves the drone at."""
    from scipy.optimize import Bounds, LinearConstraint, milp
    from scipy.sparse import lil_matrix

    n_org, n = cost.shape
    arcs = [(i, p) for i in range(n) for p in range(n_org) if np.isfinite(cost[p, i])]
    rets = [u for u in range(1, n_org) if np.isfinite(back[u])]
    na = len(arcs)
    nv = 2 * na + len(rets)  # x per order arc, z per way home, flow per order arc
    if not arcs or not rets:
        return [], True
    eps = 1.0 / (4 * (budget + 1))  # among equal money, fewer moves
    c = np.array([-value[i] + eps * cost[p, i] for i, p in arcs] +
                 [eps * back[u] for u in rets] + [0.0] * na, dtype=float)
    rows = []  # (coefficients dict, lo, hi)
    for i in range(n):  # each order at most once
        rows.append(({k: 1 for k, (j, _) in enumerate(arcs) if j == i}, 0, 1))
    for u in range(n_org):  # balance: in - out = 0
        co: dict[int, float] = {}
        for k, (i, p) in enumerate(arcs):
            if cust[i] == u:
                co[k] = co.get(k, 0) + 1
            if p == u:
                co[k] = co.get(k, 0) - 1
        for r, v in enumerate(rets):
            k = len(arcs) + r
            if u == 0:
                co[k] = co.get(k, 0) + 1
            if v == u:
                co[k] = co.get(k, 0) - 1
        rows.append((co, 0, 0))
    rows.append(({len(arcs) + r: 1 for r in range(len(rets))}, 0, 1))  # home once
    rows.append(({k: cost[p, i] for k, (i, p) in enumerate(arcs)} |
                 {len(arcs) + r: back[u] for r, u in enumerate(rets)}, 0, budget))
    proven, t0, rounds = True, time.perf_counter(), 0
    flow = na + len(rets)  # index of the first flow variable
    while time.perf_counter() - t0 < 10 * time_limit:
        rounds += 1
        if rounds == CUT_ROUNDS + 1:  # the cuts are slow to close the gaps: add the flow
            rows += _flow_rows(arcs, cust, n, n_org, flow)
        a = lil_matrix((len(rows), nv))
        lo, hi = np.empty(len(rows)), np.empty(len(rows))
        for r, (co, l_, h_) in enumerate(rows):
            for k, v in co.items():
                a[r, k] = v
            lo[r], hi[r] = l_, h_
        res = milp(c, constraints=LinearConstraint(a.tocsr(), lo, hi),
                   integrality=np.r_[np.ones(na + len(rets)), np.zeros(na)],
                   bounds=Bounds(0, np.r_[np.ones(na + len(rets)), np.full(na, n)]),
                   options={"time_limit": time_limit})
        if res.x is None:  # no solution within the time limit
            break
        proven = proven and res.status == 0
        x = np.round(res.x).astype(int)
        chosen = [arcs[k] for k in range(len(arcs)) if x[k]]
        parts = _disconnected(chosen, cust)
        if not parts:
            if not proven:  # HiGHS's best when its time ran out: at times no order at
                # all (seen under load), where the greedy tour flies some
                fallback = _greedy_arcs(value, cost, back, cust, budget)
                if value[[i for i, _ in fallback]].sum() > value[[i for i, _ in chosen]].sum():
                    return fallback, False
            return chosen, proven
        for part in parts:
            rows += _cut(arcs, cust, part)
    # out of time with the tour still in pieces: the greedy tour (connected by making)
    return _greedy_arcs(value, cost, back, cust, budget), False


def _greedy_arcs(value, cost, back, cust, budget) -> list[tuple[int, int]]:
    """:func:`greedy`'s tour as :func:`solve`'s arcs (order, origin index)."""
    arcs, at = [], 0
    for i in greedy(value, cost, back, cust, budget):
        arcs.append((i, at))
        at = int(cust[i])
    return arcs


def _flow_rows(arcs, cust, n: int, n_org: int, flow: int) -> list[tuple[dict, float, float]]:
    """Connection to home by a single-commodity flow: home sends one unit per order flown,
    each order's arc drops one unit at its customer and passes the rest on, so a piece of
    the tour cut off from home would have to create flow. Weaker in the LP than the cuts
    but needs no rounds; variables ``flow + k`` carry arc k's flow."""
    rows = []
    for k in range(len(arcs)):
        rows.append(({flow + k: 1, k: -n}, -math.inf, 0))  # f_k <= n x_k
        rows.append(({flow + k: 1, k: -1}, 0, math.inf))  # f_k >= x_k
    for u in range(1, n_org):
        co: dict[int, float] = {}
        for k, (i, p) in enumerate(arcs):
            if cust[i] == u:
                co[flow + k] = co.get(flow + k, 0) + 1
                co[k] = co.get(k, 0) - 1
            if p == u:
                co[flow + k] = co.get(flow + k, 0) - 1
        rows.append((co, 0, 0))
    return rows


def _cut(arcs, cust, inside: set[int]) -> list[tuple[dict, float, float]]:
    """Rows saying: an arc flown from a place in ``inside`` needs an arc into ``inside``
    from outside it (home is never inside)."""
    enter = {k: 1 for k, (i, p) in enumerate(arcs) if cust[i] in inside and p not in inside}
    return [(enter | {k0: -1}, 0, math.inf) for k0, (_, p0) in enumerate(arcs)
            if p0 in inside]


def _disconnected(chosen: list[tuple[int, int]], cust: np.ndarray) -> list[set[int]]:
    """The groups of places used by ``chosen`` that home cannot reach along it (each a
    connected piece of the chosen arcs)."""
    links: dict[int, set[int]] = {}
    for i, p in chosen:
        links.setdefault(p, set()).add(int(cust[i]))
        links.setdefault(int(cust[i]), set()).add(p)
    reach, todo = {0}, [0]
    while todo:
        u = todo.pop()
        for i, p in chosen:
            if p == u and int(cust[i]) not in reach:
                reach.add(int(cust[i]))
                todo.append(int(cust[i]))
    parts, seen = [], set(reach)
    for u in links:
        if u in seen:
            continue
        part, todo = {u}, [u]
        while todo:
            for v in links[todo.pop()]:
                if v not in part and v not in reach:
                    part.add(v)
                    todo.append(v)
        seen |= part
        parts.append(part)
    return parts


def circuit(chosen: list[tuple[int, int]], cust: np.ndarray) -> list[int]:
    """Orders in an Euler circuit from home over the chosen arcs (Hierholzer)."""
    out: dict[int, list[int]] = {}
    for i, p in sorted(chosen, reverse=True):
        out.setdefault(p, []).append(i)
    stack, tour = [(0, None)], []
    while stack:
        u, via = stack[-1]
        if out.get(u):
            i = out[u].pop()
            stack.append((int(cust[i]), i))
        else:
            stack.pop()
            if via is not None:
                tour.append(via)
    return tour[::-1]


def greedy(value: np.ndarray, cost: np.ndarray, back: np.ndarray, cust: np.ndarray,
           budget: int) -> list[int]:
    """Repeatedly fly the order with the most money per move that still leaves the way
    home within the budget."""
    left, at, used, tour = set(range(len(value))), 0, 0, []
    while True:
        best, pick = -1.0, None
        for i in left:
            c = cost[at, i]
            if np.isfinite(c) and used + c + back[cust[i]] <= budget and \
                    value[i] / max(c, 1) > best:
                best, pick = value[i] / max(c, 1), i
        if pick is None:
            return tour
        used += cost[at, pick]
        at = int(cust[pick])
        left.discard(pick)
        tour.append(pick)
