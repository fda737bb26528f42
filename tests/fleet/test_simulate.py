"""The fleet simulation against the issue's matrix: the three presets, five seeds, both
airspaces and both dispatchers, two simulated hours each.

Every property is checked from what a run left behind (its flights and its event log),
never from the engine's own bookkeeping: conflicts by the independent separation
checker, landings and gate hand-overs as intervals rebuilt from the flight plans and
again from the events, continuity of each flight's pieces, each drone's flights in
sequence, pickups and deliveries at the stream's gates. Each configuration is simulated
once per session (``simulated``); a re-run per preset must give byte-identical events.
Then a property test on small generated scenarios, and the soundness of the sampled
airspace reservations against the exact checker.
"""

from __future__ import annotations

import itertools
import json
import math

import numpy as np
import pytest
from hypothesis import given, settings, target
from hypothesis import strategies as st

from skyroute.fleet.airspace import Reservations, samples
from skyroute.fleet.packages import Stream
from skyroute.fleet.report import report
from skyroute.fleet.scenario import generate, preset
from skyroute.fleet.separation import check
from skyroute.fleet.simulate import Simulation, run, simulate
from skyroute.fleet.trajectory import Pieces, Trajectory, check_continuous

PRESETS = ("seed-3x3", "seed-9x9", "seed-18x9")
SEEDS = range(5)
HOURS = 2.0
CONFIGS = [(name, seed, scheduler, airspace) for name in PRESETS
           for scheduler in ("seed", "optimal") for airspace in ("layers", "shared")
           for seed in SEEDS]
_RUNS: dict[tuple, tuple[Simulation, dict]] = {}


def simulated(name: str, seed: int, scheduler: str, airspace: str) -> tuple[Simulation, dict]:
    """The run of one configuration and its report, simulated once per session."""
    key = (name, seed, scheduler, airspace)
    if key not in _RUNS:
        sim = run(preset(name), hours=HOURS, seed=seed, scheduler=scheduler,
                  airspace=airspace)
        _RUNS[key] = sim, report(sim)
    return _RUNS[key]


def config_id(c) -> str:
    return "-".join(map(str, c))


@pytest.fixture(scope="module", params=CONFIGS, ids=config_id)
def config(request) -> tuple[Simulation, dict]:
    """Module scope: pytest runs each configuration's tests one after another, so
    pytest-xdist hands them to one process in one batch; with a function scope it ran
    them test by test over all 60 configurations, and both processes simulated most of
    them (about 30 s of CPU twice)."""
    return simulated(*request.param)


def overlapping(intervals) -> list[tuple]:
    """Pairs of ``(start, end, owner, ...)`` intervals of different owners that overlap
    (meeting at an end point is not overlapping)."""
    out = []
    for a, b in itertools.combinations(sorted(intervals), 2):
        if a[2] != b[2] and a[0] < b[1] and b[0] < a[1]:
            out.append((a, b))
    return out


def by_key(items, key) -> dict:
    out: dict = {}
    for it in items:
        out.setdefault(key(it), []).append(it)
    return out


# ------------------------------------------------------------------ the matrix

def test_no_conflict_and_no_lost_package(config):
    _, rep = config
    assert rep["conflicts"] == 0
    assert rep["lost"] == 0
    assert rep["offered"] > 0 and rep["delivered"] > 0  # the run did something


def busy_spans(sim: Simulation) -> list[tuple[float, float]]:
    """From the events: each drone is busy from an ``assign`` until that package's
    ``delivered`` (or the horizon)."""
    done = {e["package"]: e["t"] for e in sim.events if e["kind"] == "delivered"}
    return [(e["t"], done.get(e["package"], math.inf)) for e in sim.events
            if e["kind"] == "assign"]


def idle_gaps(spans, horizon: float) -> list[tuple[float, float]]:
    """The open stretches of ``[0, horizon]`` that no span covers."""
    gaps, reach = [], 0.0
    for a, b in sorted(spans):
        if a > reach:
            gaps.append((reach, a))
        reach = max(reach, b)
    if reach < horizon:
        gaps.append((reach, horizon))
    return gaps


