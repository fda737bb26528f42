"""``skyroute bench fleet``: how fast the fleet simulation runs on large fleets.

Each case generates a scenario (:func:`skyroute.fleet.scenario.generate`, layout seed 0),
simulates it and runs the independent separation checker over every airborne piece;
the simulation and the check are timed apart and the run's safety counts reported
beside the speed (a fast run that lost separation would be worthless).
"""

from __future__ import annotations

import time

from skyroute.fleet.report import report
from skyroute.fleet.scenario import generate
from skyroute.fleet.separation import check
from skyroute.fleet.simulate import run

# (name, airports, drones, area km, hours, packages per hour): the two targets
CASES = (("100 drones, 30 airports, 24 h", 30, 100, 20.0, 24.0, 600.0),
         ("1000 drones, 100 airports, 1 h", 100, 1000, 30.0, 1.0, 4000.0))


def bench_case(airports: int, drones: int, area_km: float, hours: float, rate: float, *,
               scheduler: str = "optimal", airspace: str = "shared", seed: int = 0,
               progress=None) -> dict:
    """One timed run: wall seconds of the simulation and of the check, throughput and
    safety numbers from its report."""
    s = generate(airports, drones, area_km=area_km, seed=0, rate_per_hour=rate)
    t0 = time.perf_counter()
    sim = run(s, hours=hours, seed=seed, scheduler=scheduler, airspace=airspace,
              progress=progress)
    t1 = time.perf_counter()
    sep = check(sim.pieces(), sep_horizontal=s.airspace.sep_horizontal,
                sep_vertical=s.airspace.sep_vertical)
    t2 = time.perf_counter()
    rep = report(sim, sep)
    return {"airports": airports, "drones": drones, "area_km": area_km, "hours": hours,
            "rate_per_hour": rate, "scheduler": scheduler, "airspace": airspace,
            "seed": seed, "sim_seconds": t1 - t0, "check_seconds": t2 - t1,
            "wall_seconds": t2 - t0, "sim_seconds_per_wall_second": hours * 3600 / (t2 - t0),
            "flights": rep["flights"], "pieces": len(sim.pieces()),
            "delivered_per_hour": rep["delivered_per_hour"],
            "served_share": rep["served_share"], "loiters": rep["loiters"],
            "conflicts": rep["conflicts"], "lost": rep["lost"],
            "min_horizontal_m": rep["min_horizontal_m"]}
