"""``skyroute data``: write a synthetic data set, or serve one's website over HTTP."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from skyroute.cli.parse import parse_date
from skyroute.cli.status import delayed_status
from skyroute.cli.tables import plain_console
from skyroute.errors import SEED_MAX
from skyroute.io.json_text import to_json

data_app = typer.Typer(help="Delivery data sets: synthesise one, serve one over HTTP.",
                       no_args_is_help=True)


@data_app.command("synth")
def data_synth(
    folder: Annotated[Path, typer.Argument(metavar="DIR", help="Where to write it.")],
    days: Annotated[int, typer.Option(help="Days of orders.")] = 7,
    orders_per_day: Annotated[int, typer.Option(help="Orders each day.")] = 12,
    customers: Annotated[int, typer.Option(help="Customers' delivery places.")] = 7,
    start: Annotated[str, typer.Option(help="First day, YYYY-MM-DD.")] = "2024-01-01",
    seed: Annotated[int, typer.Option(
        min=0, max=SEED_MAX, help="Seed: the same seed writes the same files.")] = 1,
    replace: Annotated[bool, typer.Option(
        "--replace", help="Write into DIR even when it is not empty (files of the same "
                          "names are replaced).")] = False,
    as_json: Annotated[bool, typer.Option(
        "--json", help="Print the summary as one JSON object.")] = False,
) -> None:
    """Write a synthetic data set in the ILP layout (website/, database/) in another town."""
    first = parse_date(start, "--start")
    _check_folder(folder, replace)
    with delayed_status(f"writing a data set to {folder}"):  # imports included: seconds
        from skyroute.delivery.synth import synth
        from skyroute.files import written_together

        with written_together():  # a Ctrl-C halfway leaves no part of a data set
            summary = synth(folder, days=days, orders_per_day=orders_per_day, seed=seed,
                            start=first, customers=customers)
    # not through Rich: no markup read in the folder's name, no wrapping
    typer.echo(to_json(summary) if as_json else summary_line(summary))


def summary_line(summary: dict) -> str:
    """What ``data synth`` wrote, in one line, as ``synth-city`` says what it wrote (the
    JSON object, which it printed by default, is behind ``--json``)."""
    days = summary["days"]
    span = summary["first"] if days == 1 else f"{summary['first']} to {summary['last']}"
    return (f"wrote {summary['folder']}: {summary['orders']:,} orders over {days:,} "
            f"day{'s' if days != 1 else ''} ({span}), {summary['shops']} shops, "
            f"{summary['customers']:,} customers' places, {summary['zones']} no-fly zones")


def _check_folder(folder: Path, replace: bool) -> None:
    """DIR must be a folder that is new or empty, unless ``--replace``: a data set written
    over another (an earlier one, the wrong folder) replaced its files without a word,
    and a different seed left the old set's places among the new."""
    from skyroute.errors import OptionError

    if folder.exists() and not folder.is_dir():
        raise OptionError(f"{folder}: not a folder")
    if replace or not folder.is_dir():
        return
    names = sorted(p.name for p in folder.iterdir())
    if names:
        shown = ", ".join(names[:3]) + (f" and {len(names) - 3:,} more" if len(names) > 3
                                        else "")
        raise OptionError(f"{folder}: the folder is not empty ({shown}); --replace writes "
                          "the data set into it, replacing files of the same names")


@data_app.command("serve")
def data_serve(
    folder: Annotated[Path, typer.Argument(metavar="DIR", help="A data folder (website/).")],
    port: Annotated[int, typer.Option(min=0, max=65535, help="TCP port (0: any free "
                                      "one).")] = 9898,
    host: Annotated[str, typer.Option(help="Address to listen on.")] = "127.0.0.1",
) -> None:
    """Serve DIR/website over HTTP until interrupted (read it with --source URL)."""
    from skyroute.delivery.serve import make_server

    server = make_server(folder, port, host)
    plain_console(stderr=True).print(f"serving {folder / 'website'} at http://{host}:"
                               f"{server.server_address[1]} (Ctrl-C to stop)")
    try:
        server.serve_forever()
    finally:
        server.server_close()