def test_no_deadlock_no_package_waits_while_every_drone_is_idle(config):
    # The presets offer about twice what their fleets can carry (the seed's own load), so
    # the queue grows and "every package of the first hour delivered" cannot hold there
    # (see the below-capacity test); a deadlock shows instead as a package waiting while
    # every drone stands idle, or a drone held on the ground without end.
    sim, _ = config
    assigned = {e["package"]: e["t"] for e in sim.events if e["kind"] == "assign"}
    waits = [(e["t"], assigned.get(e["package"], sim.horizon), e["package"])
             for e in sim.events if e["kind"] == "spawn"]
    for g0, g1 in idle_gaps(busy_spans(sim), sim.horizon):
        stuck = [p for s, a, p in waits if s < g1 and a > g0 and a > s]
        assert not stuck, f"packages {stuck[:5]} wait while every drone is idle in " \
                          f"({g0}, {g1})"
    H = sim.scenario.handover_seconds
    for drone, flights in by_key(sim.flights, lambda f: f.plan.drone).items():
        ready = 0.0
        for f in sorted(flights, key=lambda f: f.plan.depart):
            hold = f.plan.depart - max(f.released, ready)
            assert hold <= 900.0, f"drone {drone} held {hold:.0f} s on the ground"
            ready = f.plan.at_gate + H


BELOW_CAPACITY = {"seed-3x3": 18.0, "seed-9x9": 40.0, "seed-18x9": 80.0}  # about half


@pytest.mark.parametrize("name, seed, scheduler, airspace", CONFIGS,
                         ids=[config_id(c) for c in CONFIGS])
def test_below_capacity_every_package_of_the_first_hour_is_delivered(name, seed, scheduler,
                                                                      airspace):
    sim = run(preset(name), hours=HOURS, seed=seed, scheduler=scheduler, airspace=airspace,
              rate_per_hour=BELOW_CAPACITY[name])
    early = np.flatnonzero(sim.stream.t < sim.horizon - 3600.0)
    delivered = {e["package"]: e["t"] for e in sim.events if e["kind"] == "delivered"}
    late = [int(p) for p in early if p not in delivered]
    assert not late, f"spawned before the last hour, not delivered: {late[:10]}"
    assert all(delivered[int(p)] <= sim.horizon for p in early)
    rep = report(sim)
    assert rep["conflicts"] == 0 and rep["lost"] == 0


def test_one_landing_at_a_time_per_airport_from_the_flights(config):
    sim, _ = config
    # the runway is the landing drone's from the start of its glide to the end of its
    # roll-out
    spans = [(f.plan.phase("approach").start, f.plan.phase("rollout").end, f.plan.drone)
             for f in sim.flights]
    airports = [f.plan.destination for f in sim.flights]
    for airport, group in by_key(zip(airports, spans, strict=True), lambda x: x[0]).items():
        clash = overlapping([s for _, s in group])
        assert not clash, f"two landings at {airport}: {clash[:3]}"


def test_one_landing_at_a_time_per_airport_from_the_events(config):
    sim, _ = config
    spans = []
    for drone, evs in by_key([e for e in sim.events if e["kind"] in
                              ("landing_granted", "touchdown")], lambda e: e["drone"]).items():
        granted = None
        for e in evs:
            if e["kind"] == "landing_granted":
                assert granted is None, f"drone {drone} granted twice without landing"
                granted = e
            else:
                assert granted is not None and granted["airport"] == e["airport"]
                spans.append((granted["t"], e["t"], drone, e["airport"]))
                granted = None
        if granted is not None:  # still gliding at the horizon
            spans.append((granted["t"], math.inf, drone, granted["airport"]))
    for airport, group in by_key(spans, lambda s: s[3]).items():
        clash = overlapping(group)
        assert not clash, f"two landings at {airport}: {clash[:3]}"


