"""Every table the CLI prints keeps its numbers whole at 80 columns (print_table's rule):
Rich narrowed the widest columns and cut through words, so a sweep read "35." over "2"."""

from __future__ import annotations

import io
import re

import numpy as np
import pytest
from rich.console import Console
from rich.table import Table

from skyroute.cli.tables import _NUMBER, fit_table, print_table, result_table
from skyroute.result import PlanResult, Status
from tests.cli.test_cli import run


def shown(table: Table, width: int = 80, **kw) -> str:
    console = Console(width=width, record=True, file=io.StringIO())
    print_table(console, table, **kw)
    return console.export_text()


def numbers(table: Table) -> list[str]:
    """The number-like words of every cell, read before the table is laid out."""
    return [w for c in table.columns for cell in c.cells if isinstance(cell, str)
            for w in cell.split() if _NUMBER.match(w)]


def assert_whole(words: list[str], text: str) -> None:
    assert max(len(line) for line in text.splitlines()) <= 80
    for w in words:
        assert re.search(rf"(?<!\S){re.escape(w)}(?!\S)", text), (w, text)


def unboxed(text: str) -> str:
    """The text without its spaces and vertical lines: a folded path reads whole."""
    return re.sub(r"[\s│┃]", "", text)


def sweep_rows() -> list[dict]:
    rows = []
    for sched, space, delivered, ci in (("seed", "layers", 35.185, 3.187),
                                        ("optimal", "shared", 45.9, 10.43)):
        row = {"scheduler": sched, "airspace": space, "rate_per_hour": 60.0,
               "conflicts": 0, "lost": 0, "runs": 3}  # sweep rows count their runs
        for m, v, c in (("delivered_per_hour", delivered, ci), ("served_share", 0.594, 0.128),
                        ("p95_delivery_s", 1625.6, 249.0), ("max_wait_s", 1838.1, 1053.4),
                        ("loiters", 3.33, 5.74), ("capacity_bound_per_hour", 37.12, 1.64)):
            row[m], row[m + "_ci95"] = v, c
        rows.append(row)
    return rows


def test_the_sweep_keeps_its_numbers_whole_at_80_columns():
    from skyroute.cli.fleet_cmd import _SWEEP_OPTIONAL, _sweep_table
    from skyroute.fleet.scenario import preset

    table = _sweep_table(preset("seed-3x3"), 1.0, [0, 1, 2], sweep_rows())
    words = numbers(table)
    text = shown(table, optional=_SWEEP_OPTIONAL)
    kept = [w for w in words if w not in ("3", "±6", "37.1", "±1.6")]  # loiters, capacity
    assert_whole(kept, text)
    assert "±10.4" in text and "1,626" in text and "±1,053" in text
    assert "not shown at 80 columns: capacity /h, loiters" in text
    # wide enough, every column shows, each mean beside its interval
    wide = shown(_sweep_table(preset("seed-3x3"), 1.0, [0, 1, 2], sweep_rows()), 160,
                 optional=_SWEEP_OPTIONAL)
    assert "not shown" not in wide and "45.9 ±10.4" in wide and "37.1 ±1.6" in wide


def test_fit_keeps_words_whole_where_rich_cut_them():
    """Ten numeric columns whose longest words fit in 80 columns only without the box."""
    table = Table(title="t")
    for i in range(10):
        table.add_column(f"metric {i} ms/req", justify="right")
    table.add_row(*(f"{1234.5 + i:.1f} ±{12.25 + i:.2f}" for i in range(10)))
    words = numbers(table)
    assert_whole(words, shown(table))


def test_optional_columns_go_last_first_and_are_named():
    table = Table(title="t", caption="built in 1.2 s")
    for name in ("runner", "speed", "memory", "extra"):
        table.add_column(name)
    table.add_row("a_rather_long_runner_name", "123456789012345678901234567",
                  "12345678901234567890", "1234567890123456789")
    text = shown(table, optional=("memory", "extra"))
    assert "12345678901234567890" in text and "1234567890123456789 " not in text
    assert "built in 1.2 s" in text and "not shown at 80 columns: extra" in text


def test_a_table_that_fits_is_left_as_built():
    table = Table(title="t")
    table.add_column("a")
    table.add_row("1.5")
    assert fit_table(Console(width=80), table) is table and table.columns[0].width is None


