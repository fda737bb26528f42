"""Fleet sweeps and runs as tasks: local and Dask give the same rows; a fleet run job's
stored files are the files of the same run made in this process."""

from __future__ import annotations

import math

import pytest

from skyroute.errors import SkyrouteError
from skyroute.fleet.report import report
from skyroute.fleet.scenario import preset
from skyroute.fleet.simulate import run
from skyroute.io.fleet_out import events_jsonl, fleet_geojson, packages_csv, tracks_csv
from skyroute.io.geojson import dumps
from skyroute.jobs import runner, store
from skyroute.jobs.executor import open_executor
from skyroute.jobs.fleet import check_fleet_params, check_sweep_params, sweep
from tests.jobs.conftest import lunch_store

SWEEP = {"schedulers": ["seed", "optimal"], "airspaces": ["shared"], "seeds": [0, 1],
         "hours": 0.5}
TIMING = ("wall_seconds", "sim_seconds_per_wall_second")
BUSY = {**preset("seed-3x3").model_dump(), "packages": {"rate_per_hour": 1e4}}


def same(a, b) -> bool:
    """Equal, NaN equal to NaN."""
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    return a == b


def test_a_sweep_gives_the_same_rows_locally_and_on_dask(dask_executor):
    s = preset("seed-3x3")
    with open_executor("local", workers=1) as local:
        a = sweep(s, **SWEEP, executor=local)
    done = []
    b = sweep(s, **SWEEP, executor=dask_executor, on_result=lambda i, _r: done.append(i))
    assert sorted(done) == [0, 1, 2, 3]
    assert len(a) == 2 and [r["scheduler"] for r in a] == ["seed", "optimal"]
    assert all(same(x, y) for x, y in zip(a, b, strict=True))
    assert all(r["runs"] == 2 and r["conflicts"] == 0 and r["lost"] == 0 for r in b)


def test_a_fleet_job_stores_the_runs_files(tmp_path, dask_executor):
    engine = lunch_store(f"sqlite:///{tmp_path / 'f.db'}", ())
    params = {"preset": "seed-3x3", "hours": 0.25, "seed": 2, "scheduler": "optimal",
              "track_step": 2.0}
    job = runner.wait(engine, runner.submit(engine, "fleet", params,
                                            executor=dask_executor), timeout=300)
    assert job["state"] == "done", job["error"]
    saved = store.get_fleet_run(engine, job["result"]["fleet_run"])
    assert saved["job_id"] == job["id"] and saved["scenario"] == "seed-3x3"
    assert store.list_fleet_runs(engine, job_id=job["id"])[0]["id"] == saved["id"]

    sim = run(preset("seed-3x3"), hours=0.25, seed=2, scheduler="optimal")
    here = report(sim)
    for rep in (saved["report"], job["result"]["report"]):
        assert {k: v for k, v in rep.items() if k not in TIMING} == \
            {k: v for k, v in here.items() if k not in TIMING}
    assert saved["events_jsonl"] == events_jsonl(sim)
    assert saved["tracks_csv"] == tracks_csv(sim, 2.0)
    assert saved["packages_csv"] == packages_csv(sim)
    assert saved["fleet_geojson"] == dumps(fleet_geojson(sim))
    assert saved["params"]["scenario"]["name"] == "seed-3x3"
    assert saved["params"]["track_step"] == 2.0 and saved["params"]["airspace"] == "layers"


def test_fleet_and_sweep_params_are_completed():
    assert check_fleet_params({"preset": "seed-3x3"}) == {
        "preset": "seed-3x3", "hours": 1.0, "seed": 0, "scheduler": "seed",
        "airspace": "layers", "rate_per_hour": None, "track_step": 1.0}
    p = check_sweep_params({"scenario": preset("seed-3x3").model_dump(), "rates": [30],
                            "seeds": [3, 1, 3]})
    assert p["seeds"] == [3, 1] and p["rates"] == [30.0] and p["hours"] == 1.0
    assert p["schedulers"] == ["seed", "optimal"] and p["airspaces"] == ["layers", "shared"]
    assert p["scenario"]["name"] == "seed-3x3"


