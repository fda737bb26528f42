"""How long one flight may stay airborne: :data:`~skyroute.fleet.limits.MAX_FLIGHT_HOURS`
with its worst loiters, before the flight is sampled each second (a turn_radius or a
layer_step of 1e9 m asked for gigabytes of samples).

A scenario is checked before a run (:func:`check_flights`, on the farthest airports
at the highest level either airspace may give a drone), so the error names the file;
the simulation checks each flight it plans as well. Either error names the field to
blame: the one whose default shortens the flight most. :func:`check_flights` first
refuses airports that no-fly zones cut off (:func:`skyroute.fleet.nofly.check_joined`):
every place that is about to fly a scenario calls it.
"""

from __future__ import annotations

import math

import numpy as np

from skyroute.errors import InputFormatError, QueryError, SkyrouteError
from skyroute.fleet.flightplan import plan_flight, takeoff_overrun
from skyroute.fleet.limits import MAX_FLIGHT_HOURS
from skyroute.fleet.nofly import check_joined
from skyroute.fleet.scenario import Airspace, Drone, Scenario

MAX_LOITERS = 12  # full circles a flight may wait before its landing is granted
# the fields with a default that a flight's airborne time depends on, as (part, field)
_FIELDS = (("drone", "cruise_speed"), ("drone", "turn_radius"), ("drone", "landing_speed"),
           ("drone", "climb_angle_deg"), ("drone", "glide_angle_deg"),
           ("airspace", "layer_step"), ("airspace", "base_altitude"),
           ("airspace", "shared_levels"))
_DEFAULTS = {"drone": Drone(), "airspace": Airspace()}


def airborne_seconds(scenario: Scenario, plan) -> float:
    """The airborne time of ``plan`` (a FlightPlan) with :data:`MAX_LOITERS` circles."""
    d = scenario.drone
    return float(plan.pieces.t1.max() - plan.pieces.t0.min()) \
        + MAX_LOITERS * 2 * math.pi * d.turn_radius / d.cruise_speed


def too_long(scenario: Scenario, origin: int, destination: int, level: int,
             plan=None) -> str | None:
    """None when the flight from airport index ``origin`` to ``destination`` at cruise
    level ``level`` (0: ``base_altitude``, each next one ``layer_step`` higher; ``plan``:
    the flight's plan, when made) is airborne within the limit, else the error:
    ``"<field>: a flight ..."``."""
    seconds, alt = _airborne(scenario, origin, destination, level, plan)
    if seconds <= MAX_FLIGHT_HOURS * 3600:
        return None
    ids = [a.id for a in scenario.airports]
    field, value = _blame(scenario, origin, destination, level, seconds)
    return (f"{field}: a flight {ids[origin]} -> {ids[destination]} at {alt:g} m would be "
            f"airborne up to {seconds / 3600:.3g} h with its loiters, over the limit of "
            f"{MAX_FLIGHT_HOURS:g} h ({field} is {value:g})")


def check_flights(scenario: Scenario, where: object = "scenario") -> None:
    """An InputFormatError naming ``where`` (the file) and the field when no-fly zones cut
    some airports off from the others (:func:`~skyroute.fleet.nofly.check_joined`), when
    the flight between the farthest airports cannot be planned round the zones, or when
    that flight, either way, at the highest level either airspace may use (a drone's
    layer, or a shared level) that its runway holds, would be airborne past the limit."""
    check_joined(scenario, where)
    pos = np.array([[a.north, a.east] for a in scenario.airports])
    far = np.hypot(*(pos[:, None] - pos[None]).transpose(2, 0, 1))
    o, b = (int(k) for k in np.unravel_index(np.argmax(far), far.shape))
    for x, y in ((o, b), (b, o)):
        try:
            error = too_long(scenario, x, y, _held(scenario, x, _top(scenario)))
        except QueryError as exc:  # a climb-out, final, loiter or cruise the zones block
            if exc.param != "no_fly_zones":
                raise
            raise InputFormatError(where, f"no_fly_zones: {exc}") from None
        if error:
            raise InputFormatError(where, error)


def _held(scenario: Scenario, origin: int, top: int) -> int:
    """The highest level up to ``top`` whose take-off roll airport ``origin``'s runway
    holds (the roll grows with the level). Higher levels are refused before a run, for
    the airspace it flies (:func:`skyroute.fleet.simulate.check_levels`): a scenario
    that flies ``shared`` is not refused for a layer it never uses."""
    a, sp = scenario.airports[origin], scenario.airspace
    lo, hi = 0, top
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if takeoff_overrun(scenario, a, sp.base_altitude + mid * sp.layer_step) is None:
            lo = mid
        else:
            hi = mid - 1
    return lo


def _airborne(scenario: Scenario, origin: int, destination: int, level: int,
              plan=None) -> tuple[float, float]:
    """(airborne seconds, cruise altitude) of the flight, planned unless ``plan``."""
    alt = scenario.airspace.base_altitude + level * scenario.airspace.layer_step
    if plan is None:
        ids = [a.id for a in scenario.airports]
        plan = plan_flight(scenario, 0, ids[origin], ids[destination], depart=0.0,
                           altitude=alt)
    return airborne_seconds(scenario, plan), alt


def _blame(scenario: Scenario, origin: int, destination: int, level: int,
           seconds: float) -> tuple[str, float]:
    """The field (``drone.turn_radius``) whose default shortens the flight most, and its
    value; the scenario's drone count (its top layer) when no default does."""
    best, blamed = seconds, ("drones", float(scenario.drones))
    for part, name in _FIELDS:
        now = getattr(getattr(scenario, part), name)
        default = getattr(_DEFAULTS[part], name)
        if now == default:
            continue
        changed = getattr(scenario, part).model_copy(update={name: default})
        trial = scenario.model_copy(update={part: changed})
        try:  # a default beside the other values may make no flight (landing > cruise)
            t, _ = _airborne(trial, origin, destination, min(level, _top(trial)))
        except (SkyrouteError, ArithmeticError, ValueError):
            continue
        if t < best:
            best, blamed = t, (f"{part}.{name}", float(now))
    return blamed


def _top(scenario: Scenario) -> int:
    """The highest level a run may use: a drone's layer, or a shared level."""
    return max(scenario.drones, scenario.airspace.shared_levels) - 1
