"""``skyroute bench jobs``: a range of delivery days on local processes and on Dask."""

from __future__ import annotations

import datetime as dt
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from skyroute.bench.machine import machine
from skyroute.cli.bench_cmd import bench_app
from skyroute.cli.parse import parse_date
from skyroute.cli.tables import plain_console, print_table, progress_bar, wide_console
from skyroute.errors import OptionError
from skyroute.files import check_writable, write_atomic
from skyroute.io.json_text import to_json


def _day(text: str, option: str) -> dt.date:
    return parse_date(text, option)


@bench_app.command("jobs")
def bench_jobs_command(
    data: Annotated[Path, typer.Option(
        help="Data folder in the ILP layout (website/, database/).")],
    first: Annotated[str, typer.Option("--from", help="First day.")] = "2022-01-01",
    last: Annotated[str, typer.Option("--to", help="Last day.")] = "2023-12-31",
    runs: Annotated[str, typer.Option(
        help="Executors to time, KIND:WORKERS comma-separated (KIND local or dask).")] =
        "local:1,local:2,dask:1,dask:2",
    simulate: Annotated[str, typer.Option(
        help="Worker counts to simulate from the local:1 task times ('' for none).")] =
        "1,2,4,8,16",
    method: Annotated[str, typer.Option(help="milp or greedy.")] = "milp",
    json_out: Annotated[Path | None, typer.Option("--json", help="Write the rows here.")] =
        None,
) -> None:
    """Time a range of delivery days on each executor; simulate more workers."""
    from skyroute.bench.jobs import bench_jobs, parse_counts, parse_runs
    from skyroute.bench.jobs import simulate as simulated

    d0, d1 = _day(first, "--from"), _day(last, "--to")
    if d1 < d0:
        raise OptionError(f"--to {d1} is before --from {d0}")
    plan = parse_runs(runs)
    counts = parse_counts(simulate)
    if json_out:  # a bad path fails now, not after the runs
        check_writable(json_out)
    n_days = (d1 - d0).days + 1
    with progress_bar(plain_console(stderr=True)) as progress:
        task = progress.add_task("days", total=n_days * len(plan))
        got = bench_jobs(data, d0, d1, plan, method=method,
                         on_day=lambda: progress.advance(task))
    rows, durations = got["rows"], got["durations"]
    base = next((r["start_seconds"] + r["wall_seconds"] for r in rows
                 if (r["executor"], r["workers"]) == ("local", 1)), None)
    t = Table(title=f"{n_days} delivery days ({d0} to {d1}, {method}), measured")
    for col in ("executor", "workers", "start s", "range s", "total s", "speed-up",
                "mean %", "min %"):
        t.add_column(col, justify="left" if col == "executor" else "right")
    for r in rows:
        total = r["start_seconds"] + r["wall_seconds"]
        t.add_row(r["executor"], f"{r['workers']:,}", f"{r['start_seconds']:,.1f}",
                  f"{r['wall_seconds']:,.1f}", f"{total:,.1f}",
                  "-" if base is None else f"{base / total:.2f}x",
                  f"{r['mean_pct']:.2f}" if r["mean_pct"] is not None else "-",
                  f"{r['min_pct']:.2f}" if r["min_pct"] is not None else "-")
    out = wide_console()
    print_table(out, t)
    sims = simulated(rows, durations, counts) if durations and counts else []
    if sims:
        s = Table(title=f"simulated from the local:1 task times (sum {sum(durations):,.1f} "
                        f"s, longest day {max(durations):,.2f} s)")
        for col in ("workers", "local s", "speed-up", "dask s", "dask speed-up"):
            s.add_column(col, justify="right")
        for r in sims:
            dask = r["dask_seconds"] is not None
            s.add_row(f"{r['workers']:,}", f"{r['local_seconds']:,.1f}", f"{r['speedup']:.2f}x",
                      f"{r['dask_seconds']:,.1f}" if dask else "-",
                      f"{r['dask_speedup']:.2f}x" if dask else "-")
        print_table(out, s)
    if json_out:
        write_atomic(json_out, to_json(
            {"settings": {"data": str(data), "from": str(d0), "to": str(d1),
                          "method": method, "runs": runs, "simulate": counts},
             "machine": machine(("dask", "distributed")),
             "rows": rows, "simulated": sims, "durations": durations}, indent=1))