def test_pickups_and_deliveries_at_the_stream_gates(config):
    sim, _ = config
    st_ = sim.stream
    ids = [a.id for a in sim.scenario.airports]
    n = 0
    for e in sim.events:
        if e["kind"] == "pickup":
            p = e["package"]
            assert (e["airport"], e["gate"]) == (ids[st_.origin[p]], st_.origin_gate[p])
        elif e["kind"] == "delivered":
            p = e["package"]
            n += 1
            assert (e["airport"], e["gate"]) == (ids[st_.destination[p]],
                                                 st_.destination_gate[p])
    assert n > 0
    # the delivery flights themselves join the package's two gates
    for f in sim.flights:
        if f.kind == "delivery":
            p, fp = f.package, f.plan
            assert (fp.origin, fp.origin_gate) == (ids[st_.origin[p]], st_.origin_gate[p])
            assert (fp.destination, fp.destination_gate) == (ids[st_.destination[p]],
                                                             st_.destination_gate[p])


def test_each_flight_is_continuous(config):
    sim, _ = config
    for f in sim.flights:
        check_continuous(f.plan.pieces, tolerance=1e-6)
        p = f.plan.pieces
        assert p.t0.min() == f.plan.phase("climb").start
        assert p.t1.max() == f.plan.touchdown


def test_a_drone_flies_one_flight_at_a_time_from_where_it_landed(config):
    sim, _ = config
    s = sim.scenario
    H = s.handover_seconds
    for drone, flights in by_key(sim.flights, lambda f: f.plan.drone).items():
        flights = sorted(flights, key=lambda f: f.plan.depart)
        # it starts at the airport the engine parks it at (drone d at airport d mod a)
        assert flights[0].plan.origin == s.airports[drone % len(s.airports)].id
        for a, b in itertools.pairwise(flights):
            assert b.plan.depart >= a.plan.at_gate, f"drone {drone} flies two at once"
            assert b.plan.origin == a.plan.destination, f"drone {drone} jumps airports"
            if a.kind == "delivery":  # it leaves only once the package is handed over
                assert b.plan.depart >= a.plan.at_gate + H


def test_a_drone_takes_one_package_at_a_time(config):
    sim, _ = config
    for drone, evs in by_key([e for e in sim.events if e["kind"] in ("assign", "delivered")],
                             lambda e: e["drone"]).items():
        kinds = [e["kind"] for e in evs]
        assert kinds[::2] == ["assign"] * len(kinds[::2]), f"drone {drone}: {kinds}"
        assert kinds[1::2] == ["delivered"] * len(kinds[1::2]), f"drone {drone}: {kinds}"
        assert all(a["package"] == b["package"] for a, b in zip(evs[::2], evs[1::2],
                                                                 strict=False))


def test_a_gate_holds_one_drone_at_a_time(config):
    sim, _ = config
    H = sim.scenario.handover_seconds
    windows = []
    for f in sim.flights:
        fp = f.plan
        windows.append((fp.depart - H, fp.depart, fp.drone, fp.origin, fp.origin_gate))
        windows.append((fp.at_gate, fp.at_gate + H, fp.drone, fp.destination,
                        fp.destination_gate))
    for gate, group in by_key(windows, lambda w: w[3:]).items():
        clash = overlapping(group)
        assert not clash, f"two drones at gate {gate}: {clash[:3]}"


@pytest.mark.parametrize("cfg", [c for c in CONFIGS if c[2] == "seed"], ids=config_id)
def test_seed_rule_sends_one_drone_at_a_time_to_a_gate(cfg):
    # the seed's rule: a drone flying to a gate (to fetch there, or to deliver there)
    # holds it from its assignment until it has arrived (fetch) or handed over (delivery);
    # times as the event log rounds them
    sim, _ = simulated(*cfg)
    ids = [a.id for a in sim.scenario.airports]
    st_ = sim.stream
    times = {(e["kind"], e["package"]): e["t"] for e in sim.events
             if e["kind"] in ("assign", "delivered")}
    heading = []
    for f in sim.flights:
        p, fp = f.package, f.plan
        start = times[("assign", p)]
        if f.kind == "reposition":
            heading.append((start, round(fp.at_gate, 3), fp.drone, ids[st_.origin[p]],
                            int(st_.origin_gate[p])))
        else:
            heading.append((start, times.get(("delivered", p), math.inf), fp.drone,
                            fp.destination, fp.destination_gate))
    for gate, group in by_key(heading, lambda w: w[3:]).items():
        clash = overlapping(group)
        assert not clash, f"two drones heading to gate {gate}: {clash[:3]}"


