"""deliver and fleet sweep with --executor dask: the same output as local processes;
bad executor flags are one line and exit 2 before any work."""

from __future__ import annotations

import datetime as dt
import json

import pytest

from skyroute.delivery import store
from tests.cli.test_cli import run
from tests.jobs.conftest import EXAMPLE

RANGE = ["--from", "2024-01-01", "--to", "2024-01-02"]  # (2024-01-03: see test_deliver_jobs)
TIMING = ("wall_seconds", "seconds_per_day_mean", "seconds_per_day_max", "jobs",
          "executor", "workers", "folders")  # and where the files went: each its own --out


def test_deliver_range_on_dask_is_the_local_range(monkeypatch, capsys, tmp_path):
    out = {}
    for name, flags in (("local", ["--jobs", "1"]), ("dask", ["--executor", "dask",
                                                               "--jobs", "2"])):
        db = f"sqlite:///{tmp_path / name}.db"
        code, text, err = run(monkeypatch, capsys, "deliver", *RANGE, "--data", str(EXAMPLE),
                              "--db", db, "--out", str(tmp_path / name), "--json", *flags)
        assert code == 0, err
        out[name] = json.loads(text), store.connect(db)
    (a, ea), (b, eb) = out["local"], out["dask"]
    assert (b["executor"], b["workers"], a["executor"]) == ("dask", 2, "local")
    assert (a["folders"], b["folders"]) == ([str(tmp_path / "local")], [str(tmp_path / "dask")])
    assert {k: v for k, v in a.items() if k not in TIMING} == \
        {k: v for k, v in b.items() if k not in TIMING}
    for d in (dt.date(2024, 1, 1), dt.date(2024, 1, 2)):
        assert store.day_rows(ea, d) == store.day_rows(eb, d)
    geo = "drone-02-01-2024.geojson"
    assert (tmp_path / "local" / geo).read_text() == (tmp_path / "dask" / geo).read_text()


def test_sweep_on_dask_prints_the_local_rows(monkeypatch, capsys):
    args = ["fleet", "sweep", "--preset", "seed-3x3", "--scheduler", "seed", "--airspace",
            "shared", "--seeds", "0-1", "--hours", "0.25", "--json"]
    code, local, err = run(monkeypatch, capsys, *args)
    assert code == 0, err
    code, dask, err = run(monkeypatch, capsys, *args, "--executor", "dask", "--jobs", "2")
    assert code == 0, err
    assert json.loads(local) == json.loads(dask)


@pytest.mark.parametrize("flags, words", [
    (["--executor", "spark"], "--executor 'spark' is not valid; choose one of 'local', 'dask'"),
    (["--executor", "local", "--dask", "tcp://127.0.0.1:8786"],
     "--dask ADDRESS runs on a Dask cluster; drop --executor local"),
    (["--dask", "nonsense"], "--dask 'nonsense': no Dask scheduler there"),
    (["--dask", ""], "--dask '': expected a scheduler address like tcp://HOST:8786"),
    (["--executor", "dask", "--jobs", "0"], "--jobs 0 must be at least 1"),
])
@pytest.mark.parametrize("command", [
    ["deliver", *RANGE, "--data", str(EXAMPLE)],
    ["fleet", "sweep", "--preset", "seed-3x3", "--seeds", "0", "--hours", "0.1"],
])
def test_bad_executor_flags_are_one_line(monkeypatch, capsys, tmp_path, command, flags,
                                         words):
    monkeypatch.chdir(tmp_path)
    code, _, err = run(monkeypatch, capsys, *command, *flags)
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1, err
    # deliver made its store (./skyroute.db) before it tried the --dask address
    assert not list(tmp_path.iterdir())


