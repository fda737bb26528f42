"""Rich output shared by commands: the PlanResult table, a console wide enough for tables,
how every table is laid out to fit a terminal, the progress bar of long runs and where
progress shows."""

from __future__ import annotations

import os
import re
from collections.abc import Sequence
from typing import TYPE_CHECKING

from skyroute.result import PlanResult

if TYPE_CHECKING:  # Rich is imported on use: `skyroute plan --json` prints without it
    from rich.console import Console
    from rich.progress import Progress
    from rich.table import Table


def result_table(title: str, result: PlanResult, *, unit: str,
                 metres_per_unit: float | None = None,
                 files: tuple[tuple[str, object], ...] = (),
                 set_up: str = "masks, tables, compiled kernels") -> Table:
    """Status, cost, waypoints, statistics and written files of one result.

    ``unit`` names the cost's unit ("cells" on a grid map, "m" or "deg" in a world);
    ``metres_per_unit``, when given and not 1, adds the cost in metres (a grid of
    0.5 m cells: "6.000000 cells (3.000000 m)"). Numbers have thousands separators, and
    as many decimals wherever they appear: costs 6, milliseconds 3. ``set_up`` says
    what a first query's set-up time (``extra["setup_seconds"]``) holds."""
    from rich.table import Table

    table = Table(title=title, show_header=False)
    table.add_column(style="bold")
    table.add_column(overflow="fold")  # a long file path folds; numbers stay whole
    table.add_row("status", result.status.value)
    if result.found:
        cost = f"{result.cost:,.6f} {unit}"
        if metres_per_unit is not None and metres_per_unit != 1:
            cost += f" ({result.cost * metres_per_unit:,.6f} m)"
        table.add_row("cost", cost)
        table.add_row("waypoints", f"{len(result.path):,}")
    table.add_row("expanded", f"{result.expanded:,}")
    table.add_row("max frontier", f"{result.max_frontier:,}")
    table.add_row("line-of-sight checks", f"{result.los_checks:,}")
    table.add_row("search time", f"{result.seconds * 1e3:,.3f} ms")
    if "setup_seconds" in result.extra:
        table.add_row("set-up time", f"{result.extra['setup_seconds'] * 1e3:,.3f} ms "
                      f"(first query: {set_up})")
    for label, path in files:
        if path:
            table.add_row(label, str(path))
    return table


def plain_console(*, stderr: bool = False, width: int | None = None) -> Console:
    """A Rich console that prints text as given, markup off: what the CLI prints holds
    file, map and scenario names, where markup took `[bold]` as a style (dropped from
    the name) and `[/]` as a closing tag (a MarkupError traceback), and "pip install
    'skyroute[bench]'" lost its extra. Colour goes by ``style=`` instead."""
    from rich.console import Console

    return Console(stderr=stderr, width=width, markup=False)


def wide_console() -> Console:
    """Stdout for wide tables: ``$COLUMNS`` when set (as every console), else the
    terminal's width, else 160 columns in a file or a pipe (where Rich would otherwise
    wrap every cell at 80). ``COLUMNS=80 skyroute bench grid ... | cat`` was 160 wide."""
    out = plain_console()
    if out.is_terminal or _columns_set():
        return out
    return plain_console(width=160)


def _columns_set() -> bool:
    """``$COLUMNS`` holds a width, as Rich reads it (digits; 0 is no width)."""
    columns = os.environ.get("COLUMNS", "")
    return columns.isdigit() and int(columns) > 0


# A word that starts like a number ("12.5", "±3.2", "(0.00%)", "256x256", "1,900"): it is
# never split across lines. Paths and names may fold where their column allows it.
_NUMBER = re.compile(r"[(±+-]?\.?\d")


def print_table(console: Console, table: Table, *, optional: Sequence[str] = ()) -> None:
    """Print ``table`` on ``console`` laid out by :func:`fit_table`."""
    console.print(fit_table(console, table, optional=optional))


def fit_table(console: Console, table: Table, *, optional: Sequence[str] = ()) -> Table:
    """``table`` (changed in place) laid out to fit ``console`` with no number split across
    lines, the one rule of every table the CLI prints.

    Rich narrows the widest columns first and then all of them evenly, cutting through
    words, so at 80 columns a sweep read "35." over "2". Here each column is at least its
    longest number or header word (and its longest word unless its overflow is "fold", as
    for file paths), and the width left over goes to the columns that need least more to
    show on one line. When that is still too wide the table drops its vertical
    lines, and then the ``optional`` columns (named by header, the last first) with a
    caption that names them. A table that fits is printed as built."""
    from rich import box

    cols, extra = _measure(console, table)
    if sum(hi for _, hi in cols) + extra <= console.width:
        return table
    if sum(lo for lo, _ in cols) + extra > console.width:
        table.box, table.show_edge, table.pad_edge = box.SIMPLE_HEAD, False, False
        table.collapse_padding = True
        cols, extra = _measure(console, table)
    dropped = []
    for header in reversed(optional):
        if sum(lo for lo, _ in cols) + extra <= console.width:
            break
        table.columns = [c for c in table.columns if c.header != header]
        for i, c in enumerate(table.columns):
            c._index = i  # Rich pads the first and last column by this index
        dropped.append(" ".join(str(header).split()))
        cols, extra = _measure(console, table)
    if dropped:
        note = f"not shown at {console.width} columns: {', '.join(reversed(dropped))}"
        table.caption = f"{table.caption}\n{note}" if table.caption else note
    spare = console.width - extra - sum(lo for lo, _ in cols)
    if spare < 0:
        return table  # narrower than any layout with whole words: Rich's own
    # the columns that need least get all they need first, so that at most one column
    # has some cells wrapped and others not
    for c, (lo, hi) in sorted(zip(table.columns, cols, strict=True),
                              key=lambda col: col[1][1] - col[1][0]):
        give = min(hi - lo, spare)
        c.width, spare = lo + give, spare - give
    return table


def _measure(console: Console, table: Table) -> tuple[list[tuple[int, int]], int]:
    """Each column's (least, natural) width of its text, and the width of the rest (lines
    and padding)."""
    from rich.measure import Measurement

    opts = console.options.update_width(100_000)
    cols = []
    for c in table.columns:
        body = list(c.cells)
        head = [Measurement.get(console, opts, c.header)] if table.show_header else []
        sizes = head + [Measurement.get(console, opts, x) for x in body]
        words = [w for x in body if isinstance(x, str) for w in x.split()]
        least = max([m.minimum for m in head]
                    + [len(w) for w in words if c.overflow != "fold" or _NUMBER.match(w)]
                    + [m.minimum for x, m in zip(body, sizes[len(head):], strict=True)
                       if not isinstance(x, str)]
                    + [c.min_width or 0, 1])
        cols.append((least, max([m.maximum for m in sizes] + [least])))
    extra = Measurement.get(console, opts, table).maximum
    return cols, extra - sum(hi for _, hi in cols)


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

    return Progress(TextColumn("{task.description}", markup=False), BarColumn(), Count(),
                    TimeElapsedColumn() if elapsed else TimeRemainingColumn(),
                    console=console, transient=True, disable=not shows_progress(console))
