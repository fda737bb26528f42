"""The ``skyroute`` Typer application and its entry point.

Every command is registered by a loader that imports its module when the command runs
(:mod:`skyroute.cli.lazy_group`), so each command pays only for its own imports:
``skyroute plan`` on a grid loads numpy, numba, Typer and Rich, not pydantic, SQLAlchemy,
scipy.linalg or shapely (tests/cli/test_startup.py).
"""

from __future__ import annotations

import contextlib
import gc
import os
import signal
import sys

import typer

from skyroute.cli.errors import run_cli
from skyroute.cli.lazy_group import lazy_group


def _plan():
    from skyroute.cli.plan_cmd import plan_command

    return plan_command


def _prepare():
    from skyroute.cli.plan_cmd import prepare_command

    return prepare_command


def _plan_world():
    from skyroute.cli.world_cmd import plan_world_command

    return plan_world_command


def _synth_city():
    from skyroute.cli.world_cmd import synth_city_command

    return synth_city_command


def _fly():
    from skyroute.cli.fly_cmd import fly_command

    return fly_command


def _bench():
    from skyroute.cli import (
        bench_fleet_cmd,  # noqa: F401  (registers 'bench fleet')
        bench_jobs_cmd,  # noqa: F401  (registers 'bench jobs')
        bench_service_cmd,  # noqa: F401  (registers 'bench service')
        bench_world_cmd,  # noqa: F401  (registers 'bench world' and 'bench motion')
    )
    from skyroute.cli.bench_cmd import bench_app

    return bench_app


def _deliver():
    from skyroute.cli.deliver_cmd import deliver_command

    return deliver_command


def _db():
    from skyroute.cli.db_cmd import db_app

    return db_app


def _data():
    from skyroute.cli.data_cmd import data_app

    return data_app


def _fleet():
    from skyroute.cli.fleet_cmd import fleet_app

    return fleet_app


def _serve():
    from skyroute.cli.serve_cmd import serve_command

    return serve_command


def _maps():
    return maps_command


# In the order of 'skyroute --help': commands, then groups (as Typer lists them).
COMMANDS = {"plan": _plan, "prepare": _prepare, "plan-world": _plan_world,
            "synth-city": _synth_city, "fly": _fly, "deliver": _deliver, "serve": _serve,
            "maps": _maps, "bench": _bench, "db": _db, "data": _data, "fleet": _fleet}

app = typer.Typer(help="skyroute: plan where drones and small robots fly or drive, and what "
                       "they deliver.",
                  cls=lazy_group(COMMANDS), no_args_is_help=True, add_completion=False,
                  pretty_exceptions_enable=False)


def _print_version(value: bool) -> None:
    if value:
        from skyroute import __version__

        print(f"skyroute {__version__}")
        raise typer.Exit()


@app.callback()
def _group(version: bool = typer.Option(False, "--version", callback=_print_version,
                                        is_eager=True, help="Print the version and exit.")
           ) -> None:
    # With no command registered Typer would not build a group; a callback makes it one
    # (the loaders' commands are added by the group class).
    pass


def maps_command() -> None:
    """List the MovingAI maps bundled with skyroute (usable by name as MAP)."""
    from rich.table import Table

    from skyroute.cli.tables import plain_console, print_table
    from skyroute.world.load import bundled_maps
    from skyroute.world.movingai import read_map

    table = Table(title="bundled maps (Sturtevant 2012, MovingAI; see CITATION.md)")
    for col in ("name", "size", "free", "scenario lines", "file"):
        table.add_column(col, overflow="fold" if col == "file" else "ellipsis",
                         justify="right" if col in ("size", "free", "scenario lines")
                         else "left")
    for name, path in bundled_maps().items():
        grid = read_map(path)
        scen = path.with_name(path.name + ".scen")
        lines = len(scen.read_text().splitlines()) - 1 if scen.exists() else 0
        table.add_row(name, f"{grid.width}x{grid.height}", f"{grid.free_fraction:.0%}",
                      f"{lines:,}", str(path))
    print_table(plain_console(), table)


def main() -> None:
    """Run the CLI on ``sys.argv``; ends in SystemExit (tests call this)."""
    run_cli(app)


# Commands that leave no processes, pools, servers, connections or temporary files
# behind when they return: the program may end them without Python's teardown.
QUICK_EXIT = frozenset({"plan", "prepare", "maps"})


def console() -> None:
    """The ``skyroute`` program: :func:`main`, then, after a QUICK_EXIT command, the
    process ends at once (``os._exit`` after flushing stdout and stderr). With numba's
    compiler loaded, Python's own teardown of the modules takes about 0.3 s, a quarter of
    a one-query command (docs/benchmarks.md section 3); the command's files are written
    and closed by then. Such a command also runs without Python's cyclic garbage
    collector: importing numba and loading its first kernel allocate about a million
    objects, and the collector's 240 passes over them took 0.08-0.11 s of a cold plan,
    to free nothing the short-lived process needs back.

    Once the command has ended, a first SIGINT or SIGTERM is ignored: its output is printed and
    its files written (or removed), and what is left is Python's teardown (0.3 s and
    more with numba, matplotlib or Dask loaded), in which a Ctrl-C printed a
    KeyboardInterrupt traceback from whatever ran (an atexit hook) or, later, killed the
    process by the signal: a command that had done its work reported as interrupted. A
    second one ends the process at once with the command's exit code, so a teardown that
    hangs (a thread or pool not let go) can still be left."""
    if len(sys.argv) >= 2 and sys.argv[1] in QUICK_EXIT:
        gc.disable()
    try:
        main()
    except SystemExit as done:
        _teardown_signals(done.code)
        if len(sys.argv) < 2 or sys.argv[1] not in QUICK_EXIT:
            raise
        code = done.code
        if code is not None and not isinstance(code, int):
            print(code, file=sys.stderr)
            code = 1
        try:
            sys.stdout.flush()
            sys.stderr.flush()
        except (OSError, ValueError):  # a closed pipe: nothing left to say
            code = code or 1
        os._exit(code or 0)


def _teardown_signals(code) -> None:
    """SIGINT and SIGTERM once the command has ended: the first is ignored (its files
    are written, and the teardown's own clean-up, an atexit hook, a temporary folder,
    runs), the second leaves at once with the command's exit code."""
    status = code if isinstance(code, int) else (0 if code is None else 1)
    seen: list[int] = []

    def handler(signum, frame) -> None:
        seen.append(signum)
        if len(seen) >= 2:
            for stream in (sys.stdout, sys.stderr):
                # closed, or a write under way (a reentrant call)
                with contextlib.suppress(Exception):
                    stream.flush()
            os._exit(status)

    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, handler)
