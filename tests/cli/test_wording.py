"""What the tables say, as a user reads them: every cost with its unit, numbers
right-aligned and labels left, thousands separators, the program named as invoked."""

from __future__ import annotations

import io
import os
import re
import subprocess
import sys

import numpy as np
import pytest
from rich.console import Console
from rich.table import Table

from skyroute.cli.tables import _NUMBER, print_table
from tests.cli.test_cli import run


def rows_of(text: str) -> dict[str, str]:
    """A two-column (name, value) table as {name: value}."""
    return {line.split("│")[1].strip(): line.split("│")[2].strip()
            for line in text.splitlines() if line.count("│") == 3}


def assert_aligned(table: Table) -> None:
    """A column of numbers (and "-" for none) is right-aligned, a column of names left."""
    for c in table.columns:
        cells = [x for x in c.cells if isinstance(x, str) and x not in ("", "-")]
        if not cells:
            continue
        numeric = all(_NUMBER.match(x) for x in cells)
        assert c.justify == ("right" if numeric else "left"), (c.header, cells, c.justify)


def rendered(table: Table, width: int = 160) -> str:
    console = Console(width=width, record=True, file=io.StringIO())
    print_table(console, table)
    return console.export_text()


def test_the_curvature_table_right_aligns_its_numbers():
    """bench motion --curvature left-aligned its numbers, alone of all the tables."""
    from skyroute.cli.bench_world_cmd import _curvature_table

    summ = {"ompl BITstar @ 1s": {"queries": 10, "found": 9, "valid": 9, "median_ratio": 1.482,
                                  "median_ms": 1004.2, "p95_ms": 1013.9},
            "skyroute hybrid": {"queries": 10, "found": 10, "valid": 10, "median_ratio": 1.3,
                                "median_ms": 31.3, "p95_ms": 2311.3},
            "skyroute vs ompl BITstar @ 1s": {"no_longer": 9, "compared": 9,
                                              "worst_ratio": 0.9, "peer_solved_we_missed": 0}}
    table = _curvature_table(summ)
    assert_aligned(table)
    text = rendered(table)
    assert "1,004.2" in text and "2,311.3" in text
    # the numbers end at their column's right edge
    line = next(x for x in text.splitlines() if "skyroute hybrid" in x)
    assert re.search(r"│\s+31\.3 │\s+2,311\.3 │$", line.rstrip()), line


def test_the_other_tables_align_numbers_right_and_names_left(monkeypatch, capsys):
    """The maps list and the sweep's scheduler and airspace were the other way round."""
    from skyroute.cli.bench_cmd import _table
    from skyroute.cli.bench_world_cmd import _dubins_table

    row = {"runner": "astar", "peer": False, "median_ms": 1234.5, "expansions_per_s": 2e7,
           "matched": 1900, "invalid": 0, "mean_cost_ratio": 1.0, "max_cost_ratio": 1.0,
           "speedup_vs": {}}
    rep = {"map": "Paris_1_512", "size": [512, 512], "queries": 1900, "scen_lines": 1900,
           "rows": [row]}
    table = _table(rep)
    assert_aligned(table)
    assert "1,900 of 1,900 scenario lines" in str(table.title)
    assert "1,234.500" in rendered(table) and "1,900/1,900" in rendered(table)
    assert_aligned(_dubins_table({"radius": 1.7, "threading_layer": "omp",
                                  "max_abs_diff_ompl": 1e-12,
                                  "rows": [{"queries": 1_000_000, "threads": 2,
                                            "skyroute_us": 0.1, "skyroute_min_us": 0.09,
                                            "ompl_us": 1.2}]}))


def test_maps_lists_numbers_right_aligned_with_separators(monkeypatch, capsys):
    monkeypatch.setenv("COLUMNS", "120")
    code, out, err = run(monkeypatch, capsys, "maps")
    assert code == 0, err
    line = next(x for x in out.splitlines() if "Paris_1_512" in x)
    cells = [c for c in line.split("│")[1:-1]]
    assert cells[3].strip() == "1,900" and cells[3].endswith("1,900 ")  # right-aligned
    assert cells[0].startswith(" Paris_1_512")  # the name left


def test_the_sweep_table_aligns_names_left_and_groups_thousands():
    from skyroute.cli.fleet_cmd import _sweep_table
    from skyroute.fleet.scenario import preset

    s = preset("seed-3x3")
    row = {"scheduler": "optimal", "airspace": "shared", "rate_per_hour": 4000.0,
           "runs": 2, "conflicts": 1200, "lost": 0}
    for m, v, ci in (("delivered_per_hour", 3456.7, 12.3), ("served_share", 0.9, 0.01),
                     ("p95_delivery_s", 2257.0, 1234.0), ("max_wait_s", 3059.0, 10.0),
                     ("loiters", 1500.0, 3.0), ("capacity_bound_per_hour", 4100.0, 1.0)):
        row[m], row[m + "_ci95"] = v, ci
    table = _sweep_table(s, 1.0, [0, 1], [row])
    assert_aligned(table)
    text = rendered(table)
    for word in ("4,000", "3,456.7", "±1,234", "2,257", "1,200"):
        assert word in text, (word, text)


