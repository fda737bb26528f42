"""The fleet simulation: a deterministic discrete-event run of drones carrying packages.

An event heap (time, then insertion order) drives three kinds of events: a package
spawns, a drone becomes ready at a gate, a drone arrives to fetch a package. At each the
dispatcher (:mod:`skyroute.fleet.dispatch`) may pair ready drones with waiting packages;
each pair becomes one or two flights (an empty **reposition** flight to the package's
airport when the drone is elsewhere, then the **delivery** flight).

A flight is released only once it is planned whole (strategic deconfliction): its
departure gate, take-off runway, the airspace of its climb, cruise, loiters and approach
(:class:`~skyroute.fleet.airspace.Reservations`), the landing runway and the arrival gate
are booked before it leaves. The landing is the airport manager's (seed) rule: the drone
asks at the approach gate; the runway is granted only when no other drone is landing
there or still rolling on it and the gate is free for the hand-over; each refusal is one
full loiter circle. Because every booking is known when the flight is released, the
number of circles is decided then, and so is the whole trajectory; when no number of
circles (up to :data:`MAX_LOITERS`), no level (``shared``) and no airspace slot fits,
the departure is held on the ground a little longer and tried again.

Gates hold a drone only for hand-over windows of ``handover_seconds``: unloading after
arrival, loading before departure (which starts once both the drone is free and the
package is assigned; an empty drone that landed to fetch a package loads in the window
it arrived in). Between flights a drone waits on the apron beside the gates (not
tracked); a drone never holds a gate outside its windows.

The run is deterministic: no clock, no unordered iteration, one seeded stream.
"""

from __future__ import annotations

import heapq
import math
import time
from dataclasses import dataclass, field

import numpy as np

from skyroute.errors import OptionError, QueryError, SkyrouteError, check_choice, check_seed
from skyroute.fleet import dispatch, packages
from skyroute.fleet.airborne import MAX_LOITERS, too_long
from skyroute.fleet.airspace import (
    MODES,
    Reservations,
    layer_altitude,
    level_choices,
    samples,
)
from skyroute.fleet.flightplan import (
    FlightPlan,
    check_arrival,
    check_climb_out,
    plan_flight,
    takeoff_overrun,
)
from skyroute.fleet.nofly import check_joined
from skyroute.fleet.packages import TIME_DECIMALS, Stream, horizon_seconds
from skyroute.fleet.scenario import Scenario
from skyroute.fleet.timetable import Timetable
from skyroute.fleet.trajectory import Pieces
from skyroute.geo import heading_to_plane
from skyroute.motion import dubins

WARMUP_SHARE = 0.1
SAMPLE_DT = 1.0
_LOCAL = 4  # optimal dispatch: packages considered per airport beyond the oldest
# ground holds tried before a departure, seconds after the earliest one
_HOLDS = (0, 2, 5, 10, 15, 20, 30, 45, 60, 75, 90, 120, 150, 180, 240, 300,
          *range(360, 4 * 3600 + 1, 60))
_SPAWN, _READY, _FETCH = 0, 1, 2
KINDS = ("spawn", "assign", "pickup", "takeoff", "landing_request", "landing_denied",
         "landing_granted", "touchdown", "delivered")


def written(t) -> np.ndarray:
    """Times ``t`` (seconds) as the run's files write them: to :data:`TIME_DECIMALS`
    places, exactly the floats a reader parses back from ``events.jsonl`` and
    ``packages.csv`` (Python's ``round`` and ``f"{t:.3f}"`` are both correctly
    rounded; numpy's ``round`` is not). NaN stays NaN. The report decides on which side
    of the warm-up and the horizon a time falls on these, so that counts taken from the
    files are its own."""
    t = np.asarray(t, dtype=float)
    return np.array([round(x, TIME_DECIMALS) for x in t.ravel().tolist()],
                    dtype=float).reshape(t.shape)


class SimulationError(SkyrouteError, RuntimeError):
    """The simulation could not go on (a flight found no slot within the hold limit)."""


