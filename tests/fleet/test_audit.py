"""``skyroute fleet simulate --out`` against an audit written from docs/fleet.md alone
(tests/fleet/audit.py: it reads only the files and shares no code with the simulator or
its checker), on the presets and on small fleets hypothesis draws, with package
streams it draws too."""

from __future__ import annotations

import csv
import json
import math

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from skyroute.cli.app import app
from skyroute.fleet.scenario import generate, load_scenario, preset, to_yaml
from tests.fleet.audit import audit


def simulate(out, *args) -> dict:
    """Run ``skyroute fleet simulate ... --out out --json``; its report."""
    res = CliRunner().invoke(app, ["fleet", "simulate", *args, "--out", str(out), "--json"])
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout.splitlines()[-1])


# Short runs in which the old runway bookings (the taxi timed at full speed, not on the
# taxi profile that is slow near the gates) put two drones on a take-off runway at once
# (the seed-18x9 runs) and cleared a landing before the drone ahead was back at the
# airport's position (the seed-3x3 run); the seed-9x9 runs passed before too.
PRESET_RUNS = [("seed-3x3", 1, "optimal", "layers", 0.75), ("seed-9x9", 0, "seed", "shared", 0.5),
               ("seed-9x9", 0, "optimal", "layers", 0.5), ("seed-18x9", 0, "seed", "layers", 0.1),
               ("seed-18x9", 0, "optimal", "layers", 0.1)]


@pytest.mark.parametrize("name, seed, scheduler, airspace, hours", PRESET_RUNS,
                         ids=["-".join(map(str, r)) for r in PRESET_RUNS])
def test_preset_runs_keep_every_rule_the_audit_checks(tmp_path, name, seed, scheduler,
                                                      airspace, hours):
    rep = simulate(tmp_path, "--preset", name, "--hours", str(hours), "--seed", str(seed),
                   "--scheduler", scheduler, "--airspace", airspace)
    problems, numbers = audit(tmp_path, preset(name))
    assert problems == []
    assert numbers["delivered"] == rep["delivered"] > 0
    assert numbers["flights"] == rep["flights"]


@st.composite
def fleets(draw):
    """A generated layout, a drone count, and either a Poisson rate or an explicit
    package list (clustered times, both gates, ties at one instant)."""
    airports = draw(st.integers(2, 4))
    s = generate(airports, draw(st.integers(1, 5)), area_km=draw(st.floats(2.5, 5.0)),
                 seed=draw(st.integers(0, 10_000)))
    rows = None
    if draw(st.booleans()):
        n = draw(st.integers(0, 25))
        rows = []
        for _ in range(n):
            a = draw(st.integers(0, airports - 1))
            b = (a + draw(st.integers(1, airports - 1))) % airports
            t = draw(st.one_of(st.sampled_from([0.0, 60.0, 60.0]), st.floats(0.0, 900.0)))
            rows.append((round(t, 3), s.airports[a].id, draw(st.integers(0, 1)),
                         s.airports[b].id, draw(st.integers(0, 1))))
    return (s, rows, draw(st.floats(10.0, 120.0)), draw(st.integers(0, 1000)),
            draw(st.sampled_from(["seed", "optimal"])),
            draw(st.sampled_from(["layers", "shared"])), draw(st.sampled_from([0.2, 0.3])))


@settings(max_examples=12, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture,
                                 HealthCheck.too_slow])
