"""Turn a plan (orders, shop orders) into the day's flight: legal moves from the actual
position to each stop, a hover at each, and the way home; every leg is ``plan_moves``
from where the drone really is, so the flight may differ from the leg table by a move
here and there. The day's loop (:mod:`skyroute.delivery.day`) re-plans with a smaller
budget when the flight comes out over the battery.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np

from skyroute.caches import register
from skyroute.errors import SkyrouteError
from skyroute.motion.step_drone import HOVER, MERGE, STEP, Flight, plan_moves
from skyroute.world.world import World

# world -> {(start bytes, target): (angles, froms, tos)}: legs recur across days
_LEGS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
register(_LEGS.clear)
# (merge, expansions): the fewest moves when that is quick to find (at most 2000
# expansions, about 95% of the legs of late 2023), else a lattice six times coarser,
# which flies one move more on about a third of those legs at a twentieth of the time.
# On 24 of the busiest days this ladder delivered the same money as one ending in a
# 1e-5 lattice, in three quarters of the time (docs/benchmarks.md, section 7).
LADDER = ((MERGE, 2000), (3e-5, 200_000))


@dataclass(frozen=True)
class DayFlight:
    """Moves of a day with the order each move serves (SPEC.md 4.6)."""

    flight: Flight
    order_no: tuple[str, ...]

    @property
    def moves(self) -> int:
        return self.flight.moves


def leg(world: World, start: np.ndarray, target: tuple[float, float]) -> Flight:
    """The fewest moves from ``start`` to close to ``target`` (none when already close)."""
    if math.dist(start, target) < STEP:
        e = np.empty((0, 2))
        return Flight(e, np.empty(0, int), e.copy())
    legs = _LEGS.setdefault(world, {})
    key = (start.tobytes(), tuple(target))
    hit = legs.get(key)
    if hit is None:
        for merge, budget in LADDER:
            f = plan_moves(world, start, target, merge=merge, max_expansions=budget)
            if f.status.value != "budget_exhausted":
                break
        if f.status.value != "found":
            raise SkyrouteError(f"no flight from ({start[0]:.6f}, {start[1]:.6f}) to "
                                f"({target[0]:.6f}, {target[1]:.6f}): {f.status.value}")
        if len(legs) > 200_000:
            legs.clear()
        hit = legs[key] = (f.angle, f.frm, f.to)
    angle, frm, to = hit
    return Flight(frm, angle, to)


def fly_day(world: World, home: tuple[float, float],
            visits: list[tuple[str, list[tuple[float, float]]]]) -> DayFlight:
    """Fly ``visits`` = [(order_no, [shop, ..., customer]), ...] from home and back,
    hovering once at every stop."""
    pos = np.asarray(home, dtype=float)
    parts, labels = [], []
    for order_no, points in visits:
        for p in points:
            f = leg(world, pos, p)
            if f.moves:
                parts.append(f)
                pos = f.to[-1]
            h = Flight(pos[None, :].copy(), np.array([HOVER]), pos[None, :].copy())
            parts.append(h)
            labels += [order_no] * (f.moves + 1)
    f = leg(world, pos, home)
    if f.moves:
        parts.append(f)
        labels += [visits[-1][0] if visits else "home"] * f.moves
    if not parts:
        e = np.empty((0, 2))
        return DayFlight(Flight(e, np.empty(0, int), e.copy()), ())
    flight = Flight(np.vstack([p.frm for p in parts]), np.concatenate([p.angle for p in parts]),
                    np.vstack([p.to for p in parts]))
    return DayFlight(flight, tuple(labels))
