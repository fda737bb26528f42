"""Orders: read from the ILP CSVs (``database/orders.csv``, ``orderDetails.csv``) with
every bad row named by file and line, and priced against a site's menus.

An order is valid with 1-4 items, every item on a menu, from at most 2 shops, and a
deliverTo place that exists, is inside the area and outside every zone; its cost is the
item prices (a repeated item counts each time) plus the 50p delivery charge (SPEC.md
4.4). An invalid order is kept with its reason, never dropped silently.
"""

from __future__ import annotations

import csv
import datetime as dt
import io
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path

from skyroute.delivery.site import check_place
from skyroute.errors import InputFormatError
from skyroute.files import need_folder, read_text

CHARGE = 50
MAX_ITEMS = 4
MAX_SHOPS = 2
ORDERS_HEADER = ["orderNo", "deliveryDate", "customer", "deliverTo"]
DETAILS_HEADER = ["orderNo", "item"]
# The longest text each field's store column keeps (migration 0001; a test checks they
# agree): checked as the file is read, so a customer 'cust-00012' is its file and line,
# before any store is opened, not a store-level error naming neither, after a new
# store (its folder, file and tables) was made.
WIDTHS = {"orderNo": 8, "customer": 8, "deliverTo": 64, "item": 100}


@dataclass(frozen=True)
class Order:
    order_no: str
    date: dt.date
    customer: str
    deliver_to: str  # what3words
    items: tuple[str, ...]


@dataclass(frozen=True)
class Priced:
    """A valid order: its cost in pence, shops in pick-up order of the menu, and place."""

    order: Order
    cost: int
    shops: tuple[int, ...]
    lonlat: tuple[float, float]


def price(site, order: Order) -> Priced | str:
    """The priced order, or the reason it cannot be delivered."""
    if not order.items:
        return "no items"
    if len(order.items) > MAX_ITEMS:
        return f"{len(order.items)} items (at most {MAX_ITEMS})"
    shops, cost = [], CHARGE
    for item in order.items:
        if item not in site.menu:
            return f"unknown item {item!r}"
        pence, shop = site.menu[item]
        cost += pence
        if shop not in shops:
            shops.append(shop)
    if len(shops) > MAX_SHOPS:
        return f"items from {len(shops)} shops (at most {MAX_SHOPS})"
    try:
        p = site.locate(order.deliver_to)
        check_place(site, f"deliverTo {order.deliver_to!r}", order.deliver_to, p)
    except InputFormatError as exc:
        return str(exc)
    return Priced(order, cost, tuple(shops), p)


def _rows(path: Path, header: list[str]):
    """(line number, row) of a CSV with exactly ``header``'s columns."""
    if not path.is_file():
        raise InputFormatError(path, "no such file")
    reader = csv.reader(io.StringIO(read_text(path)))  # a byte-order mark read past
    first = next(reader, None)
    if first is None:
        raise InputFormatError(path, f"the file is empty; expected the header "
                               f"{','.join(header)}", line=1)
    # spaces around a name are read past, as around a value ("orderNo, deliveryDate")
    if [v.strip() for v in first] != header:
        raise InputFormatError(path, f"header {first!r}; expected {header!r}", line=1)
    for row in reader:
        if not any(v.strip() for v in row):  # a blank line, or one of spaces only
            continue
        if len(row) != len(header) or not all(v.strip() for v in row):
            raise InputFormatError(path, f"expected {len(header)} non-empty fields "
                                   f"({', '.join(header)}), found {row!r}",
                                   line=reader.line_num)
        for name, v in zip(header, row, strict=True):
            if "\0" in v:  # SQLite stored it, PostgreSQL refused the whole import
                raise InputFormatError(path, f"{name} {v.strip()!r} holds a NUL character, "
                                       "which a PostgreSQL store cannot keep",
                                       line=reader.line_num)
            v = v.strip()
            if len(v) > WIDTHS.get(name, len(v)):
                raise InputFormatError(path, f"{name} {v!r} is {len(v)} characters; the "
                                       f"store keeps at most {WIDTHS[name]}",
                                       line=reader.line_num)
        yield reader.line_num, [v.strip() for v in row]


def read_csv_orders(root: Path) -> list[Order]:
    """Every order of ``root/database`` with its items (in file order)."""
    opath = need_folder(root) / "database" / "orders.csv"
    dpath = root / "database" / "orderDetails.csv"
    heads = []
    seen: set[str] = set()
    for line, (no, date, customer, to) in _rows(opath, ORDERS_HEADER):
        try:
            day = dt.date.fromisoformat(date)
        except ValueError:
            raise InputFormatError(opath, f"deliveryDate {date!r} is not YYYY-MM-DD",
                                   line=line) from None
        if no in seen:
            raise InputFormatError(opath, f"orderNo {no!r} appears twice", line=line)
        seen.add(no)
        heads.append((no, day, customer, to))
    items = defaultdict(list)
    for line, (no, item) in _rows(dpath, DETAILS_HEADER):
        if no not in seen:
            raise InputFormatError(dpath, f"orderNo {no!r} is not in orders.csv", line=line)
        items[no].append(item)
    return [Order(no, day, c, to, tuple(items[no])) for no, day, c, to in heads]
