"""A fixed-wing delivery drone's ground and climb kinematics, from the KU Leuven seed.

- Take-off: the ground distance from brake release to altitude h is the seed's
  regression, x = 254.0966 + 3.5519 h for 50 < h <= 150 m and x = 343.0420 + 3.0874 h
  above (not modelled below 50 m, so the lowest cruise altitude is 50 m). The climb is
  flown at ``climb_angle`` (20 degrees), so the roll is x - h / tan(climb_angle) and the
  rest is the climb.
- Landing: touchdown at ``landing_speed`` (40 m/s) and a roll-out of ``rollout`` metres
  to a stop with constant braking (192 m from 40 m/s: 4.17 m/s^2, 9.6 s).
- Taxi: 10 m/s, 3 m/s within one gate width of the gate, 1 m/s within half a gate width
  (speed changes taken as instant: the seed gives no accelerations).
"""

from __future__ import annotations

import math

from skyroute.errors import OptionError

MIN_CRUISE_ALTITUDE = 50.0
_LOW = (254.0966, 3.5519)  # 50 < h <= 150 m
_HIGH = (343.0420, 3.0874)  # h > 150 m


def takeoff_distance(altitude: float) -> float:
    """Ground distance (m) from brake release to ``altitude`` metres (seed regression).

    >>> round(takeoff_distance(100.0), 4), round(takeoff_distance(200.0), 4)
    (609.2866, 960.522)
    """
    h = float(altitude)
    if not (math.isfinite(h) and h >= MIN_CRUISE_ALTITUDE):
        raise OptionError(f"altitude={altitude!r}: the take-off regression holds from "
                          f"{MIN_CRUISE_ALTITUDE:g} m up", param="altitude")
    a, b = _LOW if h <= 150.0 else _HIGH
    return a + b * h


def takeoff_phases(altitude: float, climb_angle_deg: float, lift_off_speed: float,
                   climb_speed: float) -> tuple[float, float, float, float]:
    """(roll distance, roll seconds, climb ground distance, climb seconds) to reach
    ``altitude``: a roll accelerating evenly from rest to ``lift_off_speed``, then a
    straight climb at ``climb_angle_deg`` flown at ``climb_speed`` along the slope."""
    x = takeoff_distance(altitude)
    climb = altitude / math.tan(math.radians(climb_angle_deg))
    roll = x - climb
    if roll <= 0:
        raise OptionError(f"climb_angle_deg={climb_angle_deg!r} is too shallow for the "
                          f"seed's take-off distance at {altitude:g} m", param="climb_angle_deg")
    slope = math.hypot(climb, altitude)
    return roll, 2.0 * roll / lift_off_speed, climb, slope / climb_speed


def rollout_seconds(landing_speed: float, rollout: float) -> float:
    """Seconds to stop from ``landing_speed`` over ``rollout`` metres, braking evenly."""
    return 2.0 * rollout / landing_speed


def taxi_seconds(distance: float, gate_width: float, *, fast: float = 10.0,
                 near: float = 3.0, slow: float = 1.0) -> float:
    """Seconds to taxi ``distance`` metres to (or from) a gate: ``fast`` beyond one gate
    width of it, ``near`` within one gate width, ``slow`` within half a gate width.

    >>> round(taxi_seconds(100.0, 20.0), 9)  # 80 m at 10, 10 m at 3, 10 m at 1
    21.333333333
    """
    d = max(0.0, float(distance))
    slow_part = min(d, gate_width / 2)
    near_part = min(max(d - gate_width / 2, 0.0), gate_width / 2)
    fast_part = max(d - gate_width, 0.0)
    return fast_part / fast + near_part / near + slow_part / slow