@pytest.mark.parametrize("params, words", [
    ({}, "give exactly one of preset (a name) or scenario (its fields)"),
    ({"preset": "seed-3x3", "scenario": {}}, "give exactly one of preset"),
    ({"preset": "seed-3x3", "seed": -1}, "seed=-1 must be an integer from 0 to 4,294,967,295"),
    ({"preset": "seed-3x3", "seed": True}, "seed=True must be an integer"),
    ({"preset": "seed-3x3", "rate_per_hour": "many"}, "rate_per_hour='many' must be a number"),
    ({"preset": "seed-3x3", "track_step": 0}, "track_step=0 must be a number > 0"),
    ({"preset": "seed-3x3", "scheduler": "fifo"}, "scheduler='fifo' is not valid"),
    ({"preset": "seed-3x3", "drones": 4}, "drones: unknown parameter of a fleet job"),
    # past skyroute.fleet.limits, as on the command line
    ({"preset": "seed-3x3", "hours": 1e9}, "hours=1e+09 is over the limit of 168"),
    ({"preset": "seed-3x3", "rate_per_hour": 1e12}, "rate_per_hour=1e+12 is over the limit"),
    ({"preset": "seed-3x3", "rate_per_hour": 1e5, "hours": 8},
     "rate_per_hour=100000 with hours=8 would spawn about 8e+05 packages (limit 100,000)"),
    ({"preset": "seed-3x3", "hours": 8, "track_step": 1e-6},
     "track_step=1e-06 with hours=8 and 3 drones would write up to 8.6e+10 track rows"),
    ({"scenario": {**preset("seed-3x3").model_dump(), "drone": {"turn_radius": 1e12}}},
     "scenario: drone.turn_radius: a flight "),
    # no rate given: the scenario's, so hours is to blame (rate_per_hour= was named)
    ({"scenario": BUSY, "hours": 24},
     "hours=24 at the scenario's 10000 packages/h would spawn about 2.4e+05 packages"),
    # a run shorter than the millisecond its times are written to: the job was queued
    # and then failed in its run (the CLI refused it at once)
    ({"preset": "seed-3x3", "hours": 1e-7}, "hours=1e-07 is 0.00036 s, under the millisecond"),
])
def test_bad_fleet_params_name_the_field(params, words):
    from skyroute.errors import OptionError

    with pytest.raises(OptionError) as err:
        check_fleet_params(params)
    assert words in str(err.value)


@pytest.mark.parametrize("params, words", [
    ({"seeds": list(range(1001))}, "seeds: 1,001 seeds is over the limit of 1,000"),
    ({"rates": [1e5], "hours": 4}, "rates=100000 with hours=4 would spawn about 4e+05"),
    # no rate given: the scenario's, so hours is to blame (rate_per_hour= was named)
    ({"preset": None, "scenario": BUSY, "hours": 24},
     "hours=24 at the scenario's 10000 packages/h would spawn about 2.4e+05 packages"),
    ({"hours": 1e9}, "hours=1e+09 is over the limit"),
    ({"hours": 1e-7}, "hours=1e-07 is 0.00036 s, under the millisecond"),
    ({"seeds": list(range(1000)), "rates": [10, 20, 30]}, "2 scheduler(s) x 2 airspace(s) x "
     "3 rate(s) x 1,000 seed(s) is 12,000 runs, over the limit of 10,000 in one sweep; give "
     "fewer rates or seeds"),
])
def test_bad_sweep_params_past_the_limits(params, words):
    from skyroute.errors import OptionError

    with pytest.raises(OptionError) as err:
        check_sweep_params({"preset": "seed-3x3", **params})
    assert words in str(err.value)


def test_a_sweep_past_the_run_limit_is_refused_before_its_tasks():
    from skyroute.errors import OptionError

    class NoRuns:
        def map(self, *_args, **_kwargs):
            pytest.fail("the sweep's runs were sent to the executor")

    with pytest.raises(OptionError, match="is 12,000 runs, over the limit of 10,000"):
        sweep(preset("seed-3x3"), rates=(10, 20, 30), seeds=range(1000), hours=1,
              executor=NoRuns())


