"""One flight of one drone, gate to gate: timed phases and the airborne pieces.

:func:`plan_flight` turns a flight from airport ``origin`` (gate ``origin_gate``) to
``destination`` (gate ``destination_gate``), leaving the gate at ``depart`` and cruising
at ``altitude``, into a :class:`FlightPlan`: the phases with their times and the
airborne :class:`~skyroute.fleet.trajectory.Pieces`. Pure geometry and kinematics (the
seed's, :mod:`skyroute.fleet.vehicle`); no I/O, no knowledge of other drones.

Phases, in order (each ``[start, end]`` seconds; the next starts where one ends):

``taxi_out`` (ground)
    gate -> airport position -> threshold of the take-off runway, straight lines, at the
    seed's taxi profile (:func:`~skyroute.fleet.vehicle.taxi_seconds` over the whole
    route: slow within half a gate width of the gate, near within one gate width).
``takeoff`` (ground)
    the roll from the threshold along the take-off runway, accelerating evenly from rest
    to ``drone.landing_speed`` (the lift-off speed).
``climb`` (one ``line`` piece)
    straight at ``climb_angle`` along the runway heading from the lift-off point
    (altitude 0) to the climb-out point at ``altitude``, flown at ``cruise_speed`` along
    the slope. Roll plus climb is the seed's take-off regression.
``cruise`` (``line`` and ``arc`` pieces)
    the shortest Dubins path (radius ``drone.turn_radius``) at ``altitude`` from the
    climb-out pose to the **approach gate**, ``final = altitude / tan(glide_angle)``
    metres before the landing threshold on the landing heading, at ``cruise_speed``.
    On arrival the drone asks to land (:attr:`FlightPlan.landing_request`).
``loiter`` (only in :meth:`FlightPlan.with_loiters`; one ``arc`` piece per circle)
    if refused, one full **left-hand** circle (anticlockwise seen from above, as the
    standard traffic pattern; ``loiter_side="right"`` for the other) tangent to the
    approach course through the approach gate, at ``altitude`` and ``cruise_speed``:
    ``2 pi r / cruise_speed`` seconds, back at the gate on the approach heading, and it
    asks again.
``approach`` (one ``line`` piece)
    the straight glide from the approach gate at ``altitude`` to the threshold at
    altitude 0, flown at ``landing_speed`` along the slope (the drone slows from cruise
    to landing speed at the gate: the seed gives no accelerations), touching down at
    ``landing_speed``, the speed the roll-out starts from.
``landing`` (an instant)
    touchdown at the threshold: ``[touchdown, touchdown]``, kept as a phase so runway
    slots can be hung on it.
``rollout`` (ground)
    ``drone.rollout`` metres along the landing runway, braking evenly to a stop
    (:func:`~skyroute.fleet.vehicle.rollout_seconds`).
``taxi_in`` (ground)
    roll-out end -> airport position -> gate, straight lines, the taxi profile.

Gates: an airport's gate 0 stands ``gate_width / 2`` to the left of its position (seen
along the take-off runway's heading), gate 1 as far to the right, unless the airport's
``gates`` place them (:func:`gate_position`).

>>> from skyroute.fleet.scenario import Airport, Runway, Scenario
>>> s = Scenario(airports=[
...     Airport(id="A", north=0, east=0, landing=Runway(heading_deg=0),
...             takeoff=Runway(heading_deg=90)),
...     Airport(id="B", north=0, east=5000, landing=Runway(heading_deg=90),
...             takeoff=Runway(heading_deg=0))])
>>> f = plan_flight(s, 1, "A", "B", depart=0.0, altitude=100.0)
>>> [name for name, _, _ in f.phases]
['taxi_out', 'takeoff', 'climb', 'cruise', 'approach', 'landing', 'rollout', 'taxi_in']
>>> round(f.landing_request, 3), round(f.touchdown, 3), round(f.at_gate, 3)
(139.86, 163.777, 202.677)
>>> g = f.with_loiters(1)
>>> round(g.touchdown - f.touchdown, 6) == round(2 * math.pi * 250 / 50, 6)
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from skyroute.errors import OptionError, QueryError, check_choice
from skyroute.fleet import nofly
from skyroute.fleet.scenario import Airport, Drone, Scenario, runway_ends, takeoff_roll
from skyroute.fleet.trajectory import ARC, LINE, Pieces, Trajectory, arc_piece
from skyroute.fleet.vehicle import (
    MIN_CRUISE_ALTITUDE,
    rollout_seconds,
    takeoff_phases,
    taxi_seconds,
)
from skyroute.geo import heading_to_plane
from skyroute.motion.dubins import DubinsPath, shortest_path

PHASES = ("taxi_out", "takeoff", "climb", "cruise", "loiter", "approach", "landing",
          "rollout", "taxi_in")
AIRBORNE = ("climb", "cruise", "loiter", "approach")
LOITER_SIDES = ("left", "right")
_PIECE_COLUMNS = ("drone", "kind", "t0", "t1", "north", "east", "alt", "v_north", "v_east",
                  "v_alt", "radius", "angle", "rate")


class Phase(NamedTuple):
    """One phase of a flight: its name (one of :data:`PHASES`) and its times."""

    name: str
    start: float
    end: float


@dataclass(frozen=True, eq=False)
class FlightPlan:
    """One flight, gate to gate (see the module docstring for the phases).

    ``phases`` in time order; ``pieces`` the airborne trajectory (drone ``drone``) from
    lift-off to touchdown; ``landing_request`` the first time the drone asks to land (at
    the approach gate); ``loiters`` the circles flown before it was cleared, each
    ``loiter_seconds`` long. Ground geometry, (north, east) metres: ``taxi_out_route``
    and ``taxi_in_route`` (gate first / gate last), ``takeoff_roll`` and ``rollout_roll``
    (start, end); ``approach_gate`` (north, east, altitude) with ``approach_heading``
    (compass radians); ``loiter_centre`` and ``loiter_rate`` (rad/s, < 0 left-hand);
    ``aircraft`` the drone type and ``gate_widths`` the two airports' (for the taxi
    profile of :func:`ground_position`).
    """

    drone: int
    origin: str
    destination: str
    origin_gate: int
    destination_gate: int
    altitude: float
    phases: tuple[Phase, ...]
    pieces: Pieces
    landing_request: float
    loiter_seconds: float
    loiters: int
    cruise_path: DubinsPath
    approach_gate: tuple[float, float, float]
    approach_heading: float
    loiter_centre: tuple[float, float]
    loiter_rate: float
    taxi_out_route: np.ndarray
    taxi_in_route: np.ndarray
    takeoff_roll: np.ndarray
    rollout_roll: np.ndarray
    aircraft: Drone
    gate_widths: tuple[float, float]

    def phase(self, name: str) -> Phase:
        """The phase called ``name``; an OptionError names the phases of this plan."""
        for p in self.phases:
            if p.name == name:
                return p
        check_choice("name", name, tuple(p.name for p in self.phases))
        raise AssertionError  # unreachable: check_choice raised

    @property
    def depart(self) -> float:
        """When the drone leaves the origin gate."""
        return self.phases[0].start

    @property
    def cleared(self) -> float:
        """When the drone is cleared to land and starts the approach."""
        return self.landing_request + self.loiters * self.loiter_seconds

    @property
    def touchdown(self) -> float:
        """Touchdown at the landing threshold."""
        return self.phase("landing").start

    @property
    def at_gate(self) -> float:
        """Arrival at the destination gate."""
        return self.phases[-1].end

    @property
    def out_at_position(self) -> float:
        """When the taxi out reaches the origin airport's position, where the take-off
        runway starts to be held: the taxi profile's time from the gate (slow near it)."""
        route = self.taxi_out_route
        return self.depart + self._taxi_seconds(float(np.hypot(*(route[1] - route[0]))),
                                                self.gate_widths[0])

    @property
    def in_at_position(self) -> float:
        """When the taxi in reaches the destination airport's position, off the landing
        runway's roll: the taxi profile's time before the gate (slow near it)."""
        route = self.taxi_in_route
        return self.at_gate - self._taxi_seconds(float(np.hypot(*(route[2] - route[1]))),
                                                 self.gate_widths[1])

    def _taxi_seconds(self, distance: float, gate_width: float) -> float:
        d = self.aircraft
        return taxi_seconds(distance, gate_width, fast=d.taxi_speed, near=d.taxi_near_speed,
                            slow=d.taxi_gate_speed)

    def loiter(self, t: float) -> Pieces:
        """One loiter circle starting at time ``t`` at the approach gate (one arc piece,
        ``loiter_seconds`` long, ending back at the gate on the approach heading)."""
        return Pieces.from_rows([self._circle(t, t + self.loiter_seconds)])

    def _circle(self, t0: float, t1: float):
        n, e = self.loiter_centre
        gn, ge, alt = self.approach_gate
        return arc_piece(self.drone, t0, t1, (n, e), math.hypot(gn - n, ge - e),
                         math.atan2(ge - e, gn - n), self.loiter_rate, alt)

    def shifted(self, dt: float, *, drone: int | None = None) -> FlightPlan:
        """This plan ``dt`` seconds later (same geometry: every time moves by ``dt``),
        flown by ``drone`` (default the same one)."""
        dt = float(dt)
        drone = self.drone if drone is None else int(drone)
        if dt == 0.0 and drone == self.drone:
            return self
        cols = {k: getattr(self.pieces, k) for k in _PIECE_COLUMNS}
        cols["t0"] = cols["t0"] + dt
        cols["t1"] = cols["t1"] + dt
        cols["drone"] = np.full(len(self.pieces), drone, dtype=np.int64)
        return replace(self, drone=drone, pieces=Pieces(**cols),
                       phases=tuple(Phase(p.name, p.start + dt, p.end + dt)
                                    for p in self.phases),
                       landing_request=self.landing_request + dt)

    def with_loiters(self, n: int) -> FlightPlan:
        """This plan with ``n`` more loiter circles before the approach: the approach
        and everything after it (pieces and phases) ``n * loiter_seconds`` later."""
        if not (isinstance(n, int | np.integer) and n >= 0):
            raise OptionError(f"n={n!r} must be a whole number >= 0", param="n")
        if n == 0:
            return self
        t_ask = self.cleared
        shift = n * self.loiter_seconds
        p = self.pieces
        later = p.t0 >= t_ask
        cols = {k: getattr(p, k) for k in _PIECE_COLUMNS}
        cols["t0"] = np.where(later, p.t0 + shift, p.t0)
        cols["t1"] = np.where(later, p.t1 + shift, p.t1)
        # circle k over [t_ask + k T, t_ask + (k + 1) T]; the last ends exactly where the
        # shifted approach starts
        ends = [t_ask + k * self.loiter_seconds for k in range(n)] + [t_ask + shift]
        circles = Pieces.from_rows([self._circle(ends[k], ends[k + 1]) for k in range(n)])
        pieces = Pieces.concat([Pieces(**cols), circles])
        order = pieces.order()
        pieces = Pieces(**{k: getattr(pieces, k)[order] for k in cols})
        phases = []
        for ph in self.phases:
            if ph.name == "loiter":
                phases.append(Phase("loiter", ph.start, ph.end + shift))
            elif ph.start >= t_ask:
                if ph.name == "approach" and phases[-1].name != "loiter":
                    phases.append(Phase("loiter", t_ask, t_ask + shift))
                phases.append(Phase(ph.name, ph.start + shift, ph.end + shift))
            else:
                phases.append(ph)
        return replace(self, phases=tuple(phases), pieces=pieces, loiters=self.loiters + n)