@given(case=fleets())
def test_small_fleets_keep_every_rule_the_audit_checks(tmp_path_factory, case):
    s, rows, rate, seed, scheduler, airspace, hours = case
    d = tmp_path_factory.mktemp("fleet")
    data = yaml.safe_load(to_yaml(s))
    args = ["--hours", str(hours), "--seed", str(seed), "--scheduler", scheduler,
            "--airspace", airspace]
    if rows is None:
        args += ["--rate", f"{rate:g}"]
    else:
        with open(d / "packages.csv", "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["t", "from_airport", "from_gate", "to_airport", "to_gate"])
            w.writerows(rows)
        data["packages"]["csv"] = "packages.csv"
    (d / "fleet.yaml").write_text(yaml.safe_dump(data))
    rep = simulate(d / "out", str(d / "fleet.yaml"), *args)
    problems, numbers = audit(d / "out", load_scenario(d / "fleet.yaml"))
    assert problems == []
    if rows is not None:  # every listed package before the end is in the files
        with open(d / "out" / "packages.csv", newline="") as fh:
            assert len(list(csv.reader(fh))) - 1 == sum(1 for r in rows
                                                        if r[0] < hours * 3600)
    assert rep["lost"] == numbers["lost"] == 0


@st.composite
def rules(draw):
    """A generated layout with other airspace and airport rules than the defaults:
    separation minima, layers closer than the vertical minimum (each layer is then no
    slice of its own and only the reservations keep drones apart), several shared
    levels, no hand-over time (a drone leaves by the other gate the instant it
    arrived), an airport's gates placed farther apart, and small no-fly zones. (Gates
    placed on a take-off runway's line are left out: a scenario refuses them, since the
    audit flagged a drone taxiing from such a gate while another used the runway.)"""
    airports = draw(st.integers(2, 4))
    s = generate(airports, draw(st.integers(1, 6)), area_km=draw(st.floats(2.5, 5.0)),
                 seed=draw(st.integers(0, 10_000)))
    data = yaml.safe_load(to_yaml(s))
    data["airspace"].update(
        sep_horizontal=draw(st.sampled_from([20.0, 50.0, 120.0, 300.0])),
        sep_vertical=draw(st.sampled_from([5.0, 10.0, 15.0, 30.0])),
        layer_step=draw(st.sampled_from([3.0, 7.5, 10.0, 20.0])),
        shared_levels=draw(st.integers(1, 6)))
    data["handover_seconds"] = draw(st.sampled_from([0.0, 15.0, 60.0]))
    if draw(st.booleans()):  # farther apart than gate_width, off the take-off runway
        a = data["airports"][0]
        h, gap = math.radians(a["takeoff"]["heading_deg"]), draw(st.floats(30.0, 120.0))
        a["gates"] = [[a["north"] - k * gap / 2 * math.sin(h), a["east"] + k * gap / 2 *
                       math.cos(h)] for k in (-1, 1)]
    zones = []
    for k in range(draw(st.integers(0, 2))):
        n, e = draw(st.floats(-2500, 2500)), draw(st.floats(-2500, 2500))
        h, w = draw(st.floats(20, 300)), draw(st.floats(20, 300))
        zones.append({"name": f"z{k}", "points": [[n, e], [n + h, e], [n + h, e + w],
                                                   [n, e + w]]})
    data["no_fly_zones"] = zones
    return (data, draw(st.sampled_from([30.0, 90.0, 200.0])), draw(st.integers(0, 1000)),
            draw(st.sampled_from(["seed", "optimal"])),
            draw(st.sampled_from(["layers", "shared"])))


@settings(max_examples=25, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture,
                                 HealthCheck.too_slow])
@given(case=rules())
def test_fleets_under_other_rules_keep_every_rule_the_audit_checks(tmp_path_factory, case):
    from skyroute.errors import SkyrouteError
    from skyroute.fleet.report import report
    from skyroute.fleet.scenario import parse_scenario
    from skyroute.fleet.simulate import run
    from skyroute.io.fleet_out import write_run

    data, rate, seed, scheduler, airspace = case
    try:
        s = parse_scenario(data)
        sim = run(s, hours=0.3, seed=seed, scheduler=scheduler, airspace=airspace,
                  rate_per_hour=rate)
    except SkyrouteError:  # gates too close, a zone over a runway or in a final's way
        s = parse_scenario({**data, "no_fly_zones": [], "airports": [
            {**a, "gates": None} for a in data["airports"]]})
        sim = run(s, hours=0.3, seed=seed, scheduler=scheduler, airspace=airspace,
                  rate_per_hour=rate)
    rep = report(sim)
    d = tmp_path_factory.mktemp("rules")
    write_run(sim, rep, d)
    problems, numbers = audit(d, s)
    assert problems == []
    assert rep["conflicts"] == 0 and rep["lost"] == numbers["lost"] == 0
    assert numbers["delivered"] == rep["delivered"]


# ------------------------------------------------------------- the audit can fail

@pytest.fixture(scope="module")
def written(tmp_path_factory):
    d = tmp_path_factory.mktemp("run")
    simulate(d, "--preset", "seed-3x3", "--hours", "0.5", "--seed", "1")
    return d


def _copy(src, dst):
    for f in src.iterdir():
        (dst / f.name).write_bytes(f.read_bytes())
    return dst


def test_the_audit_passes_the_run_it_is_shown(written):
    assert audit(written, preset("seed-3x3"))[0] == []


def _edit_lines(path, fn):
    lines = path.read_text().splitlines(keepends=True)
    path.write_text("".join(fn(lines)))


