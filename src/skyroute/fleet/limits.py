"""How large one fleet run may be: the limits scenario files, ``skyroute fleet`` and the
service's fleet jobs share. Past them a run would exhaust memory or run for hours, so it
is refused before any work starts, with a message naming the value and the limit.

The largest runs in use (``skyroute bench fleet``, docs/benchmarks.md) are 1000 drones
and 100 airports for 1 h at 4000 packages/h (4,000 packages) and 100 drones and 30
airports for 24 h at 600/h (14,400 packages; 8.6 million rows of tracks.csv at 1 s);
the presets and sweeps run 3-18 drones for 4 h at up to 360/h. Where the cost is a
product, the product is checked (:func:`check_run`): the packages a run spawns (rate x
hours) and the rows of its tracks (drones x seconds / track step); and, for a sweep, its
runs (:func:`check_sweep`: schedulers x airspaces x rates x seeds).

>>> expected_packages(600, 24)
14400.0
>>> track_rows(100, 24, 1.0)
8640100.0
"""

from __future__ import annotations

from skyroute.errors import OptionError

MAX_AIRPORTS = 100  # the largest benchmark's airports
MAX_DRONES = 1000  # the largest benchmark's fleet
MAX_RATE = 1e5  # packages per hour: 25 times the largest benchmark's 4000/h
MAX_DISTANCE = 1e5  # metres of an airport or a zone corner from home (100 km; 15 in use)
MAX_AREA_KM = 2 * MAX_DISTANCE / 1000  # side of a generated layout's square
MAX_HOURS = 24.0 * 7  # simulated hours: a week
MAX_PACKAGES = 1e5  # packages a run is expected to spawn (rate x hours): 7x the largest
MAX_TRACK_ROWS = 2e7  # tracks.csv rows (drones x seconds / step): 0.85 GB, 3 GB of memory
MAX_SEEDS = 1000  # seeds in one sweep (the documented sweeps use 30)
MAX_SWEEP_RUNS = 10_000  # runs in one sweep (the documented ones: 2x2x2 settings x 30 seeds)
MAX_FLIGHT_HOURS = 12.0  # airborne time of one flight, its loiters included
MAX_LEVELS = MAX_DRONES  # shared cruise levels: as many as the largest fleet has layers
# no-fly zones: each zone costs about 1 ms of checks before a run (and more in its
# cruises), each corner 0.05 ms; 125,000 zones fit in the service's 10 MB body and held
# its POST /jobs/fleet for minutes (docs/fleet.md, Limits)
MAX_ZONES = 1000
MAX_ZONE_CORNERS = 100_000  # corners of all the zones together


def expected_packages(rate_per_hour: float, hours: float) -> float:
    """The packages a Poisson stream at ``rate_per_hour`` spawns in ``hours``, on average."""
    return float(rate_per_hour) * float(hours)


def track_rows(drones: int, hours: float, track_step: float) -> float:
    """An upper bound on the rows of tracks.csv: every drone in flight all the time (no
    rounding down: a step of 1e-300 s gives infinity, not an OverflowError)."""
    return float(drones) * (float(hours) * 3600.0 / float(track_step) + 1.0)


def check_run(*, drones: int, hours: float, rate_per_hour: float | None,
              track_step: float | None = None, rate_given: bool = True,
              rate_name: str = "rate_per_hour") -> None:
    """Raise an :class:`~skyroute.errors.OptionError` naming the parameters when a run of
    ``drones`` for ``hours`` at ``rate_per_hour`` (None: a package CSV, whose rows are
    read, not drawn) writing tracks every ``track_step`` seconds (None: no tracks) is
    past a limit of this module (the drones are a scenario's, within :data:`MAX_DRONES`).
    The values are assumed finite and positive. ``rate_given`` False: the rate is the
    scenario's, so the messages blame ``hours``; ``rate_name``: the parameter the rate
    was given as (a sweep's ``rates``)."""
    if hours > MAX_HOURS:
        raise OptionError(f"hours={hours:g} is over the limit of {MAX_HOURS:,g} simulated "
                          "hours", param="hours")
    if rate_per_hour is not None:
        r = rate_per_hour
        if rate_given and r > MAX_RATE:
            raise OptionError(f"{rate_name}={r:g} is over the limit of {MAX_RATE:,g} "
                              "packages per hour", param=rate_name)
        n = expected_packages(r, hours)
        if n > MAX_PACKAGES and rate_given:
            raise OptionError(f"{rate_name}={r:g} with hours={hours:g} would spawn about "
                              f"{n:.2g} packages (limit {MAX_PACKAGES:,g}); lower one of "
                              "them", param=(rate_name, "hours"))
        if n > MAX_PACKAGES:
            raise OptionError(f"hours={hours:g} at the scenario's {r:g} packages/h would "
                              f"spawn about {n:.2g} packages (limit {MAX_PACKAGES:,g}); lower "
                              "it or the scenario's packages.rate_per_hour", param="hours")
    if track_step is not None:
        rows = track_rows(drones, hours, track_step)
        if rows > MAX_TRACK_ROWS:
            raise OptionError(f"track_step={track_step:g} with hours={hours:g} and "
                              f"{drones} drones would write up to {rows:.2g} track rows "
                              f"(limit {MAX_TRACK_ROWS:,.0f}); raise the step",
                              param=("track_step", "hours"))


def check_sweep(*, schedulers: int, airspaces: int, rates: int, seeds: int,
                fewer: str = "rates or seeds") -> int:
    """The runs of a sweep of that many schedulers, airspaces, rates and seeds; an
    OptionError past :data:`MAX_SWEEP_RUNS` (``fewer``: what to give fewer of)."""
    runs = schedulers * airspaces * rates * seeds
    if runs > MAX_SWEEP_RUNS:
        raise OptionError(f"{schedulers} scheduler(s) x {airspaces} airspace(s) x {rates:,} "
                          f"rate(s) x {seeds:,} seed(s) is {runs:,} runs, over the limit of "
                          f"{MAX_SWEEP_RUNS:,} in one sweep; give fewer {fewer}",
                          param=("rates", "seeds"))
    return runs
