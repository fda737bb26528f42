"""A run's end is a whole millisecond, the resolution its files write times to, so no
written time is after it. The end was ``hours * 3600`` exactly: ``--hours
0.02777798611111111`` (100.00075 s) wrote a package spawned at 100.0007 s as 100.001."""

from __future__ import annotations

import csv
import io
import json

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from skyroute.fleet.packages import Stream
from skyroute.fleet.report import report
from skyroute.fleet.scenario import preset
from skyroute.fleet.simulate import simulate
from skyroute.io.fleet_out import events_jsonl, packages_csv, tracks_csv
from tests.cli.test_cli import run as run_cli

SCENARIO = preset("seed-3x3")
IDS = [a.id for a in SCENARIO.airports]


def _written_times(sim) -> list[float]:
    """Every time the run's files write: events, package times, track rows."""
    out = [json.loads(line)["t"] for line in events_jsonl(sim).splitlines()]
    for row in csv.DictReader(io.StringIO(packages_csv(sim))):
        out += [float(v) for k, v in row.items() if k.endswith("_s") and v]
    rows = csv.reader(io.StringIO(tracks_csv(sim, 0.25).decode()))
    next(rows)
    out += [float(r[0]) for r in rows]
    return out


def _stream(times) -> Stream:
    n = len(times)
    return Stream(t=np.array(times, dtype=float), origin=np.arange(n) % 3,
                  origin_gate=np.zeros(n, np.int64), destination=(np.arange(n) + 1) % 3,
                  destination_gate=np.ones(n, np.int64))


def test_the_reported_case_writes_nothing_after_the_end():
    hours = 100.00075 / 3600  # 0.02777798611111111
    sim = simulate(SCENARIO, _stream([10.0, 100.0007]), hours=hours)
    times = _written_times(sim)
    assert 100.001 in times  # the late spawn, as the files write it
    assert max(times) <= sim.horizon == 100.001
    assert report(sim)["settings"]["end_s"] == 100.001


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(end_us=st.integers(30_000_000, 120_000_000),  # the end, microseconds
       before_us=st.lists(st.integers(0, 2_000), min_size=1, max_size=3))
def test_no_written_time_is_after_the_end(end_us, before_us):
    # packages spawned within 2 ms before an end that is rarely a whole millisecond
    hours = end_us / 1e6 / 3600
    spawns = sorted({(end_us - b) / 1e6 for b in before_us} | {5.0})
    sim = simulate(SCENARIO, _stream(spawns), hours=hours)
    end = sim.horizon
    assert max(_written_times(sim)) <= end
    # the end: a whole millisecond, the nearest (either at a tie, as floats fall)
    assert end == round(end, 3) and abs(end * 1e6 - end_us) <= 500 + 1e-6


def test_the_cli_run_ends_on_the_millisecond(monkeypatch, capsys, tmp_path):
    (tmp_path / "pk.csv").write_text("t,from_airport,from_gate,to_airport,to_gate\n"
                                     f"10,{IDS[0]},0,{IDS[1]},0\n"
                                     f"100.0007,{IDS[1]},0,{IDS[2]},1\n")
    data = SCENARIO.model_dump()
    data["packages"]["csv"] = "pk.csv"
    import yaml

    (tmp_path / "sc.yaml").write_text(yaml.safe_dump(data, sort_keys=False))
    out = tmp_path / "out"
    code, stdout, err = run_cli(monkeypatch, capsys, "fleet", "simulate",
                                str(tmp_path / "sc.yaml"), "--hours", "0.02777798611111111",
                                "--out", str(out), "--json", "--track-step", "0.25")
    assert code in (0, 1), err
    end = json.loads(stdout)["settings"].get("end_s", 100.00075)  # the old end
    events = [json.loads(x)["t"] for x in (out / "events.jsonl").read_text().splitlines()]
    tracks = [float(r["t"]) for r in csv.DictReader((out / "tracks.csv").open())]
    spawned = [float(r["spawn_s"]) for r in csv.DictReader((out / "packages.csv").open())]
    assert spawned == [10.0, 100.001] and max(events + tracks) <= end == 100.001


@pytest.mark.parametrize("hours", [1e-7, 1.3e-7])
def test_a_run_shorter_than_a_millisecond_is_refused(hours):
    from skyroute.errors import OptionError

    with pytest.raises(OptionError, match=r"^hours=1\.?3?e-07 is .* s, under the "
                                          "millisecond"):
        simulate(SCENARIO, _stream([]), hours=hours)
