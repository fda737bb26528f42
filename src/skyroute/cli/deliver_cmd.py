"""``skyroute deliver``: one delivery day, or many in parallel, into the SQL store."""

from __future__ import annotations

import datetime as dt
import time
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.table import Table

from skyroute.cli.db_cmd import REPLACE_HELP, some_days
from skyroute.cli.executor_args import (
    DaskAddress,
    Executor,
    executor_kind,
    executor_warnings,
    open_from_flags,
)
from skyroute.cli.parse import parse_date
from skyroute.cli.tables import plain_console, print_table, progress_bar
from skyroute.delivery.day import METHODS, DayResult
from skyroute.delivery.store import DEFAULT_DB, safe_url
from skyroute.errors import OptionError, SkyrouteError, check_choice
from skyroute.io.json_text import to_json

if TYPE_CHECKING:
    from skyroute.jobs.deliver import DayFailed


def _date(text: str | None, option: str) -> dt.date | None:
    return None if text is None else parse_date(text, option)


def deliver_command(
    date: Annotated[str | None, typer.Argument(metavar="DATE", help="The day, YYYY-MM-DD.")] =
        None,
    first: Annotated[str | None, typer.Option("--from", help="First day of a range.")] = None,
    last: Annotated[str | None, typer.Option("--to", help="Last day of a range.")] = None,
    data: Annotated[Path | None, typer.Option(
        help="Data folder in the ILP layout (website/, database/); its orders are imported "
             "into the store first.")] = None,
    source: Annotated[str | None, typer.Option(
        help="Read website/ from this URL instead (see 'skyroute data serve').")] = None,
    db: Annotated[str, typer.Option(help="SQLAlchemy URL of the store.")] = DEFAULT_DB,
    replace: Annotated[bool, typer.Option("--replace", help=(
        "Store a day whose every order is invalid over its stored flight (kept otherwise); "
        "with --data also " + REPLACE_HELP[0].lower() + REPLACE_HELP[1:]))] = False,
    out: Annotated[Path, typer.Option(help="Folder for the GeoJSON, PNG and report files.")] =
        Path("."),
    jobs: Annotated[int, typer.Option(help="Worker processes for a range of days.")] = 1,
    executor: Executor = None,
    dask: DaskAddress = None,
    method: Annotated[str, typer.Option(help="milp (exact over the leg table) or greedy.")] =
        "milp",
    plot: Annotated[bool | None, typer.Option(
        help="Draw each day's PNG (default: on for one day, off for a range).")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print the report as JSON.")] = False,
) -> None:
    """Fly a day (or a range) of lunch orders for the most money within the battery.

    Stores deliveries and flightpath; writes drone-DD-MM-YYYY.geojson, a report, a map.
    """
    from skyroute.cli.db_cmd import import_folder, replaced
    from skyroute.delivery.days import open_store, prepare_legs, refuse_foreign
    from skyroute.delivery.limits import check_days
    from skyroute.delivery.orders import read_csv_orders
    from skyroute.delivery.site import load_site
    from skyroute.delivery.source import open_source
    from skyroute.delivery.store import DayKeptError, order_dates
    from skyroute.io.day_out import check_outputs, output_paths, write_outputs
    from skyroute.jobs.deliver import DaysFailedError, days_between, run_days

    check_choice("method", method, METHODS)
    day, d0, d1 = _date(date, "DATE"), _date(first, "--from"), _date(last, "--to")
    one_day, ranged = day is not None, d0 is not None or d1 is not None
    if one_day == ranged or (ranged and (d0 is None or d1 is None)):
        raise OptionError("give a DATE, or both --from and --to")
    if day is not None:
        d0 = d1 = day
    check_days(d0, d1, "--from", "--to")
    executor_kind(executor, dask, jobs)
    draw = (day is not None) if plot is None else plot
    # every file of every day checked before anything is flown or stored: a bad --out
    # must not leave rows in the store or some of the days' files behind
    check_outputs(out, [d0 + dt.timedelta(k) for k in range((d1 - d0).days + 1)],
                  plot=draw)
    src = open_source(data, source)
    site = load_site(src)
    # the order files read before the store is opened: a malformed orders.csv left a new
    # store (its file, its folder, its tables) behind
    orders = read_csv_orders(data) if data is not None else []
    # an existing store is opened; a new one is made only once nothing below refuses the
    # command: a refused command left a new store (file, folder, tables) behind
    engine = open_store(db, create=False)
    if data is None and (engine is None or not order_dates(engine)):
        raise SkyrouteError(f"{safe_url(db)}: no orders stored; load them with 'skyroute db "
                            "import DIR' or give --data DIR")
    # the orders each day will have once the files are imported: the files' own for a
    # day they give (the import adds them, or refuses a day stored otherwise), else the
    # stored ones; checked against the site's menus before anything is written
    given: dict[dt.date, list] = {}
    for o in orders:
        if d0 <= o.date <= d1:
            given.setdefault(o.date, []).append(o)
    stored = (days_between(engine, d0, d1) if engine is not None else
              {d0 + dt.timedelta(k): [] for k in range((d1 - d0).days + 1)})
    refuse_foreign(site, {**stored, **given}, stored_in=db, given=given, data=data)
    # the executor before any work: a wrong --dask address fails at once
    with open_from_flags(executor, dask, jobs, (d1 - d0).days + 1) as ex:
        err = plain_console(stderr=True)
        if engine is None:
            engine = open_store(db)
        if data is not None:
            got = import_folder(engine, data, replace=replace, orders=orders)[1]
            if got.added:
                err.print(f"imported {got.added:,} orders from {data / 'database'}"
                          + replaced(got), soft_wrap=True)
        by_date = days_between(engine, d0, d1)
        all_orders = [o for v in by_date.values() for o in v]
        with progress_bar(err) as progress:
            task = progress.add_task("leg table", total=None)
            prepare_legs(site, all_orders, on_leg=lambda: progress.advance(task),
                         on_total=lambda n: progress.update(task, total=n))
            progress.remove_task(task)
            days = progress.add_task("days", total=len(by_date))
            t0 = time.perf_counter()
            written: list[Path] = []  # every file, as written: the one-day table lists them

            def files(r: DayResult) -> None:  # staged; in place once the day is stored
                write_outputs(site, r, out, plot=draw)

            done: list[dt.date] = []  # the days stored, with their files, so far

            def finished(r: DayResult) -> None:
                written.extend(output_paths(out, r.date, plot=draw))
                done.append(r.date)
                progress.advance(days)

            failed: list[DayFailed] = []  # said once the other days are stored
            try:
                with executor_warnings(progress.console):  # e.g. a worker process died
                    results = run_days(engine, src, by_date, executor=ex, method=method,
                                       replace=replace, files=files, on_day=finished,
                                       on_failed=lambda _f: progress.advance(days))
            except DaysFailedError as exc:
                results, failed = exc.stored, exc.failed
            except SkyrouteError as exc:  # storing a day or writing its files: it stops
                kept = isinstance(exc, DayKeptError)
                if one_day and not kept:
                    raise
                text = str(exc) + ("; --replace stores the day as flown now" if kept else "")
                if not one_day:
                    text += f"; {_stopped(sorted(done), len(by_date))}"
                raise SkyrouteError(text) from None
            wall = time.perf_counter() - t0
        workers = ex.workers
    if day is not None:
        if results:
            _one_day(results[0], written, as_json)
    else:
        _summary(results, wall, jobs, workers, ex.kind, as_json, written, failed)
    _say_empty(results, list(by_date))
    if failed:
        _say_failed(failed, len(by_date))


def _stopped(stored: list[dt.date], n: int) -> str:
    """What a range stopped by an error (a full disk, a day kept) left: the days stored
    before it, each with its files, and that no other is (the error alone did not say
    whether the days before it were kept, nor that the later ones were not flown)."""
    if not stored:
        return f"the range stopped there and none of its {n:,} days is stored"
    k = len(stored)
    return (f"the range stopped there: {k:,} of its {n:,} days "
            f"{'is' if k == 1 else 'are'} stored with {'its' if k == 1 else 'their'} "
            f"files ({some_days(stored)}), the other {n - k:,} not")


def _say_empty(results: list[DayResult], dates: list[dt.date]) -> None:
    """A line on stderr for days without orders (stored as empty days, exit 0): a
    mistyped date or orders not imported would otherwise pass for a day flown.
    ``dates``: every day of the run, stored or failed."""
    empty = [r.date for r in results if not r.orders]
    if not empty:
        return
    n = len(dates)
    if n == 1:
        line = f"{empty[0]}: no orders stored for this day; nothing was flown"
    elif len(empty) == n:
        line = (f"nothing was flown: none of the {n:,} days from {dates[0]} to "
                f"{dates[-1]} had orders stored")
    else:
        line = (f"{len(empty):,} of the {n:,} days had no orders stored "
                f"({some_days(empty, 5)}); nothing "
                "was flown on " + ("it" if len(empty) == 1 else "them"))
    plain_console(stderr=True).print(line, soft_wrap=True)


def _say_failed(failed: list[DayFailed], n: int) -> None:
    """The days that failed, after the others are stored and summed up: one line each
    on stderr (a lone day: its error alone) and exit 2; a defect (not a SkyrouteError)
    prints the first such day's traceback before them and exits 1, as an uncaught error
    does."""
    bugs = [f for f in failed if not f.expected]
    if bugs:
        typer.echo(bugs[0].traceback.rstrip(), err=True)
    if n == 1:
        last = failed[0].error
    else:
        for f in failed:
            typer.echo(f"skyroute: error: {f.error}", err=True)
        rest = n - len(failed)
        last = f"all {n:,} days failed and none was stored" if not rest else (
                f"{len(failed):,} of the {n:,} days failed and "
                f"{'was' if len(failed) == 1 else 'were'} not stored; the other {rest:,} "
                f"{'is' if rest == 1 else 'are'} stored, with {'its' if rest == 1 else 'their'}"
                " files")
    if not bugs:
        raise SkyrouteError(last)
    typer.echo(f"skyroute: error: {last}", err=True)
    raise typer.Exit(1)


def _one_day(r: DayResult, files: list[Path], as_json: bool) -> None:
    rep = r.report()
    if as_json:
        typer.echo(to_json(rep))
        return
    t = Table(title=f"delivery day {r.date}", show_header=False)
    t.add_column()
    t.add_column(overflow="fold")  # a long file path folds; numbers stay whole
    pct = rep["money_pct"]
    rows = [("orders placed", f"{rep['orders_placed']:,}"),
            ("delivered", f"{rep['orders_delivered']:,}"),
            ("invalid", f"{rep['orders_invalid']:,}"),
            ("money delivered", f"{rep['money_delivered']:,}p of {rep['money_placed']:,}p"
             + ("" if pct is None else f" ({pct:.2f}%)")),
            ("moves", f"{rep['moves']:,} (battery left {rep['moves_left']:,})"),
            ("time", f"{rep['seconds']:.2f} s"),
            ("files", "\n".join(str(f) for f in files))]
    for k, v in rows:
        t.add_row(k, str(v))
    print_table(plain_console(), t)
    for o, reason in r.invalid:
        # one line however long (Rich wrapped at 80 columns in a pipe or a log)
        plain_console(stderr=True).print(f"invalid order {o.order_no}: {reason}",
                                         soft_wrap=True)


def _summary(results: list[DayResult], wall: float, jobs: int, workers: int, kind: str,
             as_json: bool, files: list[Path], failed: list[DayFailed]) -> None:
    from skyroute.jobs.deliver import summarise

    s = summarise(results)  # of the days stored
    s.update(wall_seconds=wall, jobs=jobs, executor=kind, workers=workers,
             files=len(files), folders=sorted({str(f.parent) for f in files}),
             failed=[{"date": f.date.isoformat(), "error": f.error} for f in failed])
    if as_json:
        typer.echo(to_json(s))
        return
    if not s["days_with_orders"]:  # no table of money: _say_empty says why
        if files:
            plain_console().print(f"wrote {len(files):,} files to {', '.join(s['folders'])}")
        return
    who = f"{workers} job(s)" if kind == "local" else f"{workers} Dask worker(s)"
    # a line of its own: as the title of the narrow monthly table it wrapped at the
    # table's width ("... money" over "delivered mean 99.24%, worst")
    days = f"{s['days']:,} of {s['days'] + len(failed):,}" if failed else f"{s['days']:,}"
    plain_console().print(f"{days} days, {wall:,.1f} s with {who}: money delivered "
                          f"mean {s['mean_pct']:.2f}%, worst {s['min_pct']:.2f}% on "
                          f"{s['min_date']}", soft_wrap=True)
    t = Table()
    for col in ("month", "days", "mean %", "min %"):
        t.add_column(col, justify="left" if col == "month" else "right")
    for m, v in s["months"].items():
        t.add_row(m, f"{v['days']:,}", f"{v['mean_pct']:.2f}", f"{v['min_pct']:.2f}")
    print_table(plain_console(), t)
    if files:
        plain_console().print(f"wrote {len(files):,} files to {', '.join(s['folders'])}")