@pytest.mark.parametrize("name, scheduler, airspace", [
    ("seed-3x3", "seed", "layers"), ("seed-9x9", "optimal", "shared"),
    ("seed-18x9", "optimal", "layers")])
def test_a_rerun_gives_identical_events(name, scheduler, airspace):
    first, _ = simulated(name, 1, scheduler, airspace)
    again = run(preset(name), hours=HOURS, seed=1, scheduler=scheduler, airspace=airspace)
    assert json.dumps(again.events) == json.dumps(first.events)


_OTHER_PROCESS = ("import json\n"
                  "from skyroute.fleet.scenario import preset\n"
                  "from skyroute.fleet.simulate import run\n"
                  "sim = run(preset('seed-9x9'), hours=2.0, seed=1, scheduler='optimal', "
                  "airspace='shared')\n"
                  "print(json.dumps(sim.events))\n")


@pytest.mark.early_process("-c", _OTHER_PROCESS)
def test_another_process_gives_identical_events(early_process):
    # another interpreter: another string hash seed, fresh caches
    code, out, err, _ = early_process
    assert code == 0, err
    first, _ = simulated("seed-9x9", 1, "optimal", "shared")
    assert out.strip() == json.dumps(first.events)


# ------------------------------------------------------------------ regressions

def three_packages(t0: float) -> Simulation:
    """Drones 0, 1, 2 parked at A, B, C (gate 0). Drone 0 takes package 0 from A to B's
    gate 1; package 1 leaves from B's gate 1 with drone 1 (parked at B); package 2 wants
    to go from C to B's gate 1, where drone 0 is still heading."""
    s = generate(3, 3, area_km=4.0, seed=0)
    stream = Stream(t=np.array([t0, 10.0, 20.0]), origin=np.array([0, 1, 2]),
                    origin_gate=np.array([0, 1, 1]), destination=np.array([1, 2, 1]),
                    destination_gate=np.array([1, 0, 1]))
    return simulate(s, stream, hours=1.0, scheduler="seed")


@pytest.mark.parametrize("t0", [5.0, 0.0])
def test_seed_rule_a_pickup_does_not_free_another_drones_gate(t0):
    # was: the pickup of package 1 at B's gate 1 dropped drone 0's claim on that gate,
    # and package 2 was sent to it at once
    sim = three_packages(t0)
    ev = {(e["kind"], e["package"]): e for e in sim.events}
    assert [ev[("assign", p)]["drone"] for p in range(3)] == [0, 1, 2]
    assert ev[("assign", 2)]["t"] == ev[("delivered", 0)]["t"]  # it waits for drone 0


def test_a_package_at_time_zero_keeps_its_drone_busy():
    # was: the drones' first READY came after a spawn at t = 0 and marked the drone that
    # had just taken it idle, so it was given package 1 while still carrying package 0
    sim = three_packages(0.0)
    assigned = [(e["drone"], e["package"]) for e in sim.events if e["kind"] == "assign"]
    assert assigned == [(0, 0), (1, 1), (2, 2)]


# ------------------------------------------------------------------ small random fleets

@settings(max_examples=15, deadline=None)
@given(airports=st.integers(2, 5), drones=st.integers(1, 6), area_km=st.floats(3.0, 8.0),
       seed=st.integers(0, 10_000), rate=st.floats(10.0, 150.0),
       scheduler=st.sampled_from(["seed", "optimal"]),
       airspace=st.sampled_from(["layers", "shared"]))
def test_small_random_fleets_keep_separation_and_lose_nothing(airports, drones, area_km, seed,
                                                              rate, scheduler, airspace):
    s = generate(airports, drones, area_km=area_km, seed=seed, rate_per_hour=rate)
    sim = run(s, hours=0.75, seed=seed, scheduler=scheduler, airspace=airspace)
    rep = report(sim)
    assert rep["conflicts"] == 0
    assert rep["lost"] == 0


# ------------------------------------------------------------------ reservations

SH, SV = 50.0, 10.0
SPEED, CLIMB = 50.0, 20.0  # the bounds handed to Reservations: no piece exceeds them


