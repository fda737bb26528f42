"""The Rich table that shows one PlanResult."""

from __future__ import annotations

from rich.table import Table

from skyroute.result import PlanResult


def result_table(title: str, result: PlanResult, *, unit: str = "",
                 files: tuple[tuple[str, object], ...] = ()) -> Table:
    """Status, cost, waypoints, statistics and written files of one result."""
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