@dataclass(frozen=True, eq=False)
class Flight:
    """A released flight: its plan, ``kind`` (``reposition`` or ``delivery``), the
    package it carries or goes to fetch, and when it was released."""

    plan: FlightPlan
    kind: str
    package: int
    released: float


@dataclass(eq=False)
class Simulation:
    """What a run produced (filled by :func:`simulate`)."""

    scenario: Scenario
    stream: Stream
    hours: float
    seed: int
    scheduler: str
    airspace: str
    flights: list[Flight] = field(default_factory=list)
    events: list[dict] = field(default_factory=list)
    assigned: np.ndarray | None = None
    pickup: np.ndarray | None = None
    delivered: np.ndarray | None = None
    carrier: np.ndarray | None = None
    wall_seconds: float = 0.0
    rate_per_hour: float | None = None

    @property
    def horizon(self) -> float:
        """Simulated seconds: the run's end, ``hours * 3600`` to the millisecond
        (:func:`~skyroute.fleet.packages.horizon_seconds`), so that no event is written
        after it."""
        return horizon_seconds(self.hours)

    def pieces(self) -> Pieces:
        """Every airborne piece of every flight (whole flights, also past the horizon)."""
        return Pieces.concat([f.plan.pieces for f in self.flights])


def run(scenario: Scenario, *, hours: float, seed: int = 0, scheduler: str = "seed",
        airspace: str | None = None, rate_per_hour: float | None = None,
        base=None, progress=None) -> Simulation:
    """Simulate ``scenario`` for ``hours`` on its own packages
    (:func:`skyroute.fleet.packages.for_scenario`: its CSV, read from ``base``, or the
    Poisson stream of ``seed`` at ``rate_per_hour``, default the scenario's)."""
    _check_scenario(scenario)
    stream = packages.for_scenario(scenario, hours=hours, seed=seed, base=base,
                                   rate_per_hour=rate_per_hour)
    sim = simulate(scenario, stream, hours=hours, seed=seed, scheduler=scheduler,
                   airspace=airspace, progress=progress)
    if scenario.packages.csv is None or rate_per_hour is not None:
        sim.rate_per_hour = (scenario.packages.rate_per_hour if rate_per_hour is None
                             else float(rate_per_hour))
    return sim


def simulate(scenario: Scenario, stream: Stream, *, hours: float, seed: int = 0,
             scheduler: str = "seed", airspace: str | None = None,
             progress=None) -> Simulation:
    """Run ``scenario`` for ``hours`` on the packages of ``stream`` (``seed`` is recorded;
    the stream carries the randomness) with the ``scheduler`` (``seed`` or ``optimal``)
    and ``airspace`` (``layers`` or ``shared``; default the scenario's).
    ``progress(t)`` is called now and then with the simulated time reached."""
    _check_scenario(scenario)
    check_choice("scheduler", scheduler, dispatch.SCHEDULERS)
    mode = scenario.airspace.mode if airspace is None else airspace
    check_choice("airspace", mode, MODES)
    h = packages.check_hours(hours)
    check_levels(scenario, mode)
    check_joined(scenario)  # airports no cruise joins: refused now, not mid-run
    run = Simulation(scenario, stream, h, check_seed(seed), scheduler, mode)
    wall = time.perf_counter()
    _Engine(run, progress).go()
    run.wall_seconds = time.perf_counter() - wall
    return run


def check_levels(scenario: Scenario, airspace: str | None = None, *,
                 where: object = None) -> None:
    """Refuse, before a run, a cruise level of ``airspace`` (default the scenario's mode)
    whose take-off roll some airport's take-off runway cannot hold (the scenario itself
    checks only the lowest level): an :class:`OptionError` naming the airport, the level
    and what to change, after ``where`` (the scenario's file, or ``"scenario"``) when
    given. A flight planned at such a level would roll off the runway."""
    mode = scenario.airspace.mode if airspace is None else airspace
    check_choice("airspace", mode, MODES)
    sp = scenario.airspace
    if mode == "layers":
        levels = [(layer_altitude(sp, d), f"drone {d}'s level in layers")
                  for d in range(scenario.drones)]
        advice = "fly shared, fewer drones or a longer runway"
    else:
        levels = [(sp.base_altitude + k * sp.layer_step, f"one of the {sp.shared_levels} "
                   "shared levels") for k in range(sp.shared_levels)]
        advice = "fewer shared_levels, a smaller layer_step or a longer runway"
    shortest = min(scenario.airports, key=lambda a: (a.takeoff.length, a.id))
    for alt, which in reversed(levels):  # the top level first: the longest roll
        why = takeoff_overrun(scenario, shortest, alt)
        if why is not None:
            raise OptionError(("" if where is None else f"{where}: ")
                              + f"{why}, {which}; {advice}", param="airspace")
    _check_fixed_legs(scenario, levels, where, advice.replace("or a longer runway",
                                                              "or move the zone"))