@st.composite
def simple_flight(draw, drone: int) -> Pieces:
    """A short airborne trajectory near the origin: a line (climbing or level), then
    perhaps an arc (a turn or a loiter, climbing or level), speeds within the bounds."""
    t = draw(st.floats(0.0, 20.0))
    start = (draw(st.floats(-300, 300)), draw(st.floats(-300, 300)), draw(st.floats(50, 90)))
    tr = Trajectory(drone, t, start)
    speed = draw(st.floats(5.0, SPEED))
    heading = draw(st.floats(0, 2 * math.pi))
    vz = draw(st.floats(-CLIMB, CLIMB)) * draw(st.sampled_from([0.0, 1.0]))
    vh = math.sqrt(max(speed ** 2 - vz ** 2, 0.0))
    tr.line(t + draw(st.floats(1.0, 40.0)),
            (vh * math.cos(heading), vh * math.sin(heading), vz))
    if draw(st.booleans()):
        radius = draw(st.floats(30.0, 300.0))
        side = draw(st.sampled_from([-1.0, 1.0]))
        n, e, _ = tr.position
        centre = (n - side * radius * math.sin(heading), e + side * radius * math.cos(heading))
        rate = side * draw(st.floats(2.0, SPEED)) / radius
        v_alt = draw(st.floats(-CLIMB, CLIMB)) * draw(st.sampled_from([0.0, 1.0]))
        tr.arc(tr.t + draw(st.floats(1.0, 60.0)), centre, rate, v_alt=v_alt)
    return tr.pieces()


def reserved(a: Pieces, dt: float) -> Reservations:
    res = Reservations(sep_horizontal=SH, sep_vertical=SV, dt=dt, speed_bound=SPEED,
                       climb_bound=CLIMB)
    res.add(int(a.drone[0]), *samples(a, dt))
    return res


@settings(max_examples=300, deadline=None)
@given(a=simple_flight(0), b=simple_flight(1), dt=st.sampled_from([0.5, 1.0, 2.0]))
def test_a_flight_the_reservations_clear_never_conflicts(a, b, dt):
    if not reserved(a, dt).clear(1, *samples(b, dt)):
        return
    rep = check(Pieces.concat([a, b]), sep_horizontal=SH, sep_vertical=SV)
    assert rep.separated, rep.conflicts
    if math.isfinite(rep.min_horizontal_m):  # steer towards the tight passes
        target(-rep.min_horizontal_m, label="closest accepted pass")


def test_reservations_refuse_two_drones_on_one_line_at_one_time():
    line = Trajectory(0, 0.0, (0.0, 0.0, 80.0)).line(60.0, (0.0, 40.0, 0.0)).pieces()
    other = Trajectory(1, 10.0, (0.0, 0.0, 80.0)).line(70.0, (0.0, 40.0, 0.0)).pieces()
    res = reserved(line, 1.0)
    assert res.clear(1, *samples(other, 1.0))  # 400 m behind all along: clear
    same = Trajectory(1, 0.0, (0.0, 0.0, 80.0)).line(60.0, (0.0, 40.0, 0.0)).pieces()
    assert not res.clear(1, *samples(same, 1.0))
    assert res.clear(0, *samples(same, 1.0))  # a drone's own reservation is no obstacle
    assert not check(Pieces.concat([line, same])).separated


def test_reservations_accept_what_is_far_apart_in_space_or_time():
    line = Trajectory(0, 0.0, (0.0, 0.0, 80.0)).line(60.0, (0.0, 40.0, 0.0)).pieces()
    res = reserved(line, 1.0)
    above = Trajectory(1, 0.0, (0.0, 0.0, 120.0)).line(60.0, (0.0, 40.0, 0.0)).pieces()
    later = Trajectory(1, 100.0, (0.0, 0.0, 80.0)).line(160.0, (0.0, 40.0, 0.0)).pieces()
    beside = Trajectory(1, 0.0, (200.0, 0.0, 80.0)).line(60.0, (0.0, 40.0, 0.0)).pieces()
    for b in (above, later, beside):
        assert res.clear(1, *samples(b, 1.0))


