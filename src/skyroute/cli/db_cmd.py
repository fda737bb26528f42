"""``skyroute db``: make the store's tables and load the ILP order CSVs into it."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from skyroute.cli.tables import plain_console
from skyroute.delivery.store import DEFAULT_DB, safe_url

db_app = typer.Typer(help="The SQL store of orders, deliveries and flight paths.",
                     no_args_is_help=True)


@db_app.command("init")
def db_init(db: Annotated[str, typer.Option(help="SQLAlchemy URL of the store.")] =
            DEFAULT_DB) -> None:
    """Create the tables, or upgrade them to the newest migration."""
    from skyroute.delivery.days import open_store
    from skyroute.delivery.store import init

    rev = init(open_store(db))
    plain_console().print(f"{safe_url(db)}: schema at revision {rev}", soft_wrap=True)


@db_app.command("import")
def db_import(
    data: Annotated[Path, typer.Argument(metavar="DIR", help="Data folder with database/orders"
                                         ".csv and database/orderDetails.csv.")],
    db: Annotated[str, typer.Option(help="SQLAlchemy URL of the store.")] = DEFAULT_DB,
) -> None:
    """Load orders and their items; orders already stored are left as they are."""
    from skyroute.delivery.days import open_store
    from skyroute.delivery.orders import read_csv_orders
    from skyroute.delivery.store import import_orders

    orders = read_csv_orders(data)
    added, had = import_orders(open_store(db), orders)
    plain_console().print(f"{safe_url(db)}: {added:,} orders added, {len(orders) - added:,} "
                          f"already there ({had + added:,} stored)", soft_wrap=True)