def _check_fixed_legs(scenario: Scenario, levels, where, advice: str) -> None:
    """Refuse, before a run, a level at which some airport's climb-out, final approach
    or both loiter circles enter a no-fly zone: any flight may use any airport at any
    level of its airspace, and one that did failed the run when it was first planned,
    hours into it, naming neither the file nor the level's drone."""
    if not scenario.no_fly_zones:
        return
    for alt, which in levels:  # the lowest first: the level most flights use
        for a in scenario.airports:
            try:
                check_climb_out(scenario, a, alt)
                check_arrival(scenario, a, alt)
            except QueryError as exc:
                raise OptionError(("" if where is None else f"{where}: ") + "no_fly_zones: "
                                  f"{exc}, {which}; {advice}", param="scenario") from None


def _check_scenario(scenario) -> None:
    if not isinstance(scenario, Scenario):
        raise OptionError(f"scenario must be a Scenario (from load_scenario, "
                          f"parse_scenario, preset or generate), not "
                          f"{type(scenario).__name__}", param="scenario")


class _Engine:
    """The event loop and the state it mutates (one per run)."""

    def __init__(self, run: Simulation, progress) -> None:
        self.run = run
        s = self.s = run.scenario
        self.progress = progress
        self.ids = [a.id for a in s.airports]
        self.index = {a: k for k, a in enumerate(self.ids)}
        self.horizon = run.horizon
        n_pk = len(run.stream)
        run.assigned = np.full(n_pk, np.nan)
        run.pickup = np.full(n_pk, np.nan)
        run.delivered = np.full(n_pk, np.nan)
        run.carrier = np.full(n_pk, -1, dtype=np.int64)
        self.heap: list = []
        self.seq = 0
        self.waiting: list[int] = []  # package ids in spawn order
        n = s.drones
        a = len(s.airports)
        # drone d starts parked at airport d mod a, gate (d // a) mod 2, ready at 0
        self.at = [(d % a, (d // a) % 2) for d in range(n)]
        self.ready_at = [0.0] * n
        self.idle: set[int] = set()  # ready drones (each gets a _READY at 0)
        self.job = [-1] * n  # the package a busy drone is fetching or carrying
        self.next_free: dict[int, float] = {}  # delivering drones: ready time (optimal)
        self.heading: dict[tuple[int, int], int] = {}
        self.gates = [[Timetable(f"gate {i} {g}") for g in (0, 1)] for i in self.ids]
        self.landing = [Timetable(f"landing runway {i}") for i in self.ids]
        self.takeoff = [Timetable(f"take-off runway {i}") for i in self.ids]
        d = s.drone
        self.res = Reservations(sep_horizontal=s.airspace.sep_horizontal,
                                sep_vertical=s.airspace.sep_vertical, dt=SAMPLE_DT,
                                speed_bound=d.cruise_speed,
                                climb_bound=d.cruise_speed * math.sin(
                                    math.radians(max(d.climb_angle_deg,
                                                     d.glide_angle_deg))))
        self.handover = s.handover_seconds
        self.templates: dict[tuple, tuple] = {}
        self.travel = self._travel_times()

    # -- events -------------------------------------------------------------------
    def push(self, t: float, kind: int, a: int) -> None:
        heapq.heappush(self.heap, (t, self.seq, kind, a))
        self.seq += 1

    def log(self, t: float, kind: str, *, drone=None, package=None, airport=None,
            gate=None) -> None:
        if t > self.horizon:
            return
        e = {"t": round(float(t), TIME_DECIMALS), "kind": kind}
        if drone is not None:
            e["drone"] = int(drone)
        if package is not None:
            e["package"] = int(package)
        if airport is not None:
            e["airport"] = self.ids[airport]
        if gate is not None:
            e["gate"] = int(gate)
        self.run.events.append((float(t), len(self.run.events), e))

    def go(self) -> None:
        st = self.run.stream
        # the drones' first READY before any spawn: at t = 0 a package must not be
        # given to a drone that a later READY would then mark idle again
        for d in range(self.s.drones):
            self.push(0.0, _READY, d)
        for p in range(len(st)):
            if st.t[p] < self.horizon:
                self.push(float(st.t[p]), _SPAWN, p)
        count = 0
        while self.heap:
            t, _, kind, a = heapq.heappop(self.heap)
            if t > self.horizon:
                break
            self.now = t
            if kind == _SPAWN:
                self.waiting.append(a)
                p = a
                self.log(t, "spawn", package=p, airport=int(st.origin[p]),
                         gate=int(st.origin_gate[p]))
            elif kind == _READY:
                self.idle.add(a)
                self.job[a] = -1
                self.next_free.pop(a, None)
                for key in [k for k, v in self.heading.items() if v == a]:
                    del self.heading[key]
            else:  # _FETCH: the drone is at the package's gate; fly it
                self._deliver(a, self.job[a], t)
            self._dispatch(t)
            count += 1
            if count % 256 == 0:
                self._forget(t)
                if self.progress is not None:
                    self.progress(t)
        if self.progress is not None:
            self.progress(self.horizon)
        self.run.events = [e for _, _, e in sorted(self.run.events, key=lambda x: x[:2])]

    def _forget(self, t: float) -> None:
        before = t - self.handover - 1.0
        for tt in (*self.landing, *self.takeoff, *(g for pair in self.gates for g in pair)):
            tt.forget(before)
        self.res.forget(t - 10.0)

    # -- dispatch -----------------------------------------------------------------
    def _dispatch(self, now: float) -> None:
        if not self.waiting or not self.idle:
            return
        st = self.run.stream
        if self.run.scheduler == "seed":
            pairs = dispatch.seed(
                packages=[(p, int(st.origin[p]), int(st.origin_gate[p]),
                           int(st.destination[p]), int(st.destination_gate[p]))
                          for p in self.waiting],
                drones=[(d, *self.at[d]) for d in sorted(self.idle)],
                travel=self.travel, heading=self.heading)
        else:
            # a bounded window, the oldest packages (age wins ties of distance) and the
            # soonest-ready drones, keeps the assignment small: its cost grows with the
            # cube of its size
            idle = sorted(self.idle)
            k = 8 * len(idle) + 16
            soon = sorted(self.next_free.items(), key=lambda x: (x[1], x[0]))[:4 * k]
            drones = [(d, self.at[d][0], now) for d in idle]
            drones += [(d, self.at[d][0], r) for d, r in soon]
            # the oldest packages, and the oldest few at every airport a drone is (or
            # lands) at: a long queue must not hide the packages a drone need not fly
            # empty to fetch
            here = {a for _, a, _ in drones}
            per: dict[int, int] = {}
            chosen = []
            for j, p in enumerate(self.waiting):
                a = int(st.origin[p])
                if j < k or (a in here and per.get(a, 0) < _LOCAL):
                    chosen.append(p)
                    per[a] = per.get(a, 0) + 1
            pairs = dispatch.optimal(
                now=now, packages=[(p, int(st.origin[p]), float(st.t[p])) for p in chosen],
                drones=drones, travel=self.travel)
        for d, p in pairs:
            self._assign(d, p, now)

    def _assign(self, d: int, p: int, now: float) -> None:
        st = self.run.stream
        self.waiting.remove(p)
        self.idle.discard(d)
        self.job[d] = p
        self.run.assigned[p] = now
        self.log(now, "assign", drone=d, package=p)
        a, g = int(st.origin[p]), int(st.origin_gate[p])
        if self.run.scheduler == "seed":
            self.heading[(int(st.destination[p]), int(st.destination_gate[p]))] = d
        start = max(now, self.ready_at[d])
        if self.at[d][0] == a:
            self._deliver(d, p, now)
            return
        if self.run.scheduler == "seed":
            self.heading[(a, g)] = d
        f = self._release(d, a, g, start, "reposition", p)
        self.push(f.at_gate, _FETCH, d)

    def _deliver(self, d: int, p: int, earliest: float) -> None:
        st = self.run.stream
        key = (int(st.origin[p]), int(st.origin_gate[p]))
        if self.heading.get(key) == d:  # it has arrived; another's claim on the gate stays
            del self.heading[key]
        # loading takes the hand-over window before departure, once both the drone is
        # free at the airport and the package is there to load
        f = self._release(d, int(st.destination[p]), int(st.destination_gate[p]),
                          max(earliest, self.ready_at[d]) + self.handover, "delivery", p,
                          gate=int(st.origin_gate[p]))
        self.run.pickup[p] = f.depart
        self.run.carrier[p] = d
        self.log(f.depart, "pickup", drone=d, package=p, airport=int(st.origin[p]),
                 gate=int(st.origin_gate[p]))
        done = f.at_gate + self.handover
        self.run.delivered[p] = done
        self.log(done, "delivered", drone=d, package=p, airport=int(st.destination[p]),
                 gate=int(st.destination_gate[p]))
        if self.run.scheduler == "optimal":
            self.next_free[d] = done
        self.push(done, _READY, d)

    # -- flights ------------------------------------------------------------------
    def _template(self, o: int, og: int, b: int, bg: int, alt: float):
        key = (o, og, b, bg, alt)
        tpl = self.templates.get(key)
        if tpl is None:
            plan = plan_flight(self.s, 0, self.ids[o], self.ids[b], depart=0.0, altitude=alt,
                               origin_gate=og, destination_gate=bg)
            # before the flight is sampled each second (fleet.airborne): a scenario read
            # from a file was checked on its farthest airports, this is every flight
            sp = self.s.airspace
            error = too_long(self.s, o, b, round((alt - sp.base_altitude) / sp.layer_step),
                             plan)
            if error:
                raise SimulationError(f"scenario: {error}")
            # on the take-off runway from the airport's position to lift-off; on the
            # landing runway from the start of the approach until the drone has rolled
            # out and taxied back to the airport's position: both timed on the taxi
            # profile (slow near a gate; the airport's position is half a gate width
            # from its gates), not at the full taxi speed, which put the drone on the
            # take-off runway before its booking and on the landing runway after it
            on_rwy, off_rwy = plan.out_at_position, plan.in_at_position
            tpl = (plan, on_rwy, plan.phase("takeoff").end, plan.landing_request, off_rwy,
                   plan.at_gate)
            self.templates[key] = tpl
        return tpl

    def _levels(self, d: int, o: int, b: int) -> list[float]:
        if self.run.airspace == "layers":
            return [layer_altitude(self.s.airspace, d)]
        ao, ab = self.s.airports[o], self.s.airports[b]
        bearing = math.degrees(math.atan2(ab.east - ao.east, ab.north - ao.north))
        return level_choices(self.s.airspace, bearing)

    def _release(self, d: int, b: int, bg: int, earliest: float, kind: str, p: int, *,
                 gate: int | None = None) -> FlightPlan:
        """Plan, book and log the flight of drone ``d`` from where it is (leaving by its
        own gate, or ``gate`` of the same airport) to airport ``b`` gate ``bg``."""
        o = self.at[d][0]
        og = self.at[d][1] if gate is None else gate
        H = self.handover
        loiter_s = 2 * math.pi * self.s.drone.turn_radius / self.s.drone.cruise_speed
        gate_out = self.gates[o][og]
        for hold in _HOLDS:
            dep = earliest + hold
            if not gate_out.free(dep - H, dep, owner=d):
                continue
            for alt in self._levels(d, o, b):
                plan, on_rwy, lift, ask, off_rwy, at_gate = self._template(o, og, b, bg, alt)
                if not self.takeoff[o].free(dep + on_rwy, dep + lift):
                    continue
                for k in range(MAX_LOITERS + 1):
                    shift = dep + k * loiter_s
                    if (self.landing[b].free(ask + shift, off_rwy + shift)
                            and self.gates[b][bg].free(at_gate + shift, at_gate + shift + H,
                                                       owner=d)):
                        break
                else:
                    continue
                fp = plan.shifted(dep, drone=d).with_loiters(k)
                k0, S = samples(fp.pieces, SAMPLE_DT)
                if not self.res.clear(d, k0, S):
                    continue
                self.res.add(d, k0, S)
                gate_out.book(dep - H, dep, owner=d)
                self.takeoff[o].book(dep + on_rwy, dep + lift, owner=d)
                shift = dep + k * loiter_s
                self.landing[b].book(ask + shift, off_rwy + shift, owner=d)
                self.gates[b][bg].book(at_gate + shift, at_gate + shift + H, owner=d)
                self._record(d, fp, kind, p, o, b, bg, loiter_s)
                self.at[d] = (b, bg)
                # free after unloading a delivery; an empty drone at once (it loads in
                # the window it arrived in)
                self.ready_at[d] = fp.at_gate + (H if kind == "delivery" else 0.0)
                return fp
        raise SimulationError(f"drone {d}: no slot for a flight {self.ids[o]} -> "
                              f"{self.ids[b]} within {_HOLDS[-1] / 3600:g} h of "
                              f"t={earliest:.0f} s")

    def _record(self, d, fp: FlightPlan, kind, p, o, b, bg, loiter_s) -> None:
        self.run.flights.append(Flight(fp, kind, p, self.now))
        carried = p if kind == "delivery" else None
        self.log(fp.phase("takeoff").end, "takeoff", drone=d, package=carried, airport=o)
        for j in range(fp.loiters + 1):  # asks at the approach gate, one per circle
            ask = fp.landing_request + j * loiter_s
            self.log(ask, "landing_request", drone=d, package=carried, airport=b, gate=bg)
            if j < fp.loiters:
                self.log(ask, "landing_denied", drone=d, package=carried, airport=b,
                         gate=bg)
        self.log(fp.cleared, "landing_granted", drone=d, package=carried, airport=b, gate=bg)
        self.log(fp.touchdown, "touchdown", drone=d, package=carried, airport=b)

    # -- travel times -------------------------------------------------------------
    def _travel_times(self) -> np.ndarray:
        """Gate-to-gate seconds between airports at the lowest level plus a hand-over:
        the dispatcher's estimate of a flight. The time to the climb-out point depends
        on the origin only and the time from the approach gate on the destination only;
        the Dubins cruise between them is one vectorised call over all pairs."""
        a = len(self.ids)
        alt = self.s.airspace.base_altitude
        d = self.s.drone
        out_s, in_s = np.zeros(a), np.zeros(a)
        top, gate = np.zeros((a, 3)), np.zeros((a, 3))
        for i in range(a):
            f = self._template(i, 0, (i + 1) % a, 0, alt)[0]
            out_s[i] = f.phase("climb").end - f.depart
            n, e, _ = f.pieces.end()[0]  # the climb's end
            top[i] = e, n, heading_to_plane(math.radians(self.s.airports[i].takeoff
                                                         .heading_deg), "ned")
            g = self._template((i + 1) % a, 0, i, 0, alt)[0]
            in_s[i] = g.at_gate - g.landing_request
            gn, ge, _ = g.approach_gate
            gate[i] = ge, gn, heading_to_plane(g.approach_heading, "ned")
        starts = np.repeat(top, a, axis=0)
        goals = np.tile(gate, (a, 1))
        cruise = dubins.lengths(starts, goals, d.turn_radius).reshape(a, a) / d.cruise_speed
        out = out_s[:, None] + cruise + in_s[None, :] + self.handover
        np.fill_diagonal(out, 0.0)
        return out
