"""The stream of packages a fleet carries: a seeded Poisson stream or an explicit CSV.

A package has a spawn time (seconds), an origin airport and gate and a destination airport
and gate; airports are indices into ``scenario.airports``, gates 0 or 1. A package never
joins the two gates of one airport.

The Poisson stream draws every arrival and every origin-destination pair from one
generator seeded with ``seed``, so two runs that differ only in the dispatcher or the
airspace see the very same packages (common random numbers for fair comparisons).

>>> from skyroute.fleet.scenario import preset
>>> s = preset("seed-3x3")
>>> p = poisson(s, hours=1.0, seed=4)
>>> len(p) == len(poisson(s, hours=1.0, seed=4)), bool((p.origin != p.destination).all())
(True, True)
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from skyroute.errors import InputFormatError, OptionError, check_seed, real
from skyroute.files import cannot_read, open_text
from skyroute.fleet.limits import MAX_PACKAGES, expected_packages
from skyroute.fleet.scenario import Scenario

CSV_HEADER = ("t", "from_airport", "from_gate", "to_airport", "to_gate")


@dataclass(frozen=True, eq=False)
class Stream:
    """Packages in spawn order, as columns (one row per package, row = package id)."""

    t: np.ndarray
    origin: np.ndarray
    origin_gate: np.ndarray
    destination: np.ndarray
    destination_gate: np.ndarray

    def __len__(self) -> int:
        return len(self.t)


def _stream(t, origin, og, dest, dg) -> Stream:
    order = np.argsort(np.asarray(t, dtype=float), kind="stable")
    cols = [np.asarray(c)[order] for c in (t, origin, og, dest, dg)]
    cols = [cols[0].astype(float)] + [c.astype(np.int64) for c in cols[1:]]
    for c in cols:
        c.setflags(write=False)
    return Stream(*cols)


TIME_DECIMALS = 3  # the event log and packages.csv write times to the millisecond


def horizon_seconds(hours: float) -> float:
    """The end of a run of ``hours``, in seconds: ``hours * 3600`` rounded to the
    millisecond (:data:`TIME_DECIMALS`), the resolution its files write times to. Rounding
    is monotone and the end is its own rounding, so an event at or before the end is
    written at or before it. With the exact product, ``--hours 0.02777798611111111``
    (100.00075 s) wrote a spawn at 100.0007 s as 100.001, after the end."""
    return round(float(hours) * 3600.0, TIME_DECIMALS)


def check_hours(hours) -> float:
    """Simulated hours: a finite number > 0 whose end (:func:`horizon_seconds`) is at
    least a millisecond."""
    h = real("hours", hours, low=0.0, strict=True)
    if horizon_seconds(h) <= 0:
        raise OptionError(f"hours={h:g} is {h * 3600:.2g} s, under the millisecond a "
                          "run's times are written to", param="hours")
    return h


def poisson(scenario: Scenario, *, hours: float, seed: int = 0,
            rate_per_hour: float | None = None) -> Stream:
    """A Poisson stream over ``[0, horizon_seconds(hours))`` at ``rate_per_hour`` (default the
    scenario's), origin and destination airports and gates uniform, airports distinct."""
    h = check_hours(hours)
    rate = scenario.packages.rate_per_hour if rate_per_hour is None else \
        real("rate_per_hour", rate_per_hour, low=0.0)
    n = expected_packages(rate, h)
    if n > MAX_PACKAGES:  # numpy's "lam value too large" before, or all memory
        raise OptionError(f"rate_per_hour={rate:g} with hours={h:g} would spawn about "
                          f"{n:.2g} packages (limit {MAX_PACKAGES:,g}); lower one of them",
                          param=("rate_per_hour", "hours"))
    rng = np.random.default_rng(check_seed(seed))
    horizon = horizon_seconds(h)
    if rate == 0:
        n = 0
        t = np.empty(0)
    else:
        n = int(rng.poisson(rate * h))
        t = np.sort(rng.uniform(0.0, horizon, n))  # given the count, arrivals are uniform
    a = len(scenario.airports)
    origin = rng.integers(0, a, n)
    dest = (origin + rng.integers(1, a, n)) % a  # any other airport, uniformly
    og = rng.integers(0, 2, n)
    dg = rng.integers(0, 2, n)
    return _stream(t, origin, og, dest, dg)


def read_csv(path: str | Path, scenario: Scenario) -> Stream:
    """Packages from a CSV with header ``t,from_airport,from_gate,to_airport,to_gate``
    (airport ids of the scenario, gates 0 or 1, ``t`` seconds >= 0), at most
    :data:`~skyroute.fleet.limits.MAX_PACKAGES` of them (the limit of a Poisson run, met
    as the file is read); an error names the file, the line and the field."""
    p = Path(path)
    ids = {a.id: k for k, a in enumerate(scenario.airports)}
    rows = []
    try:
        with open_text(p) as fh:  # a byte-order mark (Excel's "CSV UTF-8") read past
            reader = csv.reader(fh)
            header = next(reader, None)
            if header is None or tuple(h.strip() for h in header) != CSV_HEADER:
                raise InputFormatError(p, "header must be " + ",".join(CSV_HEADER), line=1)
            end = reader.line_num  # the physical line each record ends on: a quoted
            for rec in reader:  # field may hold a line break, so records are not lines
                line, end = end + 1, reader.line_num
                if not rec or all(not x.strip() for x in rec):
                    continue
                if len(rows) >= MAX_PACKAGES:
                    raise InputFormatError(p, f"more than {MAX_PACKAGES:,.0f} packages, the "
                                           "limit of one run; split the file", line=line)
                rows.append(_row(p, line, rec, ids))
    except OSError as exc:  # strerror: the file is named once, not twice
        raise cannot_read(p, exc) from None
    except UnicodeDecodeError as exc:  # as files.read_text words it for every other file
        raise InputFormatError(p, f"cannot read: not UTF-8 text ({exc.reason} at byte "
                               f"{exc.start})") from None
    if not rows:
        return _stream(*(np.empty(0) for _ in range(5)))
    return _stream(*zip(*rows, strict=True))


def _row(p: Path, line: int, rec: list[str], ids: dict[str, int]) -> tuple:
    if len(rec) != len(CSV_HEADER):
        raise InputFormatError(p, f"expected {len(CSV_HEADER)} fields, got {len(rec)}",
                               line=line)
    t_s, fa, fg, ta, tg = (x.strip() for x in rec)
    try:
        t = float(t_s)
    except ValueError:
        t = math.nan
    if not (math.isfinite(t) and t >= 0):
        raise InputFormatError(p, f"t: {t_s!r} must be a number of seconds >= 0", line=line)
    out = [t]
    for name, airport, gate in (("from", fa, fg), ("to", ta, tg)):
        if airport not in ids:
            raise InputFormatError(p, f"{name}_airport: no airport {airport!r}; airports: "
                                   + ", ".join(ids), line=line)
        if gate not in ("0", "1"):
            raise InputFormatError(p, f"{name}_gate: {gate!r} must be 0 or 1", line=line)
        out += [ids[airport], int(gate)]
    if out[1] == out[3]:
        raise InputFormatError(p, f"to_airport: {ta!r} is the origin; a package joins two "
                               "airports", line=line)
    return tuple(out)


def for_scenario(scenario: Scenario, *, hours: float, seed: int = 0,
                 base: str | Path | None = None,
                 rate_per_hour: float | None = None) -> Stream:
    """The scenario's packages over ``hours``: its CSV (a relative path read from ``base``,
    the scenario file's folder; rows at or after the horizon dropped) when it names one,
    else the Poisson stream."""
    h = check_hours(hours)
    if scenario.packages.csv is None or rate_per_hour is not None:
        return poisson(scenario, hours=h, seed=seed, rate_per_hour=rate_per_hour)
    path = Path(scenario.packages.csv)
    if not path.is_absolute() and base is not None:
        path = Path(base) / path
    s = read_csv(path, scenario)
    keep = s.t < horizon_seconds(h)
    return _stream(*(getattr(s, c)[keep] for c in ("t", "origin", "origin_gate",
                                                     "destination", "destination_gate")))
