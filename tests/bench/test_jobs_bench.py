"""`bench jobs`: the list-scheduling simulation and one small measured run."""

import json

import pytest
from hypothesis import given
from hypothesis import strategies as st

from skyroute.bench.jobs import makespan, parse_runs
from tests.cli.test_cli import run
from tests.jobs.conftest import EXAMPLE

durations = st.lists(st.floats(0.0, 10.0), min_size=1, max_size=40)


@given(durations, st.integers(1, 8), st.floats(0.0, 1.0))
def test_makespan_bounds(d, n, over):
    m = makespan(d, n, over)
    work = [x + over for x in d]
    assert m >= max(max(work), sum(work) / n) - 1e-9  # no schedule beats these
    assert m <= sum(work) / n + max(work) + 1e-9  # list scheduling's guarantee
    assert abs(makespan(d, 1, over) - sum(work)) < 1e-6
    if n >= len(d):
        assert abs(m - max(work)) < 1e-9


def test_parse_runs():
    assert parse_runs("local:1, dask:2") == [("local", 1), ("dask", 2)]


def test_bench_jobs_runs_a_range(monkeypatch, capsys, tmp_path, leg_cache):
    out = tmp_path / "jobs.json"
    code, text, err = run(monkeypatch, capsys, "bench", "jobs", "--data", str(EXAMPLE),
                          "--from", "2024-01-01", "--to", "2024-01-03", "--runs", "local:1",
                          "--simulate", "1,3", "--json", str(out))
    assert code == 0, err
    doc = json.loads(out.read_text())
    (row,) = doc["rows"]
    assert (row["executor"], row["workers"], row["days"]) == ("local", 1, 3)
    assert len(doc["durations"]) == 3 and all(d > 0 for d in doc["durations"])
    one, three = doc["simulated"]
    assert abs(one["local_seconds"] - sum(doc["durations"])) < 1e-9
    assert abs(three["local_seconds"] - max(doc["durations"])) < 1e-9
    assert one["dask_seconds"] is None  # no dask:1 run to measure the overhead from
    assert "3 delivery days" in text


@pytest.mark.parametrize(("flag", "value"), [("--runs", "ray:2"), ("--simulate", "2,x"),
                                             ("--simulate", "0")])
def test_bench_jobs_bad_options_are_one_line(monkeypatch, capsys, tmp_path, flag, value):
    out = tmp_path / "jobs.json"
    code, _, err = run(monkeypatch, capsys, "bench", "jobs", "--data", str(EXAMPLE), flag,
                       value, "--json", str(out))
    assert code == 2 and f"{flag} {value!r}" in err and "Traceback" not in err
    assert not out.exists()


def _no_bench(*_args, **_kwargs):
    raise AssertionError("the days were timed before the --json path was checked")


def test_bench_jobs_checks_its_json_path_before_running(monkeypatch, capsys, tmp_path):
    monkeypatch.setattr("skyroute.bench.jobs.bench_jobs", _no_bench)
    (tmp_path / "file").write_text("keep me")
    code, _, err = run(monkeypatch, capsys, "bench", "jobs", "--data", str(EXAMPLE),
                       "--runs", "local:1", "--json", str(tmp_path / "file" / "jobs.json"))
    assert code == 2 and "jobs.json: cannot write: " in err and "file is not a folder" in err
    assert len(err.strip().splitlines()) == 1