def gate_position(airport: Airport, gate: int) -> np.ndarray:
    """(north, east) of gate 0 or 1: where the airport's ``gates`` put it, else gate 0
    ``gate_width / 2`` left of the airport's position (seen along the take-off runway's
    heading) and gate 1 as far right."""
    if gate not in (0, 1):
        raise OptionError(f"gate={gate!r} is not valid; choose 0 or 1", param="gate")
    if airport.gates is not None:
        return np.array(airport.gates[gate], dtype=float)
    h = math.radians(airport.takeoff.heading_deg)
    right = np.array([-math.sin(h), math.cos(h)])
    return np.array([airport.north, airport.east]) + (gate - 0.5) * airport.gate_width * right


def plan_flight(scenario: Scenario, drone: int, origin: str, destination: str, *,
                depart: float, altitude: float, origin_gate: int = 0,
                destination_gate: int = 0, loiter_side: str = "left") -> FlightPlan:
    """The :class:`FlightPlan` of drone ``drone`` from airport ``origin`` to
    ``destination`` (ids of ``scenario``), leaving the gate at ``depart`` (s), cruising at
    ``altitude`` (m, >= 50: the seed's take-off regression starts there)."""
    check_choice("loiter_side", loiter_side, LOITER_SIDES)
    if origin == destination:
        raise OptionError(f"destination={destination!r} is the origin; a flight joins two "
                          "airports", param="destination")
    a, b = scenario.airport(origin), scenario.airport(destination)
    t = float(depart)
    if not math.isfinite(t):
        raise OptionError(f"depart={depart!r} must be a finite number", param="depart")
    h = float(altitude)
    if not (math.isfinite(h) and h >= MIN_CRUISE_ALTITUDE):
        raise OptionError(f"altitude={altitude!r} must be >= {MIN_CRUISE_ALTITUDE:g} m (the "
                          "seed's take-off regression starts there)", param="altitude")
    d = scenario.drone
    for name, gate in (("origin_gate", origin_gate), ("destination_gate", destination_gate)):
        if gate not in (0, 1):
            raise OptionError(f"{name}={gate!r} is not valid; choose 0 or 1", param=name)

    def taxi(distance: float, gate_width: float) -> float:
        return taxi_seconds(distance, gate_width, fast=d.taxi_speed,
                            near=d.taxi_near_speed, slow=d.taxi_gate_speed)

    phases: list[Phase] = []

    def add(name: str, seconds: float) -> float:
        start = phases[-1].end if phases else t
        phases.append(Phase(name, start, start + seconds))
        return start + seconds

    # taxi out and take-off roll, on the ground
    thr, _ = runway_ends(a, a.takeoff)
    pos_a = np.array([a.north, a.east])
    route_out = np.array([gate_position(a, origin_gate), pos_a, thr])
    add("taxi_out", taxi(_polyline_length(route_out), a.gate_width))
    psi_up = math.radians(a.takeoff.heading_deg)
    u_up = np.array([math.cos(psi_up), math.sin(psi_up)])
    roll, roll_s, climb, climb_s = takeoff_phases(h, d.climb_angle_deg, d.landing_speed,
                                                  d.cruise_speed)
    overrun = takeoff_overrun(scenario, a, h)
    if overrun is not None:
        raise QueryError(overrun, param="altitude")
    lift_off = thr + roll * u_up
    t_lift = add("takeoff", roll_s)

    # climb: one straight piece from the lift-off point to the climb-out point
    top = lift_off + climb * u_up
    check_climb_out(scenario, a, h)
    tr = Trajectory(drone, t_lift, (*lift_off, 0.0))
    tr.line_to(add("climb", climb_s), (*top, h))

    # cruise: the Dubins path in the plane (x east, y north) to the approach gate
    land_thr, _ = runway_ends(b, b.landing)
    psi_down = math.radians(b.landing.heading_deg)
    u_down = np.array([math.cos(psi_down), math.sin(psi_down)])
    final = h / math.tan(math.radians(d.glide_angle_deg))
    gate = land_thr - final * u_down
    r, v = d.turn_radius, d.cruise_speed
    side = check_arrival(scenario, b, h, loiter_side)  # the final, the loiter's side
    plane_start = (top[1], top[0], float(heading_to_plane(psi_up, "ned")))
    plane_goal = (gate[1], gate[0], float(heading_to_plane(psi_down, "ned")))
    path = shortest_path(plane_start, plane_goal, r)
    route = nofly.cruise(scenario, plane_start, plane_goal, r, path,  # around no-fly zones
                         what=f"flight {origin} -> {destination} at {h:g} m")
    psi = psi_up  # compass heading (radians) along the way
    clock = tr.t
    for letter, length in route:
        if not length > 1e-9:  # a turn of float noise (the word's unused letter)
            continue
        clock += length / v
        if letter == "S":
            tr.line(clock, (v * math.cos(psi), v * math.sin(psi), 0.0))
            continue
        side = 1.0 if letter == "R" else -1.0  # R: centre on the right, clockwise
        n0, e0, _ = tr.position
        centre = (n0 - side * r * math.sin(psi), e0 + side * r * math.cos(psi))
        tr.arc(clock, centre, side * v / r)
        psi += side * length / r
    # the phase ends where the last piece does (the sum of the segments' times)
    phases.append(Phase("cruise", phases[-1].end, clock))
    t_ask = clock

    # the loiter circle through the approach gate, tangent to the approach course
    loiter_centre = _loiter_centre(gate, psi_down, r, side)

    # approach: one straight glide from the approach gate to the threshold
    slope = math.hypot(final, h)
    t_down = add("approach", slope / d.landing_speed)
    # restart the builder at the exact gate (the cruise ends within rounding of it) so
    # the glide and every loiter circle start from one point; no time passes
    tr.ground(t_ask, (*gate, h)).line_to(t_down, (*land_thr, 0.0))
    add("landing", 0.0)

    # roll-out and taxi in, on the ground
    stop = land_thr + d.rollout * u_down
    add("rollout", rollout_seconds(d.landing_speed, d.rollout))
    route_in = np.array([stop, [b.north, b.east], gate_position(b, destination_gate)])
    add("taxi_in", taxi(_polyline_length(route_in), b.gate_width))

    for arr in (route_out, route_in):
        arr.setflags(write=False)
    rolls = (np.array([thr, lift_off]), np.array([land_thr, stop]))
    for arr in rolls:
        arr.setflags(write=False)
    return FlightPlan(
        drone=int(drone), origin=origin, destination=destination,
        origin_gate=int(origin_gate), destination_gate=int(destination_gate), altitude=h,
        phases=tuple(phases), pieces=tr.pieces(), landing_request=t_ask,
        loiter_seconds=2 * math.pi * r / v, loiters=0, cruise_path=path,
        approach_gate=(float(gate[0]), float(gate[1]), h), approach_heading=psi_down,
        loiter_centre=loiter_centre, loiter_rate=side * v / r,
        taxi_out_route=route_out, taxi_in_route=route_in,
        takeoff_roll=rolls[0], rollout_roll=rolls[1], aircraft=d,
        gate_widths=(a.gate_width, b.gate_width))


