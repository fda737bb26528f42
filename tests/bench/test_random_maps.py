"""Synthetic random maps for `bench grid --random`: scipy's optima are the planners'."""

import json

import numpy as np
import pytest

import skyroute
from skyroute.bench.random_maps import far_queries, parse_random, random_grid
from skyroute.errors import OptionError
from tests.cli.test_cli import run


def test_parse_random():
    assert parse_random("512:0.2") == (512, 0.2)
    for bad in ("512", "x:0.2", "512:1.0", "1:0.1", "64:-0.1"):
        with pytest.raises(OptionError, match="--random"):
            parse_random(bad)


@pytest.mark.parametrize("share", [0.1, 0.3])
def test_far_queries_optima_equal_astar_and_are_far(share):
    grid = random_grid(96, share, seed=3)
    assert abs(grid.blocked.mean() - share) < 0.03
    scen = far_queries(grid, 12, seed=3)
    for s, t, opt in zip(scen.starts, scen.goals, scen.optimal, strict=True):
        dx, dy = np.abs(s - t)
        assert max(dx, dy) + (2 ** 0.5 - 1) * min(dx, dy) >= 48
        r = skyroute.plan(grid, tuple(s.tolist()), tuple(t.tolist()), algorithm="astar")
        assert r.found and r.cost == pytest.approx(opt, abs=1e-9)


def test_bench_grid_random_only(monkeypatch, capsys, tmp_path):
    """A random map has no scenario file: its title said "4 of 4 scenario lines" and its
    report named a "random-64-0.2-s0.scen" that does not exist."""
    report = tmp_path / "r.json"
    code, out, err = run(monkeypatch, capsys, "bench", "grid", "--random", "64:0.2",
                         "--per-map", "4", "--peers", "", "--json", str(report))
    assert code == 0, err
    assert "random-64-0.2-s0 (64x64): 4 far queries, optima from scipy" in out
    assert "scenario" not in out
    assert out.count("4/4") == 2  # astar and jps match scipy's optimum on every query
    rep, = json.loads(report.read_text())["maps"]
    assert rep["scen"] is None and rep["scen_lines"] is None and rep["queries"] == 4


def test_bench_grid_random_bad_spec_is_one_line(monkeypatch, capsys):
    code, _, err = run(monkeypatch, capsys, "bench", "grid", "--random", "64", "--peers", "")
    assert code == 2 and "--random '64'" in err and "Traceback" not in err
