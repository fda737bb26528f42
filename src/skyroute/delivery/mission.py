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
  way in from outside, added as found (a handful of rounds at most).

Any Euler circuit of the chosen arcs flies the same moves. ``greedy`` (the course's
usual best-value-per-move insertion) is kept for comparison in the benchmarks.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

HOVER = 1  # moves per hover


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
                c = sum(legs_) + HOVER * (len(perm) + 1)
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
    nv = len(arcs) + len(rets)
    if not arcs or not rets:
        return [], True
    eps = 1.0 / (4 * (budget + 1))  # among equal money, fewer moves
    c = np.array([-value[i] + eps * cost[p, i] for i, p in arcs] +
                 [eps * back[u] for u in rets], dtype=float)
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
    proven = True
    for _ in range(50):
        a = lil_matrix((len(rows), nv))
        lo, hi = np.empty(len(rows)), np.empty(len(rows))
        for r, (co, l_, h_) in enumerate(rows):
            for k, v in co.items():
                a[r, k] = v
            lo[r], hi[r] = l_, h_
        res = milp(c, constraints=LinearConstraint(a.tocsr(), lo, hi),
                   integrality=np.ones(nv), bounds=Bounds(0, 1),
                   options={"time_limit": time_limit})
        if res.x is None:
            return [], False
        proven = proven and res.status == 0
        x = np.round(res.x).astype(int)
        chosen = [arcs[k] for k in range(len(arcs)) if x[k]]
        cut = _disconnected(chosen, cust)
        if cut is None:
            return chosen, proven
        inside = set(cut)
        # something flown from a place in `cut` needs an arc into `cut` from outside
        enter = {k: 1 for k, (i, p) in enumerate(arcs) if cust[i] in inside
                 and p not in inside}
        for k0, (_, p0) in enumerate(arcs):
            if p0 in inside:
                rows.append(({k: v for k, v in enter.items()} | {k0: -1}, 0, math.inf))
    return [], False


def _disconnected(chosen: list[tuple[int, int]], cust: np.ndarray) -> list[int] | None:
    """Places used by ``chosen`` that home cannot reach along it, or None."""
    used = {p for _, p in chosen} | {int(cust[i]) for i, _ in chosen}
    reach, todo = {0}, [0]
    while todo:
        u = todo.pop()
        for i, p in chosen:
            if p == u and int(cust[i]) not in reach:
                reach.add(int(cust[i]))
                todo.append(int(cust[i]))
    rest = sorted(used - reach)
    return rest or None


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