def check_climb_out(scenario: Scenario, airport: Airport, altitude: float) -> None:
    """A QueryError naming the airport and the zone when the straight climb from
    ``airport``'s lift-off point to ``altitude`` (along its take-off heading) enters a
    no-fly zone; a drone cannot bend it."""
    if not scenario.no_fly_zones:
        return
    d = scenario.drone
    thr, _ = runway_ends(airport, airport.takeoff)
    psi = math.radians(airport.takeoff.heading_deg)
    u = np.array([math.cos(psi), math.sin(psi)])
    roll, _, climb, _ = takeoff_phases(altitude, d.climb_angle_deg, d.landing_speed,
                                       d.cruise_speed)
    lift_off = thr + roll * u
    nofly.check_line(scenario, lift_off, lift_off + climb * u,
                     f"airport {airport.id}'s climb-out to {altitude:g} m")


def check_arrival(scenario: Scenario, airport: Airport, altitude: float,
                  loiter_side: str = "left") -> float:
    """The side of the loiter circle at ``airport`` for a cruise at ``altitude``: -1.0
    (left-hand) or 1.0, ``loiter_side`` unless its circle enters a no-fly zone and the
    other's does not. A QueryError naming the airport and the zones when the final
    approach (a straight glide) enters a zone, or both circles do."""
    side = -1.0 if loiter_side == "left" else 1.0
    if not scenario.no_fly_zones:
        return side
    land_thr, _ = runway_ends(airport, airport.landing)
    psi = math.radians(airport.landing.heading_deg)
    u = np.array([math.cos(psi), math.sin(psi)])
    gate = land_thr - altitude / math.tan(math.radians(scenario.drone.glide_angle_deg)) * u
    nofly.check_line(scenario, gate, land_thr, f"airport {airport.id}'s final approach "
                     f"from {altitude:g} m")
    r = scenario.drone.turn_radius
    names = []
    for s_try in (side, -side):
        name = nofly.circle_crossed(scenario, _loiter_centre(gate, psi, r, s_try), r)
        if name is None:
            return s_try
        names.append(name)
    zones = (f"no-fly zone {names[0]!r}" if names[0] == names[1] else
             f"no-fly zones {names[0]!r} and {names[1]!r}")
    raise QueryError(f"airport {airport.id}: both loiter circles at {altitude:g} m cross "
                     f"{zones}", param="no_fly_zones")