def test_fleet_and_sweep_jobs_refuse_an_airport_no_cruise_can_reach():
    # the job failed mid-run, when C was first flown, with the planner's raw status
    from skyroute.errors import OptionError
    from tests.fleet.test_nofly import RING_ERROR, ringed

    for check in (check_fleet_params, check_sweep_params):
        with pytest.raises(OptionError) as err:
            check({"scenario": ringed()})
        assert str(err.value) == f"scenario: {RING_ERROR}"
        assert err.value.param == "scenario"


def test_a_level_whose_roll_overruns_a_runway_names_the_jobs_scenario():
    # the message named the airport and level but not the scenario, unlike the others
    from skyroute.errors import OptionError

    data = preset("seed-3x3").model_dump()
    data["airports"][2]["takeoff"]["length"] = 320.0  # holds the roll to 50 m, not to 90 m
    data["drones"] = 5
    for check, extra in ((check_fleet_params, {"airspace": "layers"}),
                         (check_sweep_params, {"airspaces": ["layers"]})):
        with pytest.raises(OptionError) as err:
            check({"scenario": data, **extra})
        assert str(err.value).startswith("scenario: airport C's take-off runway (320 m) is "
                                         "shorter than the take-off roll to climb to 90 m")
        assert err.value.param == "airspace"


def test_a_run_whose_worker_dies_is_named_by_its_settings(monkeypatch, tmp_path):
    """A sweep's run whose worker process dies every time it is tried, and a fleet job's
    run lost so on Dask (a one-task map runs in the calling process on the local
    executor): the errors named the executor's task numbers ("2 of the 4 tasks were
    lost: task 1: ...", "1 of the 1 tasks was lost: task 0: ..."), which mean nothing
    to the user; they now name the runs by their settings."""
    from functools import partial

    from skyroute.jobs import executor
    from skyroute.jobs.executor import TasksLostError
    from skyroute.jobs.fleet import fleet_job
    from tests.jobs.failing import fleet_dies_on_seed

    monkeypatch.setattr(executor, "_leave_sigint", partial(fleet_dies_on_seed, 1))
    died = "its worker process died (killed by SIGKILL, as the out-of-memory killer does)"
    with open_executor("local", workers=2) as ex, pytest.raises(SkyrouteError) as err:
        sweep(preset("seed-3x3"), **{**SWEEP, "hours": 0.1}, executor=ex)
    assert str(err.value) == (f"2 of the 4 runs were lost and left out of the rows: "
                              f"scheduler seed, airspace shared, seed 1: {died}, also "
                              "when run again alone; and 1 more")

    class KilledOnDask:  # what DaskExecutor.map raises for a KilledWorker
        def map(self, fn, items, *, on_result=None):
            raise TasksLostError({0: "its Dask worker died running it (KilledWorker; see "
                                     "the workers' logs)"}, [None])

    engine = lunch_store(f"sqlite:///{tmp_path / 'f.db'}", [])
    with pytest.raises(SkyrouteError) as err:
        fleet_job(engine, "a-job", {"preset": "seed-3x3", "hours": 0.1},
                  executor=KilledOnDask(), progress=lambda _p: None)
    assert str(err.value) == ("the fleet run was lost: its Dask worker died running it "
                              "(KilledWorker; see the workers' logs)")


def test_a_fleet_task_on_a_machine_without_the_sqlite_store_makes_nothing(tmp_path):
    """A Dask worker on another machine, given the server's SQLite store: it made an
    empty file and its folders at that path, then failed "no skyroute tables; run
    'skyroute db init' first" of a store that has them."""
    from skyroute.jobs.fleet import FleetTask, RunSpec, fly_fleet

    elsewhere = tmp_path / "server" / "data" / "skyroute.db"  # not on this "machine"
    spec = RunSpec(preset("seed-3x3").model_dump(), 0.05)
    with pytest.raises(SkyrouteError) as err:
        fly_fleet(FleetTask(f"sqlite:///{elsewhere}", "run-1", "job-1", spec))
    text = str(err.value)
    assert text.startswith(f"the SQLite store {elsewhere} is not on this worker's machine")
    assert "PostgreSQL" in text and "\n" not in text
    assert not (tmp_path / "server").exists()
