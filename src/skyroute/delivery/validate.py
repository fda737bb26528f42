"""Re-check a day's flight against the rules before it is stored (SPEC.md 4.2-4.4).

Independent of how the flight was made: it recomputes every move from its angle, tests
each segment against the zones and the area, and checks that every delivered order has
its hovers at each shop and then at its customer, one order after another, and that the
day ends home.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from skyroute.motion.step_drone import HOVER, STEP

BATTERY = 1500


def check_flight(world, home, frm, angle, to, labels, deliveries) -> list[str]:
    """Problems found (empty when the flight is legal). ``deliveries``: [(order_no,
    [shop (lon, lat), ..., customer (lon, lat)]), ...] the orders claimed delivered."""
    bad = []
    frm, to, angle = np.asarray(frm).reshape(-1, 2), np.asarray(to).reshape(-1, 2), \
        np.asarray(angle, dtype=int)
    n = len(angle)
    if n > BATTERY:
        bad.append(f"{n} moves, more than the battery's {BATTERY}")
    if n and tuple(frm[0]) != tuple(home):
        bad.append("the first move does not start at home")
    broken = np.flatnonzero((frm[1:] != to[:-1]).any(axis=1))
    if len(broken):
        bad.append(f"moves do not chain (move {broken[0] + 1} starts elsewhere)")
    hover = angle == HOVER
    fly = ~hover
    if (hover & (frm != to).any(axis=1)).any():
        bad.append("a hover moves")
    wrong = fly & ((angle < 0) | (angle > 350) | (angle % 10 != 0))
    if wrong.any():
        bad.append(f"illegal angle {angle[wrong][0]} at move {np.flatnonzero(wrong)[0]}")
    rad = np.radians(angle[fly])
    expect = frm[fly] + STEP * np.c_[np.cos(rad), np.sin(rad)]
    if len(expect) and np.abs(expect - to[fly]).max() > 1e-12:
        bad.append("a move does not end where its angle and step put it")
    if n and not world.is_free(to).all():
        bad.append("a move ends outside the confinement area")
    if fly.any():
        clear = world.segments_clear(frm[fly], to[fly])
        if not clear.all():
            bad.append(f"move {np.flatnonzero(fly)[np.flatnonzero(~clear)[0]]} touches a "
                       "no-fly zone")
    end = to[-1] if n else np.asarray(home, dtype=float)
    if not math.dist(end, home) < STEP:
        bad.append("the day does not end close to home")
    hovers = np.flatnonzero(hover)
    for order_no, stops in deliveries:
        k = 0
        for h in hovers:
            if k < len(stops) and labels[h] == order_no and math.dist(to[h], stops[k]) < STEP:
                k += 1
        if k < len(stops):
            bad.append(f"order {order_no}: missing its hover at stop {k + 1} of {len(stops)}")
    # one order at a time (SPEC.md 4.2): the delivered orders' hovers come order by
    # order; a flight that picked up two orders before delivering either passed
    claimed = {order_no for order_no, _ in deliveries}
    runs = [no for no, _ in itertools.groupby(labels[h] for h in hovers if labels[h] in claimed)]
    twice = next((no for k, no in enumerate(runs) if no in runs[:k]), None)
    if twice is not None:
        bad.append(f"order {twice}: its stops are split by another order's (the drone "
                   "carries one order at a time)")
    return bad
