"""Orders: SPEC.md 4.4 pricing checked against the data set's own daily totals; invalid
orders keep their reason; bad CSV rows are named by file and line."""

from __future__ import annotations

import csv
import datetime as dt
import shutil
from collections import defaultdict

import pytest

from skyroute.delivery.orders import Order, Priced, price, read_csv_orders
from skyroute.delivery.site import load_site
from skyroute.delivery.source import DirSource
from skyroute.errors import InputFormatError
from tests.conftest import SHARED

ILP = SHARED / "ilp2021"
pytestmark = pytest.mark.shared_data


@pytest.fixture(scope="module")
def site():
    return load_site(DirSource(ILP))


def test_every_day_prices_to_the_published_daily_total(site):
    """daily_summary.csv (derived by the data's curators) for all 730 days."""
    totals = defaultdict(int)
    orders = read_csv_orders(ILP)
    assert len(orders) == 11_334 and sum(len(o.items) for o in orders) == 28_393
    for o in orders:
        p = price(site, o)
        assert isinstance(p, Priced), p
        totals[o.date.isoformat()] += p.cost
    with (ILP / "database" / "daily_summary.csv").open() as f:
        expect = {r["deliveryDate"]: int(r["totalValuePence"]) for r in csv.DictReader(f)}
    assert totals == expect


def test_invalid_orders_say_why(site):
    d = dt.date(2022, 1, 1)
    rudis = next(i for i, (_, s) in site.menu.items() if s == 0)
    greggs = next(i for i, (_, s) in site.menu.items() if s == 1)
    nile = next(i for i, (_, s) in site.menu.items() if s == 2)
    to = "less.change.atomic"
    two = price(site, Order("a", d, "c", to, (rudis, rudis, greggs)))
    assert two.cost == 50 + 2 * site.menu[rudis][0] + site.menu[greggs][0]  # repeats count
    assert two.shops == (0, 1)
    assert price(site, Order("b", d, "c", to, (rudis,) * 5)) == "5 items (at most 4)"
    assert "3 shops" in price(site, Order("c", d, "c", to, (rudis, greggs, nile)))
    assert price(site, Order("e", d, "c", to, ("Deep-fried Mars bar",))) == \
        "unknown item 'Deep-fried Mars bar'"
    assert price(site, Order("f", d, "c", to, ())) == "no items"
    missing = price(site, Order("g", d, "c", "no.such.place", (rudis,)))
    assert "no/such/place/details.json" in missing and "no such file" in missing


@pytest.mark.parametrize("edit, words", [
    (lambda t: t.replace("4e67bb23,2022-01-01,s2210630,less.change.atomic",
                         "4e67bb23,2022-01-01,s2210630"), "orders.csv:2: expected 4"),
    (lambda t: t.replace("4e67bb23,2022-01-01", "4e67bb23,2022-13-01"),
     "orders.csv:2: deliveryDate '2022-13-01'"),
    (lambda t: t.replace("orderNo,deliveryDate", "order,deliveryDate"), "orders.csv:1: header"),
])
def test_malformed_csv_rows_are_named(tmp_path, edit, words):
    shutil.copytree(ILP / "database", tmp_path / "database")
    p = tmp_path / "database" / "orders.csv"
    p.write_text(edit(p.read_text()))
    with pytest.raises(InputFormatError, match=words):
        read_csv_orders(tmp_path)


def test_item_row_of_an_unknown_order_is_named(tmp_path):
    shutil.copytree(ILP / "database", tmp_path / "database")
    p = tmp_path / "database" / "orderDetails.csv"
    p.write_text(p.read_text() + "ffffffff,Ham and mozzarella Italian roll\n")
    with pytest.raises(InputFormatError, match=r"orderDetails.csv:28395: orderNo 'ffffffff'"):
        read_csv_orders(tmp_path)