@pytest.mark.parametrize("edit, words", [
    (lambda d: d["drone"].update(turn_radius=1e12), "drone.turn_radius: a flight A -> B at "
                                                    "50 m would be airborne up to 4.54e+08 h"),
    (lambda d: d["drone"].update(cruise_speed=0.001, landing_speed=0.0005),
     "drone.cruise_speed: a flight A -> B at 50 m would be airborne up to 6.09e+03 h"),
])
def test_a_flight_airborne_too_long_is_refused_before_it_is_sampled(edit, words):
    # a Scenario made in Python is not checked as a file is: the run checks each flight
    from skyroute.fleet.scenario import Scenario
    from skyroute.fleet.simulate import SimulationError

    data = preset("seed-3x3").model_dump()
    edit(data)
    with pytest.raises(SimulationError, match="over the limit of 12 h") as info:
        run(Scenario.model_validate(data), hours=0.2, seed=0)
    assert str(info.value).startswith("scenario: " + words)


def test_a_scenario_read_with_a_flight_too_long_names_the_file_and_field(tmp_path):
    import yaml

    from skyroute.errors import InputFormatError
    from skyroute.fleet.airborne import check_flights
    from skyroute.fleet.scenario import load_scenario, parse_scenario

    data = preset("seed-3x3").model_dump()
    data["drone"]["turn_radius"] = 1e12
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(InputFormatError) as info:
        check_flights(load_scenario(path), path)
    assert str(info.value).startswith(f"{path}: drone.turn_radius: a flight ")
    assert str(info.value).endswith("over the limit of 12 h (drone.turn_radius is 1e+12)")
    with pytest.raises(InputFormatError, match=r"^scenario: drone\.turn_radius: a flight "):
        check_flights(parse_scenario(data))


def test_a_top_level_whose_roll_overruns_a_runway_is_refused_before_the_run():
    from skyroute.errors import OptionError
    from skyroute.fleet.scenario import Scenario

    data = preset("seed-3x3").model_dump()
    data["airports"][2]["takeoff"]["length"] = 320.0  # holds the roll to 50 m (294 m)
    data["drones"] = 5  # layers: the top drone cruises at 90 m, a 326 m roll
    s = Scenario.model_validate(data)
    with pytest.raises(OptionError) as err:
        run(s, hours=0.2, seed=0, airspace="layers")
    assert str(err.value) == ("airport C's take-off runway (320 m) is shorter than the "
                              "take-off roll to climb to 90 m (326 m), drone 4's level in "
                              "layers; fly shared, fewer drones or a longer runway")
    sim = run(s, hours=0.2, seed=0, airspace="shared")  # its top level is 80 m: 319 m
    assert sim.flights
    # a layer_step of 1e9 m (it reached the 12 h airborne limit, see above) is refused
    # by its roll now, before any flight is planned
    data = preset("seed-3x3").model_dump()
    data["airspace"]["layer_step"] = 1e9
    with pytest.raises(OptionError, match=r"to climb to 2e\+09 m \(679845521 m\), drone "
                                          "2's level in layers"):
        run(Scenario.model_validate(data), hours=0.2, seed=0)


def test_the_airborne_check_skips_levels_no_runway_holds():
    """100 drones on seed-9x9 fly shared (layers would put drone 99 at 1040 m, a roll
    longer than the runways, which check_levels refuses for layers only): the scenario's
    12 h check must not refuse it by planning a flight at that layer."""
    from skyroute.errors import OptionError
    from skyroute.fleet.airborne import check_flights
    from skyroute.fleet.simulate import check_levels

    s = preset("seed-9x9").model_copy(update={"drones": 100})
    check_flights(s, "seed-9x9")
    check_levels(s, "shared")
    with pytest.raises(OptionError, match="drone 99's level in layers"):
        check_levels(s, "layers")


def test_run_names_a_bad_scenario_hours_or_seed():
    # an AttributeError for a dict, numpy's errors for the seed
    from skyroute.errors import OptionError

    with pytest.raises(OptionError, match="scenario must be a Scenario"):
        run({"airports": []}, hours=0.1)
    for kw in ({"hours": "1"}, {"hours": True}, {"seed": "1"}, {"seed": -1}):
        (name, _), = kw.items()
        with pytest.raises(OptionError, match=f"{name}="):
            run(preset("seed-3x3"), **{"hours": 0.1, **kw})
