"""Rich output shared by commands: the PlanResult table, a console wide enough for tables,
the progress bar of long runs and where progress shows."""

from __future__ import annotations

from typing import TYPE_CHECKING

from skyroute.result import PlanResult

if TYPE_CHECKING:  # Rich is imported on use: `skyroute plan --json` prints without it
    from rich.console import Console
    from rich.progress import Progress
    from rich.table import Table


def result_table(title: str, result: PlanResult, *, unit: str = "",
                 files: tuple[tuple[str, object], ...] = ()) -> Table:
    """Status, cost, waypoints, statistics and written files of one result."""
    from rich.table import Table

    table = Table(title=title, show_header=False)
    table.add_column(style="bold")
    table.add_column()
    table.add_row("status", result.status.value)
    if result.found:
        table.add_row("cost", f"{result.cost:.6f}" + (f" {unit}" if unit else ""))
        table.add_row("waypoints", str(len(result.path)))
    table.add_row("expanded", f"{result.expanded:,}")
    table.add_row("max frontier", f"{result.max_frontier:,}")
    table.add_row("line-of-sight checks", f"{result.los_checks:,}")
    table.add_row("search time", f"{result.seconds * 1e3:.3f} ms")
    if "setup_seconds" in result.extra:
        table.add_row("set-up time", f"{result.extra['setup_seconds'] * 1e3:.3f} ms "
                      "(first query: masks, tables, compiled kernels)")
    for label, path in files:
        if path:
            table.add_row(label, str(path))
    return table


def wide_console() -> Console:
    """Stdout for wide tables: at least 160 columns when it is a file or a pipe (where
    Rich would otherwise wrap every cell at 80)."""
    from rich.console import Console

    out = Console()
    return out if out.is_terminal else Console(width=160)


def shows_progress(console: Console) -> bool:
    """Whether progress (a bar, a status line) shows on ``console``: only on an
    interactive terminal, never on a file or a pipe (a log, CI), where it would garble
    what is read there."""
    return console.is_interactive


def progress_bar(console: Console, *, elapsed: bool = False) -> Progress:
    """The progress bar of a long run (description, bar, done/total, time left or, with
    ``elapsed``, time taken), on ``console`` (stderr), gone when finished.

    It shows only on an interactive terminal: where stderr is a file or a pipe (a log,
    CI) it writes nothing at all (Rich would leave an empty line per bar there). A task
    without a total (a phase of unknown length) shows a moving bar and no count."""
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )
    from rich.text import Text

    class Count(MofNCompleteColumn):
        def render(self, task) -> Text:
            return Text("") if task.total is None else super().render(task)

    return Progress(TextColumn("{task.description}"), BarColumn(), Count(),
                    TimeElapsedColumn() if elapsed else TimeRemainingColumn(),
                    console=console, transient=True, disable=not shows_progress(console))
