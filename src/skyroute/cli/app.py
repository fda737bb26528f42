"""The ``skyroute`` Typer application and its entry point."""

from __future__ import annotations

import typer
from rich.console import Console
from rich.table import Table

from skyroute.cli import (
    bench_fleet_cmd,  # noqa: F401  (registers 'bench fleet')
    bench_jobs_cmd,  # noqa: F401  (registers 'bench jobs')
    bench_service_cmd,  # noqa: F401  (registers 'bench service')
    bench_world_cmd,  # noqa: F401  (registers 'bench world')
)
from skyroute.cli.bench_cmd import bench_app
from skyroute.cli.data_cmd import data_app
from skyroute.cli.db_cmd import db_app
from skyroute.cli.deliver_cmd import deliver_command
from skyroute.cli.errors import run_cli
from skyroute.cli.fleet_cmd import fleet_app
from skyroute.cli.fly_cmd import fly_command
from skyroute.cli.plan_cmd import plan_command, prepare_command
from skyroute.cli.serve_cmd import serve_command
from skyroute.cli.world_cmd import plan_world_command, synth_city_command
from skyroute.world.load import bundled_maps
from skyroute.world.movingai import read_map

app = typer.Typer(help="skyroute: plan where drones and small robots fly or drive, and what "
                       "they deliver.",
                  no_args_is_help=True, add_completion=False, pretty_exceptions_enable=False)
app.command("plan")(plan_command)
app.command("prepare")(prepare_command)
app.command("plan-world")(plan_world_command)
app.command("synth-city")(synth_city_command)
app.command("fly")(fly_command)
app.add_typer(bench_app, name="bench")
app.command("deliver")(deliver_command)
app.add_typer(db_app, name="db")
app.add_typer(data_app, name="data")
app.add_typer(fleet_app, name="fleet")
app.command("serve")(serve_command)


@app.command("maps")
def maps_command() -> None:
    """List the MovingAI maps bundled with skyroute (usable by name as MAP)."""
    table = Table(title="bundled maps (Sturtevant 2012, MovingAI; see CITATION.md)")
    for col in ("name", "size", "free", "scenario lines", "file"):
        table.add_column(col)
    for name, path in bundled_maps().items():
        grid = read_map(path)
        scen = path.with_name(path.name + ".scen")
        lines = len(scen.read_text().splitlines()) - 1 if scen.exists() else 0
        table.add_row(name, f"{grid.width}x{grid.height}", f"{grid.free_fraction:.0%}",
                      str(lines), str(path))
    Console().print(table)


def main() -> None:
    """Console entry point."""
    run_cli(app)