def test_plan_says_the_cost_is_in_cells(monkeypatch, capsys):
    """The plan table's cost had no unit; plan-world's says "m"."""
    code, out, err = run(monkeypatch, capsys, "plan", "den312d", "--start", "50,76", "--goal",
                         "60,13")
    assert code == 0, err
    assert rows_of(out)["cost"] == "112.556349 cells"


def test_plan_on_a_raster_gives_the_cost_in_metres_too(monkeypatch, capsys, tmp_path):
    """A .csv of walls rasterised at --resolution 0.5: the cost is 6 cells, 3 m."""
    walls = tmp_path / "walls.csv"
    walls.write_text("0,0,10,0\n0,0,0,10\n10,0,10,10\n0,10,10,10\n")
    code, out, err = run(monkeypatch, capsys, "plan", str(walls), "--start", "4,4", "--goal",
                         "4,10", "--resolution", "0.5")
    assert code == 0, err
    assert rows_of(out)["cost"] == "6.000000 cells (3.000000 m)"
    code, out, err = run(monkeypatch, capsys, "plan", str(walls), "--start", "4,4", "--goal",
                         "4,10", "--resolution", "0.5", "--json")
    assert code == 0 and '"cost": 6.0' in out  # --json stays in cells


def test_result_table_groups_thousands():
    from skyroute.cli.tables import result_table
    from skyroute.result import PlanResult, Status

    r = PlanResult(Status.FOUND, np.zeros((1234, 2)), 12345.678, expanded=1234567,
                   seconds=7.130294, extra={"setup_seconds": 2.29})
    rows = rows_of(rendered(result_table("t", r, unit="m")))
    assert rows["cost"] == "12,345.678000 m" and rows["waypoints"] == "1,234"
    assert rows["search time"] == "7,130.294 ms"
    assert rows["set-up time"].startswith("2,290.000 ms")


@pytest.mark.parametrize("name, value, plane, text", [
    ("length", 1234567.8, "m", "1,234,567.800000 m"),
    ("length", 230.877, "m", "230.877000 m"),
    ("length_deg", 0.00465, "deg", "0.004650 deg"),
    ("seconds", 17.4755, "m", "17.476 s"),
    ("time", 3600.25, "m", "3,600.250 s"),
    ("smoothness", 0.0485813, "m", "0.0486 rad/move"),
    ("moves", 12881, "m", "12,881"),
])
def test_fly_metrics_have_fixed_decimals_and_separators(name, value, plane, text):
    """6 significant digits printed 1234567.8 m as "1.23457e+06 m" and a length of
    2,345.67 m as "2345.67 m"."""
    from skyroute.cli.fly_cmd import _shown

    assert _shown(name, value, plane) == text


def test_deliver_day_table_groups_thousands(monkeypatch):
    from skyroute.cli import deliver_cmd

    class Day:
        date, invalid = "2024-01-03", []

        def report(self):
            return {"orders_placed": 1200, "orders_delivered": 1100, "orders_invalid": 3,
                    "money_delivered": 27235, "money_placed": 27870, "money_pct": 97.72,
                    "moves": 1442, "moves_left": 58, "seconds": 5.35}

    console = Console(width=80, record=True, file=io.StringIO())
    monkeypatch.setattr(deliver_cmd, "plain_console", lambda **kw: console)
    deliver_cmd._one_day(Day(), [], as_json=False)
    rows = rows_of(console.export_text())
    assert rows["moves"] == "1,442 (battery left 58)" and rows["orders placed"] == "1,200"


def test_the_program_is_named_skyroute_however_it_is_run(monkeypatch, capsys):
    """`python -m skyroute --help` said "Usage: python -m skyroute" (and its hints "see
    'python -m skyroute plan --help'") beside "skyroute: error:" and the commands that
    messages suggest ("skyroute plan-world ..."); main() run inside another program
    started with -m (pytest) said "python -m pytest.skyroute". Now "skyroute" always."""
    done = subprocess.run([sys.executable, "-m", "skyroute", "plan", "--help"],
                          capture_output=True, text=True, env={**os.environ, "COLUMNS": "100"})
    assert "Usage: skyroute plan [OPTIONS] MAP" in done.stdout and "python -m" not in done.stdout
    done = subprocess.run([sys.executable, "-m", "skyroute", "fleet", "simulate", "--nope"],
                          capture_output=True, text=True)
    assert done.returncode == 2 and done.stderr.strip().endswith(
        "(see 'skyroute fleet simulate --help')"), done.stderr
    code, _, err = run(monkeypatch, capsys, "plan")
    assert code == 2 and err.strip() == ("skyroute: error: Missing argument 'MAP'. (see "
                                         "'skyroute plan --help')")
