"""The build's peak memory that `bench grid --prepared` reports, measured in a child."""

import pytest

from skyroute.bench.build_memory import build_peak_bytes
from skyroute.bench.random_maps import random_grid
from skyroute.search.prepared import prepare


def test_peak_holds_the_index_the_build_writes():
    grid = random_grid(192, 0.2, 0)
    peak = build_peak_bytes(grid.blocked, "jump")
    index = prepare(grid, method="jump")
    pivot_table = index.pivots * 8 * (grid.width + 2) * (grid.height + 2)  # float64 a pivot
    assert pivot_table > 5_000_000
    # Every pivot distance is written during the build, so it was resident at the peak;
    # the build's scratch (a Dijkstra's workspace) is a few grid-sized arrays on top.
    assert pivot_table <= peak <= 3 * index.nbytes


def test_a_failing_build_is_an_error_not_a_figure():
    with pytest.raises(RuntimeError, match=r"measuring process failed: .*method"):
        build_peak_bytes(random_grid(8, 0.1, 0).blocked, "nosuchmethod")


def test_bench_grid_prepared_reports_build_time_peak_and_bytes(monkeypatch, capsys, tmp_path):
    import json

    from tests.cli.test_cli import run

    out_json = tmp_path / "bench.json"
    code, out, err = run(monkeypatch, capsys, "bench", "grid", "--random", "48:0.2",
                         "--per-map", "3", "--peers", "", "--prepared", "--json", str(out_json))
    assert code == 0, err
    prep = json.loads(out_json.read_text())["maps"][0]["prepared"]
    assert prep["build_seconds"] > 0 and prep["index_bytes"] > 0
    assert prep["build_peak_bytes"] > 0
    assert f"peak {prep['build_peak_bytes'] / 1e6:.1f} MB resident" in " ".join(out.split())
    assert out.count("3/3") == 3  # astar, jps and the index match scipy's optimum


def test_bench_grid_goes_on_when_the_measuring_process_fails(monkeypatch, capsys):
    import skyroute.bench.grid as grid_mod
    from tests.cli.test_cli import run

    def fail(blocked):
        raise RuntimeError("build memory: the measuring process failed: MemoryError")

    monkeypatch.setattr(grid_mod, "build_peak_bytes", fail)
    code, out, err = run(monkeypatch, capsys, "bench", "grid", "--random", "32:0.2",
                         "--per-map", "2", "--peers", "", "--prepared")
    assert code == 0, err
    assert "measuring process failed: MemoryError" in err and "Traceback" not in err
    assert "peak - MB resident" in " ".join(out.split())