def test_the_audit_finds_a_loss_of_separation_between_samples(written, tmp_path):
    """Two cruising rows of one drone moved onto another's path, one second apart: the
    lines between the samples pass closer than the minima, the samples do not."""
    d = _copy(written, tmp_path)
    lines = (d / "tracks.csv").read_text().splitlines()
    rows = [r.split(",") for r in lines[1:]]
    by = {(r[0], r[1]): r for r in rows}
    # a cruise sample of drone a at t and t+1, and drone b airborne at both
    for r in rows:
        nxt = by.get((str(int(r[0]) + 1), r[1]))
        if r[5] != "cruise" or nxt is None or nxt[5] != "cruise":
            continue
        other = [x for x in rows if x[0] == r[0] and x[1] != r[1] and x[5] == "cruise"
                 and by.get((nxt[0], x[1]), ["", "", "", "", "", ""])[5] == "cruise"]
        if other:
            b = other[0]
            b_next = by[(nxt[0], b[1])]
            break
    else:
        pytest.skip("no two drones cruise together in this run")
    # put drone b 60 m either side of drone a across the step: it passes through a
    na, ea = float(r[2]), float(r[3])
    na1, ea1 = float(nxt[2]), float(nxt[3])
    b[2:5] = [f"{na + 60:.3f}", f"{ea:.3f}", r[4]]
    b_next[2:5] = [f"{na1 - 60:.3f}", f"{ea1:.3f}", nxt[4]]
    (d / "tracks.csv").write_text("\n".join([lines[0], *(",".join(x) for x in rows)]) + "\n")
    problems, _ = audit(d, preset("seed-3x3"))
    assert any(p.startswith("separation:") for p in problems)


@pytest.mark.parametrize("edit, words", [
    ("drop_grant", "without permission"),
    ("count", "report.json delivered"),
    ("gate", "picked up at"),
])
def test_the_audit_finds_a_broken_rule(written, tmp_path, edit, words):
    d = _copy(written, tmp_path)
    if edit == "drop_grant":
        _edit_lines(d / "events.jsonl", lambda ls: [x for x in ls
                                                    if '"landing_granted"' not in x])
    elif edit == "count":
        rep = json.loads((d / "report.json").read_text())
        rep["delivered"] += 1
        (d / "report.json").write_text(json.dumps(rep))
    else:
        def move(ls):
            for k, x in enumerate(ls):
                e = json.loads(x)
                if e["kind"] == "pickup":
                    e["gate"] = 1 - e["gate"]
                    ls[k] = json.dumps(e) + "\n"
                    break
            return ls
        _edit_lines(d / "events.jsonl", move)
    problems, _ = audit(d, preset("seed-3x3"))
    assert any(words in p for p in problems), problems


def test_the_audit_finds_two_drones_on_one_take_off_runway(written, tmp_path):
    """A take-off row copied to a drone that has not landed yet (so it is not taxiing
    in): two drones on one take-off runway at once."""
    d = _copy(written, tmp_path)
    s = preset("seed-3x3")
    events = [json.loads(x) for x in (d / "events.jsonl").read_text().splitlines()]
    first_down = {}
    for e in events:
        if e["kind"] == "touchdown":
            first_down.setdefault(e["drone"], e["t"])
    lines = (d / "tracks.csv").read_text().splitlines()
    taken = {tuple(x.split(",")[:2]) for x in lines[1:]}
    for line in lines[1:]:
        t, drone, n, e, _alt, phase = line.split(",")
        others = [y for y in range(s.drones) if y != int(drone) and (t, str(y)) not in taken
                  and first_down.get(y, math.inf) > float(t)]
        if phase == "takeoff" and others:
            lines.append(f"{t},{others[0]},{n},{e},0.000,takeoff")
            break
    else:
        pytest.skip("no take-off while another drone waits for its first flight")
    rows = sorted(lines[1:], key=lambda x: (float(x.split(",")[0]), int(x.split(",")[1])))
    (d / "tracks.csv").write_text("\n".join([lines[0], *rows]) + "\n")
    problems, _ = audit(d, s)
    assert any("take-off runway" in p for p in problems), problems


# ------------------------------------------------------------- a longer sweep

@pytest.mark.slow
@pytest.mark.parametrize("name", ["seed-3x3", "seed-9x9", "seed-18x9"])
def test_presets_for_an_hour_on_several_seeds(tmp_path, name):
    for seed in range(3):
        for scheduler in ("seed", "optimal"):
            for airspace in ("layers", "shared"):
                out = tmp_path / f"{seed}-{scheduler}-{airspace}"
                simulate(out, "--preset", name, "--hours", "1", "--seed", str(seed),
                         "--scheduler", scheduler, "--airspace", airspace)
                problems, _ = audit(out, preset(name))
                assert problems == [], (seed, scheduler, airspace)
