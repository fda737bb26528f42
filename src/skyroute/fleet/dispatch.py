"""Which drone fetches which package: the seed's rule and an optimal assignment.

Both are pure functions of the moment: the waiting packages, the drones and the travel
times between airports; the simulation calls one at every event that can change the
answer (a package spawns, a drone becomes ready) and releases the pairs it returns.

``seed``
    the KU Leuven rule, packages first come first served: a ready drone at the
    package's gate, else at its airport, else the ready drone that can get there
    soonest (ties to the lowest id); only one drone heading to an airport+gate at a time
    (a package whose pickup or delivery gate already has a drone heading to it waits).
``optimal``
    a minimum-cost assignment (:func:`scipy.optimize.linear_sum_assignment`) of the
    ready and soon-ready drones (in flight to a delivery, with nothing after it) to the
    waiting packages. A pair costs the expected pickup time (until the drone is ready,
    plus the flight to the package's airport) minus the package's age times
    ``age_weight`` (0.1: ten seconds of waiting weigh as one second of pickup, so while
    the queue is long a drone still takes a package where it stands rather than fly
    empty to an older one; measured on 18x9 at saturation, 1.0 delivered 205/h, 0.1
    228/h, 0.02 231/h). A waiting package's age grows without bound while pickup times
    stay bounded, so none is stranded.
    Only pairs whose drone is ready now are released; the rest are re-solved at the
    next event (a drone that lands may find a better package, or a package a closer
    drone).

>>> import numpy as np
>>> travel = np.array([[0.0, 100.0], [100.0, 0.0]])
>>> optimal(now=10.0, packages=[(0, 0, 5.0), (1, 1, 0.0)],
...         drones=[(7, 0, 10.0), (8, 1, 10.0)], travel=travel)
[(7, 0), (8, 1)]
"""

from __future__ import annotations

import numpy as np

SCHEDULERS = ("seed", "optimal")
AGE_WEIGHT = 0.1


def seed(*, packages, drones, travel, heading) -> list[tuple[int, int]]:
    """The seed's rule. ``packages``: ``(id, airport, gate, dest_airport, dest_gate)``
    waiting, in spawn order; ``drones``: ``(id, airport, gate)`` ready now; ``travel``:
    seconds between airports; ``heading``: the set of ``(airport, gate)`` a drone is
    already heading to. Returns ``(drone, package)`` pairs (and does not touch its
    inputs)."""
    free = {d: (a, g) for d, a, g in drones}
    busy_gates = set(heading)
    out = []
    for p, a, g, b, h in packages:
        if not free:
            break
        if (b, h) in busy_gates:
            continue
        at_gate = [d for d, (da, dg) in free.items() if da == a and dg == g]
        at_airport = [d for d, (da, _) in free.items() if da == a]
        if at_gate or at_airport:
            d = min(at_gate or at_airport)
        else:
            if (a, g) in busy_gates:
                continue
            d = min(free, key=lambda k: (travel[free[k][0], a], k))
            busy_gates.add((a, g))
        busy_gates.add((b, h))
        del free[d]
        out.append((d, p))
    return out


def optimal(*, now: float, packages, drones, travel,
            age_weight: float = AGE_WEIGHT) -> list[tuple[int, int]]:
    """The optimal rule. ``packages``: ``(id, airport, spawn time)`` waiting;
    ``drones``: ``(id, airport, ready time)`` ready now (``<= now``) or soon; returns the
    ``(drone, package)`` pairs of the minimum-cost assignment whose drone is ready now,
    sorted by drone."""
    if not packages or not drones:
        return []
    # here, not at the top: scipy.optimize takes about 0.7 s CPU to import, and a run
    # with the seed rule (the default), a worker or a server that only names the
    # schedulers never calls it
    from scipy.optimize import linear_sum_assignment

    pa = np.array([a for _, a, _ in packages], dtype=np.int64)
    age = now - np.array([t for _, _, t in packages])
    da = np.array([a for _, a, _ in drones], dtype=np.int64)
    wait = np.maximum(np.array([r for _, _, r in drones]) - now, 0.0)
    cost = wait[:, None] + travel[da[:, None], pa[None, :]] - age_weight * age[None, :]
    rows, cols = linear_sum_assignment(cost)
    out = [(drones[i][0], packages[j][0]) for i, j in zip(rows, cols, strict=True)
           if drones[i][2] <= now]
    return sorted(out)
