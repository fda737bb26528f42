"""A sweep some of whose runs are lost (their worker process died each time they were
tried): the rows of the runs that finished are kept and reported, each lost run is named
by its setting and seed, and the end is an error (exit 2, a failed job). The executor
raised TasksLostError and the sweep ended in one line, its finished runs gone."""

from __future__ import annotations

import json

import pytest

from skyroute.fleet.scenario import preset
from skyroute.jobs import runner
from skyroute.jobs.fleet import RunsLostError, sweep
from tests.cli.test_cli import run
from tests.jobs.conftest import lunch_store
from tests.jobs.failing import LosingExecutor, failing_workers

# runs in sweep order (settings outermost): 0 shared/0, 1 shared/1, 2 layers/0, 3 layers/1
SETTINGS = {"schedulers": ["seed"], "airspaces": ["shared", "layers"], "seeds": [0, 1],
            "hours": 0.25}
ARGS = ["fleet", "sweep", "--preset", "seed-3x3", "--scheduler", "seed", "--airspace",
        "shared,layers", "--seeds", "0-1", "--hours", "0.25"]
DIED = "its worker process died (killed by SIGKILL), also when run again alone"
OOM = "killed by SIGKILL, as the out-of-memory killer does"


def _same(a: dict, b: dict) -> bool:
    return json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)  # NaN == NaN


def test_a_sweep_keeps_the_rows_of_the_runs_that_finished():
    s = preset("seed-3x3")
    with pytest.raises(RunsLostError) as err:
        sweep(s, **SETTINGS, executor=LosingExecutor(lose={1, 2, 3}))
    e = err.value
    # shared over its seed 0 alone; layers lost whole: no row
    alone = sweep(s, **{**SETTINGS, "airspaces": ["shared"], "seeds": [0]},
                  executor=LosingExecutor())
    assert len(e.rows) == 1 and e.rows[0]["runs"] == 1 and _same(e.rows[0], alone[0])
    assert [(x["airspace"], x["seed"], x["rate_per_hour"]) for x in e.lost] == [
        ("shared", 1, 60.0), ("layers", 0, 60.0), ("layers", 1, 60.0)]
    assert e.lost[0]["error"] == f"scheduler seed, airspace shared, seed 1: {DIED}"
    assert str(e) == (f"3 of the 4 runs were lost and left out of the rows: scheduler "
                      f"seed, airspace shared, seed 1: {DIED}; and 2 more")


def test_fleet_sweep_json_reports_the_rows_and_names_each_lost_run(monkeypatch, capsys):
    monkeypatch.setattr("skyroute.cli.fleet_cmd.open_from_flags",
                        lambda *a: LosingExecutor(lose={1}))
    code, out, err = run(monkeypatch, capsys, *ARGS, "--json")
    assert code == 2 and "Traceback" not in err, err
    doc = json.loads(out)
    assert [(r["airspace"], r["runs"]) for r in doc["rows"]] == [("shared", 1), ("layers", 2)]
    assert doc["lost"] == [{"scheduler": "seed", "airspace": "shared", "rate_per_hour": 60.0,
                            "seed": 1, "error": f"scheduler seed, airspace shared, seed 1: "
                                                f"{DIED}"}]
    assert err.strip().splitlines()[-2:] == [
        f"skyroute: error: scheduler seed, airspace shared, seed 1: {DIED}",
        "skyroute: error: 1 of the 4 runs was lost; the rows are over the other 3 (a "
        "row's runs count them)"], err


def test_fleet_sweep_table_shows_the_runs_of_a_short_row(monkeypatch, capsys):
    monkeypatch.setenv("COLUMNS", "200")
    monkeypatch.setattr("skyroute.cli.fleet_cmd.open_from_flags",
                        lambda *a: LosingExecutor(lose={2}))
    code, out, err = run(monkeypatch, capsys, *ARGS)
    assert code == 2, err
    head = next(line for line in out.splitlines() if "scheduler" in line)
    assert head.split("┃")[1:4] == [" scheduler ", " airspace ", " runs "], out
    rows = [line.split("│")[1:4] for line in out.splitlines() if line.startswith("│")]
    assert [[c.strip() for c in r] for r in rows] == [["seed", "shared", "2"],
                                                      ["seed", "layers", "1"]]
    assert err.strip().splitlines()[-1] == (
        "skyroute: error: 1 of the 4 runs was lost; the rows are over the other 3 (a row's "
        "runs count them)")


def test_fleet_sweep_with_every_run_lost_prints_no_rows(monkeypatch, capsys):
    monkeypatch.setattr("skyroute.cli.fleet_cmd.open_from_flags",
                        lambda *a: LosingExecutor(lose={0, 1, 2, 3}))
    code, out, err = run(monkeypatch, capsys, *ARGS)
    assert code == 2 and out == "", (out, err)
    assert err.strip().splitlines()[-1] == \
        "skyroute: error: all 4 runs were lost; there are no rows"


def test_ctrl_c_in_a_sweep_is_still_an_interrupt(monkeypatch, capsys):
    monkeypatch.setattr("skyroute.cli.fleet_cmd.open_from_flags",
                        lambda *a: LosingExecutor(lose={0}, interrupt_at=2))
    code, out, err = run(monkeypatch, capsys, *ARGS, "--json")
    assert (code, out, err.strip().splitlines()[-1]) == (130, "", "skyroute: interrupted")


def test_a_sweep_job_with_a_lost_run_fails_keeping_the_rows(tmp_path):
    engine = lunch_store(f"sqlite:///{tmp_path / 's.db'}", ())
    params = {"preset": "seed-3x3", **SETTINGS}
    job = runner.wait(engine, runner.submit(engine, "sweep", params,
                                            executor=LosingExecutor(lose={3})), timeout=300)
    assert (job["state"], job["progress"]) == ("failed", 1.0)
    assert job["error"] == ("1 of the 4 runs was lost and left out of the rows: scheduler "
                            f"seed, airspace layers, seed 1: {DIED}")
    rows, lost = job["result"]["rows"], job["result"]["lost"]
    assert [(r["airspace"], r["runs"]) for r in rows] == [("shared", 2), ("layers", 1)]
    assert [(x["airspace"], x["seed"]) for x in lost] == [("layers", 1)]


def test_a_sweep_whose_worker_dies_keeps_the_other_runs(monkeypatch, capsys):
    # a real pool (--jobs 2): the worker of shared/seed 1 kills itself (SIGKILL, as the
    # out-of-memory killer does) each time; the sweep ended in "2 of the 4 tasks were
    # lost: task 1: ..." and printed no row. Now the three other runs are reported
    failing_workers(monkeypatch, {"seed shared seed 1": "die"})
    code, out, err = run(monkeypatch, capsys, *ARGS, "--jobs", "2", "--json")
    assert code == 2 and "Traceback" not in err, err
    doc = json.loads(out)
    assert [(r["airspace"], r["runs"]) for r in doc["rows"]] == [("shared", 1), ("layers", 2)]
    assert f"skyroute: a worker process died ({OOM}); the " in err
    assert err.strip().splitlines()[-2:] == [
        f"skyroute: error: scheduler seed, airspace shared, seed 1: its worker process died "
        f"({OOM}), also when run again alone",
        "skyroute: error: 1 of the 4 runs was lost; the rows are over the other 3 (a "
        "row's runs count them)"], err