def test_long_paths_fold_and_numbers_stay_whole_in_the_result_table():
    result = PlanResult(Status.FOUND, np.array([(0.5, 0.5), (1.5, 1.5)]), 1234567.891234,
                        expanded=123456789, max_frontier=1234567, los_checks=987654321,
                        seconds=12.3456, extra={"setup_seconds": 2.296})
    path = "/tmp/" + "a_long_folder/" * 6 + "path.png"
    table = result_table("den312d.map: astar", result, unit="cells", files=(("plot", path),))
    text = shown(table)
    assert_whole(numbers(table), text)
    assert path in unboxed(text)  # folded, not cut with "…"


@pytest.mark.parametrize("peers", [("pathfinding", "networkx", "scikit-image")])
def test_the_grid_bench_table_fits_with_three_peers(peers):
    from skyroute.cli.bench_cmd import _table

    rows = [{"runner": "lazy_theta", "peer": False, "median_ms": 0.1234,
             "expansions_per_s": 12.34e6, "matched": 910, "invalid": 0, "mean_cost_ratio": 1.0,
             "max_cost_ratio": 1.0123, "speedup_vs": {p: 1234.56 for p in peers}}]
    rows += [{"runner": p, "peer": True, "median_ms": 12.345, "expansions_per_s": None,
              "matched": 907, "invalid": 3, "mean_cost_ratio": 1.0, "max_cost_ratio": 1.0,
              "speedup_vs": {}} for p in peers]
    rep = {"map": "Berlin_1_256", "size": [256, 256], "queries": 910, "scen_lines": 910,
           "rows": rows}
    table = _table(rep)
    words = [w for w in numbers(table) if w not in ("12.34", "1.0000", "1.0123")]  # given way
    assert_whole(words, shown(table, optional=(
        *(f"x faster than {p}" for p in peers), "cost/opt max", "cost/opt mean", "M exp/s")))


def test_maps_and_plan_at_80_columns(monkeypatch, capsys):
    monkeypatch.setenv("COLUMNS", "80")
    code, out, _ = run(monkeypatch, capsys, "maps")
    assert code == 0 and "…" not in out and "/maps/Berlin_1_256.map" in unboxed(out)
    code, out, _ = run(monkeypatch, capsys, "plan", "den312d", "--start", "10,10",
                       "--goal", "40,60")
    assert code == 0 and "67.112698" in out


def test_bench_tables_are_160_columns_in_a_pipe(monkeypatch, capsys):
    """docs/cli.md: the wide bench tables are 160 columns in a file or a pipe. 'bench
    grid' (and 'bench world', 'bench motion') printed at 80 there, so a log of the README's
    'bench grid --peers networkx' wrapped "networkx (peer)" and, with more runners,
    dropped the speed-ups as "not shown at 80 columns"."""
    pytest.importorskip("networkx")
    monkeypatch.delenv("COLUMNS", raising=False)
    code, out, err = run(monkeypatch, capsys, "bench", "grid", "--map", "den312d",
                         "--per-map", "2", "--algorithms", "astar,jps,theta",
                         "--peers", "networkx")
    assert code == 0, err
    assert "not shown" not in out and "M exp/s" in out and "networkx (peer)" in out, out
    assert 80 < max(len(line) for line in out.splitlines()) <= 160


@pytest.mark.parametrize("columns, width", [("80", 80), ("200", 200), (None, 160),
                                            ("wide", 160), ("0", 160)])
def test_wide_tables_honour_columns_in_a_pipe(monkeypatch, columns, width):
    """$COLUMNS, when set, is the width of the wide tables too: 'COLUMNS=80 skyroute bench
    grid ... | cat' printed 160 columns. Unset (or not a width, as Rich reads it): 160."""
    from skyroute.cli.tables import wide_console

    if columns is None:
        monkeypatch.delenv("COLUMNS", raising=False)
    else:
        monkeypatch.setenv("COLUMNS", columns)
    assert wide_console().width == width


@pytest.mark.parametrize("columns", ["72", "130"])
def test_fleet_sweep_table_is_as_wide_as_columns(monkeypatch, capsys, columns):
    monkeypatch.setenv("COLUMNS", columns)
    code, out, err = run(monkeypatch, capsys, "fleet", "sweep", "--preset", "seed-3x3",
                         "--seeds", "0-1", "--hours", "0.1", "--jobs", "1")
    assert code == 0, err
    widths = [len(line) for line in out.splitlines()]
    # the title is centred over the table: its line is the table's width
    assert max(widths) <= int(columns) and "served" in out, out
    if columns == "72":
        assert "not shown at 72 columns" in out