def test_deliver_on_dask_with_a_failing_day_and_a_dying_worker(monkeypatch, capsys,
                                                               tmp_path):
    # on an in-process Dask cluster, 2024-01-01's worker kills itself (SIGKILL) and
    # 2024-01-02 fails: Dask's KilledWorker ended the range in a traceback, dropping the
    # days not yet stored. Now each failed day is one line and the others are stored.
    # (allowed-failures 0: the first death loses the task, as the fourth does by default;
    # worker-saturation 1.0: a worker holds only the task it runs, so the death takes
    # no other task with it; Dask queues only a map of more than twice the worker
    # threads: 5 days, not 4)
    import dask
    import distributed  # noqa: F401  (its defaults loaded, so the block only overrides)

    from skyroute.jobs.executor import DaskExecutor
    from tests.cli.test_deliver_cli import _stored_day
    from tests.jobs.failing_dask import FailingDaskWorkers

    real = DaskExecutor.__init__

    def started(self, **kw):
        real(self, **kw)
        self.client.register_plugin(FailingDaskWorkers({"2024-01-01": "die",
                                                        "2024-01-02": "skyroute"}))

    monkeypatch.setattr(DaskExecutor, "__init__", started)
    db = tmp_path / "k.db"
    with dask.config.set({"distributed.scheduler.allowed-failures": 0,
                          "distributed.scheduler.worker-saturation": 1.0}):
        code, out, err = run(monkeypatch, capsys, "deliver", "--from", "2023-12-30", "--to",
                             "2024-01-03", "--data", str(EXAMPLE), "--db", f"sqlite:///{db}",
                             "--out", str(tmp_path / "out"), "--executor", "dask",
                             "--jobs", "2")
    assert code == 2 and "Traceback" not in err, err
    assert err.strip().splitlines()[-3:] == [
        "skyroute: error: 2024-01-01: its Dask worker died running it (KilledWorker; see "
        "the workers' logs)",
        "skyroute: error: 2024-01-02: the planner failed",
        "skyroute: error: 2 of the 5 days failed and were not stored; the other 3 are "
        "stored, with their files"], err
    assert _stored_day(db, "2024-01-01")[0] == _stored_day(db, "2024-01-02")[0] == []
    assert _stored_day(db, "2024-01-03")[0] and _stored_day(db, "2023-12-31")[0] == [(0, 0)]
    assert "3 of 5 days" in out


def test_fleet_sweep_says_a_worker_died_and_names_the_lost_run(monkeypatch, capsys):
    # a run whose worker process dies every time: the executor's warning came out bare
    # (Python's last resort, no "skyroute:"), and the error named "task 1" of the map;
    # the row over the run that finished is printed (tests/jobs/test_sweep_lost.py)
    from functools import partial

    from tests.jobs.failing import fleet_dies_on_seed

    monkeypatch.setattr("os.cpu_count", lambda: 2)
    monkeypatch.setattr("skyroute.jobs.executor._leave_sigint",
                        partial(fleet_dies_on_seed, 1))
    code, out, err = run(monkeypatch, capsys, "fleet", "sweep", "--preset", "seed-3x3",
                         "--seeds", "0-1", "--hours", "0.1", "--jobs", "2", "--scheduler",
                         "seed", "--airspace", "shared")
    died = "(killed by SIGKILL, as the out-of-memory killer does)"
    lines = err.strip().splitlines()
    assert code == 2 and "Traceback" not in err, err
    assert "│ seed      │ shared   │    1 │" in out, out  # the row over seed 0 alone
    assert any(x.startswith(f"skyroute: a worker process died {died}; the ")
               for x in lines), err
    assert lines[-2:] == [
        "skyroute: error: scheduler seed, airspace shared, seed 1: its worker process "
        f"died {died}, also when run again alone",
        "skyroute: error: 1 of the 2 runs was lost; the rows are over the other 1 (a "
        "row's runs count them)"], err


def test_fleet_sweep_on_dask_with_a_dying_worker_keeps_the_other_rows(monkeypatch, capsys):
    # on an in-process Dask cluster the worker running seed 1 kills itself (SIGKILL) each
    # time: the rows over the runs that finished are printed, the lost run is one line
    # naming it, exit 2, as on the local executor (tests/jobs/test_sweep_lost.py).
    # allowed-failures 0: the first death loses the run; worker-saturation 1.0 and 5 runs
    # (more than twice the worker threads, so Dask queues them): a worker holds only the
    # run it flies, so its death takes no other run with it.
    import dask
    import distributed  # noqa: F401  (its defaults loaded, so the block only overrides)

    from skyroute.jobs.executor import DaskExecutor
    from tests.jobs.failing_dask import FailingDaskWorkers

    real = DaskExecutor.__init__

    def started(self, **kw):
        real(self, **kw)
        self.client.register_plugin(FailingDaskWorkers({"seed 1": "die"}))

    monkeypatch.setattr(DaskExecutor, "__init__", started)
    with dask.config.set({"distributed.scheduler.allowed-failures": 0,
                          "distributed.scheduler.worker-saturation": 1.0}):
        code, out, err = run(monkeypatch, capsys, "fleet", "sweep", "--preset", "seed-3x3",
                             "--scheduler", "seed", "--airspace", "shared", "--seeds", "0-4",
                             "--hours", "0.1", "--json", "--executor", "dask", "--jobs", "2")
    assert code == 2 and "Traceback" not in err, err
    doc = json.loads(out)
    assert [(r["airspace"], r["runs"]) for r in doc["rows"]] == [("shared", 4)]
    why = ("scheduler seed, airspace shared, seed 1: its Dask worker died running it "
           "(KilledWorker; see the workers' logs)")
    assert [(x["seed"], x["error"]) for x in doc["lost"]] == [(1, why)]
    assert err.strip().splitlines()[-2:] == [
        f"skyroute: error: {why}",
        "skyroute: error: 1 of the 5 runs was lost; the rows are over the other 4 (a "
        "row's runs count them)"], err
