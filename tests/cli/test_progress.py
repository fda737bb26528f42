"""Long commands' progress and results as a user and a log see them: a bar only on an
interactive terminal, gone when done; nothing at all on a pipe or a file (stdout stays
pure JSON with --json, stderr empty); a sweep table that keeps its digits."""

from __future__ import annotations

import io
import json

from rich.console import Console

from skyroute.cli.tables import print_table, progress_bar
from tests.cli.test_cli import run


def test_no_progress_output_off_a_terminal():
    """Rich printed an empty line per bar into a log (stderr a file or a pipe)."""
    log = io.StringIO()
    with progress_bar(Console(file=log)) as progress:
        task = progress.add_task("days", total=3)
        progress.advance(task)
    assert log.getvalue() == ""


def test_the_bar_shows_on_a_terminal_and_goes_away():
    screen = io.StringIO()
    console = Console(file=screen, force_terminal=True, force_interactive=True, width=80)
    with progress_bar(console) as progress:
        assert not progress.disable and progress.live.transient
        task = progress.add_task("simulated seconds", total=10)
        progress.update(task, completed=4)
        progress.refresh()
        phase = progress.add_task("separation check", total=None)
        progress.refresh()
        # a phase of unknown length shows a moving bar, not "0/?"
        counts = [c.render(progress.tasks[phase]).plain for c in progress.columns[2:3]]
        assert counts == [""]
    out = screen.getvalue()
    assert "simulated seconds" in out and "4/10" in out and "0/?" not in out


def test_fleet_simulate_json_keeps_stdout_and_stderr_clean(monkeypatch, capsys):
    code, out, err = run(monkeypatch, capsys, "fleet", "simulate", "--preset", "seed-3x3",
                         "--hours", "0.5", "--json")
    assert code == 0, err
    assert json.loads(out)["settings"]["hours"] == 0.5
    assert err == ""  # was "\n": the progress bar's empty line


def test_sweep_table_wraps_numbers_instead_of_cutting_them():
    """At 100 columns the sweep's cells read "18.2±…", the interval lost."""
    from skyroute.cli.fleet_cmd import _sweep_table
    from skyroute.fleet.scenario import preset

    row = {"scheduler": "optimal", "airspace": "shared", "rate_per_hour": 60.0, "runs": 2,
           "conflicts": 0, "lost": 0}
    for m, v, ci in (("delivered_per_hour", 48.8, 3.6), ("served_share", 0.849, 0.046),
                     ("p95_delivery_s", 1693, 681), ("max_wait_s", 3502, 1373),
                     ("loiters", 5, 4), ("capacity_bound_per_hour", 48.3, 4.2)):
        row[m], row[m + "_ci95"] = v, ci
    screen = io.StringIO()
    print_table(Console(file=screen, width=100),
                _sweep_table(preset("seed-3x3"), 2.0, [0, 1], [row]))
    text = screen.getvalue()
    assert "…" not in text
    for cell in ("optimal", "shared", "48.8", "±3.6", "1,693", "±681", "3,502", "±1,373"):
        assert cell in text, cell
