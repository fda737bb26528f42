"""One delivery day end to end: price the orders, choose and order them over the leg
table, fly them with legal moves, re-plan while the flight is over the battery, and
re-validate the flight before anyone stores it."""

from __future__ import annotations

import datetime as dt
import time
from dataclasses import dataclass, field

import numpy as np

from skyroute.delivery import mission
from skyroute.delivery.assemble import DayFlight, fly_day
from skyroute.delivery.legs import leg_table
from skyroute.delivery.orders import CHARGE, Order, Priced, price
from skyroute.delivery.validate import BATTERY, check_flight
from skyroute.errors import OptionError, SkyrouteError

METHODS = ("milp", "greedy")
MAX_ROUNDS = 8


@dataclass
class DayResult:
    date: dt.date
    orders: list[Order]
    invalid: list[tuple[Order, str]]
    delivered: list[Priced]  # in flying order
    flight: DayFlight
    money_placed: int  # every order placed: its known item prices + 50p
    settings: dict = field(default_factory=dict)
    started: float = 0.0
    seconds: float = 0.0

    @property
    def money_delivered(self) -> int:
        return sum(p.cost for p in self.delivered)

    @property
    def money_pct(self) -> float | None:
        """Percentage monetary value (SPEC.md 4.7); None on a day without orders."""
        return 100.0 * self.money_delivered / self.money_placed if self.money_placed else None

    def report(self) -> dict:
        return {"date": self.date.isoformat(), "orders_placed": len(self.orders),
                "orders_delivered": len(self.delivered), "orders_invalid": len(self.invalid),
                "invalid": [{"order_no": o.order_no, "reason": r} for o, r in self.invalid],
                "money_placed": self.money_placed, "money_delivered": self.money_delivered,
                "money_pct": self.money_pct, "moves": self.flight.moves,
                "moves_left": BATTERY - self.flight.moves, "seconds": self.seconds,
                "settings": self.settings}


def _placed_value(site, order: Order) -> int:
    return CHARGE + sum(site.menu[i][0] for i in order.items if i in site.menu)


def plan_day(site, date: dt.date, orders: list[Order], *, method: str = "milp",
             battery: int = BATTERY) -> DayResult:
    """Plan and fly one day of ``orders`` (all for ``date``)."""
    if method not in METHODS:
        raise OptionError(f"method={method!r} is not valid; choose one of 'milp', 'greedy'")
    t0 = time.perf_counter()
    started = time.time()
    priced, invalid = [], []
    for o in orders:
        p = price(site, o)
        (priced.append(p) if isinstance(p, Priced) else invalid.append((o, p)))
    shops = [s.lonlat for s in site.shops]
    custs = sorted({p.lonlat for p in priced})
    places = [site.home, *shops, *custs]
    legs = leg_table(site.world, places)
    origins = [0] + [1 + len(shops) + k for k in range(len(custs))]
    org_of = {c: 1 + k for k, c in enumerate(custs)}
    back = np.array([legs[o, 0] if o else 0 for o in origins], dtype=float)
    back[back < 0] = np.inf
    stops = [([1 + s for s in p.shops], 1 + len(shops) + custs.index(p.lonlat))
             for p in priced]
    cost, best = mission.order_costs(legs, origins, stops)
    cust = np.array([org_of[p.lonlat] for p in priced], dtype=int)
    unreachable = ~np.isfinite(cost[0]) | ~np.isfinite(back[cust]) if len(priced) else []
    for i in np.flatnonzero(unreachable):
        invalid.append((priced[i].order, "no legal flight reaches its shops and customer "
                                         "from home and back"))
        cost[:, i] = np.inf  # never chosen
    value = np.array([p.cost for p in priced], dtype=float)

    def plan(budget: int) -> list[tuple[int, tuple]]:
        nonlocal proven
        if method == "milp" and len(priced):
            chosen, ok = mission.solve(value, cost, back, cust, budget)
            proven &= ok
            origin = dict(chosen)
            return [(i, best[origin[i]][i]) for i in mission.circuit(chosen, cust)]
        tour, at = [], 0
        for i in mission.greedy(value, cost, back, cust, budget):
            tour.append((i, best[at][i]))
            at = cust[i]
        return tour

    # The leg table prices legs from each place exactly, the flight flies them from
    # where the drone really is: re-plan with the budget moved by what the flight
    # over- or under-spent, keep the best flight that fits (a few rounds at most).
    # Past MAX_ROUNDS it only goes on while nothing has fitted yet: every flight over the
    # battery lowers the budget, so it ends (an empty plan always fits).
    # Only the integer program proves its choice optimal (over the leg table); the
    # greedy insertion never does, and its report said "proven_optimal": true.
    proven = method == "milp"
    budget, rounds, fit, tried, last, over = battery, 0, None, set(), None, 0
    flyable = len(priced) - int(np.count_nonzero(unreachable))
    while budget > 0 and budget not in tried and (rounds < MAX_ROUNDS or fit is None):
        tried.add(budget)
        tour = plan(budget)
        money = sum(value[i] for i, _ in tour)
        if fit is not None and (tour == last or money <= fit[0]):
            break  # nothing to gain from flying it
        if tour == last:  # the same tour, over the battery again: lower the budget more
            budget -= over
            continue
        rounds += 1
        last = tour
        flight = fly_day(site.world, site.home, [
            (priced[i].order.order_no, [places[s] for s in perm] + [priced[i].lonlat])
            for i, perm in tour])
        over = flight.moves - battery
        if over <= 0:
            if fit is None or (money, -flight.moves) > (fit[0], -fit[2].moves):
                fit = (money, tour, flight)
            if len(tour) == flyable:
                break  # everything that can be delivered is
        budget -= over
    if fit is None:  # nothing fitted: fly nothing
        tour, flight = [], fly_day(site.world, site.home, [])
    else:
        _, tour, flight = fit
    delivered = [priced[i] for i, _ in tour]
    problems = check_flight(site.world, site.home, flight.flight.frm, flight.flight.angle,
                            flight.flight.to, flight.order_no,
                            [(p.order.order_no, [places[s] for s in perm] +
                              [p.lonlat]) for p, (_, perm) in zip(delivered, tour,
                                                                 strict=True)])
    if problems:
        raise SkyrouteError(f"{date}: the flight failed validation: {'; '.join(problems)}")
    return DayResult(date, list(orders), invalid, delivered, flight,
                     sum(_placed_value(site, o) for o in orders),
                     {"method": method, "battery": battery, "rounds": rounds,
                      "proven_optimal": bool(proven)},
                     started, time.perf_counter() - t0)
