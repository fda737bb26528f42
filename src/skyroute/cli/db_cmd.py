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


# Where a field of an order comes from in the ILP CSVs (for messages)
CSV_FIELDS = {"date": ("orders.csv", "deliveryDate"), "customer": ("orders.csv", "customer"),
              "deliver_to": ("orders.csv", "deliverTo"), "items": ("orderDetails.csv", "items")}
REPLACE_HELP = ("Store the files' orders of each day whose stored orders differ (an order "
                "corrected or removed), deleting that day's stored deliveries and flight "
                "path.")


def import_folder(engine, data: Path, *, replace: bool, orders: list | None = None):
    """Import ``data/database``'s orders (:func:`~skyroute.delivery.store.import_orders`;
    ``orders``: those files' orders when already read): how many the files hold, and
    what was done. Stored orders that the files contradict are one line naming the
    file, the days and ``--replace``."""
    from skyroute.delivery.orders import read_csv_orders
    from skyroute.delivery.store import OrdersChangedError, import_orders, shown
    from skyroute.errors import SkyrouteError

    if orders is None:
        orders = read_csv_orders(data)
    try:
        return len(orders), import_orders(engine, orders, replace=replace)
    except OrdersChangedError as exc:
        _, no, field, old, new = exc.changes[0]
        name, column = CSV_FIELDS.get(field, ("orders.csv", None))
        what = (f"order {no} is stored but not in the file" if field is None else
                f"order {no}: {column} {shown(new)}, stored {shown(old)}")
        raise SkyrouteError(f"{data / 'database' / name}: the orders of {some_days(exc.days)} "
                            "differ from "
                            f"the stored ones ({what}); --replace stores the file's orders "
                            "of " + ("that day" if len(exc.days) == 1 else "those days")
                            + ", deleting what was flown from the stored ones") from None


@db_app.command("import")
def db_import(
    data: Annotated[Path, typer.Argument(metavar="DIR", help="Data folder with database/orders"
                                         ".csv and database/orderDetails.csv.")],
    db: Annotated[str, typer.Option(help="SQLAlchemy URL of the store.")] = DEFAULT_DB,
    replace: Annotated[bool, typer.Option("--replace", help=REPLACE_HELP)] = False,
) -> None:
    """Load orders and their items; orders already stored as in the files are left as they
    are, and orders stored otherwise are an error unless --replace."""
    from skyroute.delivery.days import open_store
    from skyroute.delivery.orders import read_csv_orders

    # read before the store is opened: malformed files leave no new store behind
    orders = read_csv_orders(data)
    n, got = import_folder(open_store(db), data, replace=replace, orders=orders)
    plain_console().print(f"{safe_url(db)}: {got.added:,} orders added, {n - got.added:,} "
                          f"already there ({got.had + got.added:,} stored)" + replaced(got),
                          soft_wrap=True)


def replaced(got) -> str:
    """'; replaced the stored orders of DAYS (...)' for an import that replaced days, else
    ''."""
    if not got.replaced:
        return ""
    return (f"; replaced the stored orders of {some_days(got.replaced)} (what was flown "
            "from them is deleted)")


def some_days(days, most: int = 3) -> str:
    """The first ``most`` of ``days`` and how many more: '2024-01-01, 2024-01-02 and 5
    more days'."""
    text = ", ".join(str(d) for d in days[:most])
    return text + (f" and {len(days) - most:,} more days" if len(days) > most else "")
