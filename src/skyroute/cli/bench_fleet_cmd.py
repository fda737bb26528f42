"""``skyroute bench fleet``: the fleet simulation's speed on the issue's two large cases."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from skyroute.bench.fleet import CASES, bench_case
from skyroute.bench.machine import machine
from skyroute.cli.bench_cmd import bench_app
from skyroute.cli.tables import plain_console, print_table, progress_bar, wide_console
from skyroute.errors import SEED_MAX, OptionError, check_choice
from skyroute.files import check_writable, write_atomic
from skyroute.io.json_text import to_json


@bench_app.command("fleet")
def bench_fleet(
    case: Annotated[list[int] | None, typer.Option(
        help="Only case K (repeatable; 1: 100 drones/30 airports/24 h, 2: 1000 drones/100 "
             "airports/1 h).")] = None,
    scheduler: Annotated[str, typer.Option(help="seed or optimal.")] = "optimal",
    airspace: Annotated[str, typer.Option(help="layers or shared.")] = "shared",
    seed: Annotated[int, typer.Option(
        min=0, max=SEED_MAX, help="Seed of the package stream.")] = 0,
    json_out: Annotated[Path | None, typer.Option("--json", help="Write the rows here.")] =
        None,
) -> None:
    """Time large fleet simulations (and the separation check of every piece)."""
    check_choice("scheduler", scheduler, ("seed", "optimal"))
    check_choice("airspace", airspace, ("layers", "shared"))
    chosen = case or list(range(1, len(CASES) + 1))
    for k in chosen:
        if not 1 <= k <= len(CASES):
            raise OptionError(f"--case {k} is not valid; choose 1 to {len(CASES)}")
    if json_out:  # a bad path fails now, not after the runs
        check_writable(json_out)
    err = plain_console(stderr=True)
    rows = []
    with progress_bar(err, elapsed=True) as progress:
        for k in chosen:
            name, airports, drones, area, hours, rate = CASES[k - 1]
            task = progress.add_task(name, total=round(hours * 3600))
            row = bench_case(airports, drones, area, hours, rate, scheduler=scheduler,
                             airspace=airspace, seed=seed,
                             progress=lambda t, task=task: progress.update(
                                 task, completed=round(t)))
            progress.remove_task(task)
            rows.append({"case": name, **row})
    t = Table(title=f"fleet simulation speed ({scheduler} + {airspace}, seed {seed})")
    for col in ("case", "offered/h", "flights", "simulate s", "check s", "simulated s/s",
                "delivered/h", "conflicts", "lost"):
        t.add_column(col, justify="left" if col == "case" else "right")
    for r in rows:
        t.add_row(r["case"], f"{r['rate_per_hour']:,.0f}", f"{r['flights']:,}",
                  f"{r['sim_seconds']:,.1f}", f"{r['check_seconds']:,.2f}",
                  f"{r['sim_seconds_per_wall_second']:,.0f}",
                  f"{r['delivered_per_hour']:,.0f}", f"{r['conflicts']:,}", f"{r['lost']:,}")
    # the speed is the point; the traffic columns give way first on a narrow terminal
    print_table(wide_console(), t, optional=("conflicts", "lost", "delivered/h", "offered/h"))
    if json_out:
        # the options, as every bench report keeps them (this one had none)
        settings = {"case": chosen, "scheduler": scheduler, "airspace": airspace,
                    "seed": seed}
        write_atomic(json_out, to_json({"settings": settings, "machine": machine(),
                                           "rows": rows}, indent=1))
