"""What ``skyroute deliver`` leaves on disk for a day, checked on a day made by hand (no
flight planned): the files written, and the picture's customer places - served, partly
served, not served - read from matplotlib's objects, not from pixels."""

from __future__ import annotations

import datetime as dt

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

from skyroute.delivery.assemble import DayFlight
from skyroute.delivery.day import DayResult
from skyroute.delivery.orders import price, read_csv_orders
from skyroute.delivery.site import load_site
from skyroute.delivery.source import DirSource
from skyroute.io import day_out
from skyroute.motion.step_drone import Flight
from tests.conftest import ROOT

LUNCH = ROOT / "examples" / "lunch"
DAY = dt.date(2024, 1, 3)


@pytest.fixture(scope="module")
def site():
    return load_site(DirSource(LUNCH))


@pytest.fixture(scope="module")
def orders(site):
    """The lunch data's orders of 2024-01-03 by place (lon, lat), places sorted."""
    by_place: dict = {}
    for o in read_csv_orders(LUNCH):
        if o.date == DAY:
            by_place.setdefault(site.locate(o.deliver_to), []).append(o)
    return dict(sorted(by_place.items()))


def a_day(site, orders, delivered, invalid=()) -> DayResult:
    """A day of ``orders`` with ``delivered`` flown (no moves drawn) and ``invalid``."""
    empty = np.empty((0, 2))
    flight = DayFlight(Flight(empty, np.empty(0, int), empty.copy()), ())
    return DayResult(DAY, list(orders), [(o, "made up") for o in invalid],
                     [price(site, o) for o in delivered], flight, money_placed=1)


@pytest.fixture
def day(site, orders):
    """Place 0: every order delivered; place 1: all but one (partly served); place 2:
    none; place 3: its orders all invalid (never flown: not drawn as a customer)."""
    p = list(orders.values())
    assert len(p) >= 4 and len(p[1]) >= 2
    return a_day(site, [o for os in p[:4] for o in os], delivered=[*p[0], *p[1][1:]],
                 invalid=p[3])


def test_places_are_served_partly_served_or_not(site, orders, day):
    places = list(orders)
    p = list(orders.values())
    assert day_out.customer_places(site, day) == {
        "served": {places[0]: (len(p[0]), len(p[0]))},
        "partly served": {places[1]: (len(p[1]) - 1, len(p[1]))},
        "not served": {places[2]: (0, len(p[2]))},
    }


def test_a_day_with_one_order_left_is_not_all_green(site, orders):
    """The lunch day 2024-01-03 flew 34 of 36 orders, both left at places that had others
    delivered: every place was drawn "served"."""
    every = [o for os in orders.values() for o in os]
    left = {os[0].order_no for os in list(orders.values())[:2]}
    day = a_day(site, every, delivered=[o for o in every if o.order_no not in left])
    places = day_out.customer_places(site, day)
    assert sorted(places["partly served"]) == sorted(list(orders)[:2])
    assert not places["not served"]
    assert len(places["served"]) == len(orders) - 2


def _customers(ax) -> dict:
    return {ln.get_label(): ln for ln in ax.get_lines()
            if ln.get_label().startswith("customer")}


def test_picture_marks_a_partly_served_place_apart(site, orders, day, figures, tmp_path):
    day_out.plot_day(site, day, tmp_path / "d.png")
    (fig,) = figures
    ax = fig.axes[0]
    p = list(orders.values())
    n1 = len(p[1])
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert [t for t in labels if t.startswith("customer")] == [
        "customer served (1 place)",
        f"customer partly served (1 place, {n1 - 1} of {n1} orders)",
        "customer not served (1 place)"]
    lines = _customers(ax)
    served, partly, missed = (lines[t] for t in labels if t.startswith("customer"))
    # another shape and another fill than a served place, where the place is
    assert partly.get_marker() != served.get_marker()
    assert partly.get_fillstyle() != served.get_fillstyle()
    assert partly.get_markerfacecolor() != missed.get_markerfacecolor()
    assert partly.get_xydata().tolist() == [list(list(orders)[1])]


def test_picture_legend_names_only_the_kinds_present(site, orders, figures, tmp_path):
    every = [o for os in orders.values() for o in os]
    day_out.plot_day(site, a_day(site, every, delivered=every), tmp_path / "d.png")
    assert list(_customers(figures[0].axes[0])) == [f"customer served ({len(orders)} places)"]


@pytest.mark.parametrize("plot", [True, False])
def test_write_outputs_returns_every_file_written_and_no_other(site, orders, day, tmp_path,
                                                                plot):
    out = tmp_path / "out"
    paths = day_out.write_outputs(site, day, out, plot=plot)
    names = ["drone-03-01-2024.geojson", "report-03-01-2024.json"] + \
        (["drone-03-01-2024.png"] if plot else [])
    assert [p.name for p in paths] == names
    assert sorted(p.name for p in out.iterdir()) == sorted(names)


def test_an_invalid_order_is_not_a_customer(site, orders):
    only = next(iter(orders.values()))
    day = a_day(site, only, delivered=[], invalid=only)
    assert day_out.customer_places(site, day) == {"served": {}, "partly served": {},
                                                 "not served": {}}


def test_the_title_says_a_day_without_orders_or_valid_orders_and_moves_as_the_table(
        site, orders, figures, tmp_path):
    """An empty day's picture read "0/0 orders, no orders, 0 moves"; one whose orders
    were all invalid "0/N orders, no orders"; and a day of 1,442 moves "1442 moves"
    under a table that prints "1,442"."""
    every = [o for os in orders.values() for o in os]
    empty = np.empty((0, 2))
    still = DayFlight(Flight(empty, np.empty(0, int), empty.copy()), ())
    n = 1200
    lon = np.linspace(-3.169, -3.163, n + 1)
    path = np.c_[lon, np.full(n + 1, 55.971)]
    flown = DayFlight(Flight(path[:-1], np.zeros(n, int), path[1:]), ())
    days = [DayResult(DAY, [], [], [], still, money_placed=0),
            DayResult(DAY, every, [(o, "made up") for o in every], [], still, money_placed=0),
            DayResult(DAY, every, [], [price(site, o) for o in every], flown,
                      money_placed=sum(price(site, o).cost for o in every))]
    for i, result in enumerate(days):
        day_out.plot_day(site, result, tmp_path / f"d{i}.png")
    titles = [fig.axes[0].get_title().replace("\n", ", ") for fig in figures]
    assert titles == ["Delivery day 03 Jan 2024: no orders stored, nothing flown",
                      f"Delivery day 03 Jan 2024: 0/{len(every)} orders, none valid, 0 moves",
                      f"Delivery day 03 Jan 2024: {len(every)}/{len(every)} orders, 100.0% "
                      "of the money, 1,200 moves"]