def _loiter_centre(gate, psi_down: float, r: float, side: float) -> tuple[float, float]:
    """Centre (north, east) of the loiter circle through the approach ``gate``, tangent
    to the approach course ``psi_down`` (compass radians), on ``side`` (-1.0 left-hand)."""
    return (float(gate[0] - side * r * math.sin(psi_down)),
            float(gate[1] + side * r * math.cos(psi_down)))


def takeoff_overrun(scenario: Scenario, airport: Airport, altitude: float) -> str | None:
    """Why ``airport``'s take-off runway cannot hold the roll before a climb to
    ``altitude`` (the roll grows with the altitude: the seed's take-off distance less a
    climb at a fixed angle), or None when it can."""
    roll = takeoff_roll(scenario.drone, altitude)
    if roll is None:
        return (f"drone.climb_angle_deg {scenario.drone.climb_angle_deg:g} is too shallow: "
                f"the climb to {altitude:g} m alone is longer than the seed's take-off "
                "distance")
    if roll > airport.takeoff.length:
        return (f"airport {airport.id}'s take-off runway ({airport.takeoff.length:g} m) is "
                f"shorter than the take-off roll to climb to {altitude:g} m ({roll:.0f} m)")
    return None


def ground_position(plan: FlightPlan, t) -> np.ndarray:
    """(north, east) of the drone at times ``t`` (vectorised: shape ``(*t.shape, 2)``) while it
    is on the ground: taxiing (the taxi profile, speeds changing instantly), rolling for
    take-off (even acceleration from rest) or rolling out (even braking to a stop); NaN
    while airborne and outside the flight. At the instant a ground phase meets an
    airborne one (lift-off, touchdown) the ground position is given."""
    t = np.asarray(t, dtype=float)
    out = np.full((*t.shape, 2), np.nan)
    d = plan.aircraft
    speeds = (d.taxi_gate_speed, d.taxi_near_speed, d.taxi_speed)
    for name in ("taxi_out", "takeoff", "rollout", "taxi_in"):
        ph = plan.phase(name)
        at = (t >= ph.start) & (t <= ph.end)
        if not at.any():
            continue
        tau = t[at] - ph.start
        span = ph.end - ph.start
        if name == "taxi_out":
            out[at] = _taxi(plan.taxi_out_route, tau, plan.gate_widths[0], speeds)
        elif name == "taxi_in":
            out[at] = _taxi(plan.taxi_in_route[::-1], span - tau, plan.gate_widths[1],
                            speeds)
        else:
            a, b = plan.takeoff_roll if name == "takeoff" else plan.rollout_roll
            f = tau / span
            f = f * f if name == "takeoff" else 1.0 - (1.0 - f) ** 2
            out[at] = a + f[:, None] * (b - a)
    return out


def _taxi(route: np.ndarray, tau: np.ndarray, gate_width: float, speeds) -> np.ndarray:
    """Points ``tau`` seconds out from the gate (``route[0]``) along ``route``."""
    seg = np.hypot(*np.diff(route, axis=0).T)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    s = np.minimum([0.0, gate_width / 2, gate_width, np.inf], cum[-1])
    times = np.concatenate([[0.0], np.cumsum(np.diff(s) / np.array(speeds))])
    dist = np.interp(tau, times, s)
    return np.stack([np.interp(dist, cum, route[:, 0]), np.interp(dist, cum, route[:, 1])],
                    axis=-1)


def _polyline_length(points: np.ndarray) -> float:
    return float(np.sum(np.hypot(*np.diff(points, axis=0).T)))


def horizontal_lengths(pieces: Pieces) -> np.ndarray:
    """Horizontal distance flown on each piece (metres): ``|v| dt`` on a line,
    ``r |rate| dt`` on an arc."""
    dt = pieces.t1 - pieces.t0
    line = np.hypot(pieces.v_north, pieces.v_east) * dt
    arc = pieces.radius * np.abs(pieces.rate) * dt
    return np.where(pieces.kind == ARC, arc, np.where(pieces.kind == LINE, line, 0.0))
