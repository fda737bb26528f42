"""The re-check of a day's flight before it is stored (skyroute.delivery.validate)
against the rules of SPEC.md 4.2, on flights made to break one rule."""

from __future__ import annotations

import pytest

from skyroute.delivery.assemble import fly_day
from skyroute.delivery.site import load_site
from skyroute.delivery.source import DirSource
from skyroute.delivery.validate import check_flight
from tests.conftest import ROOT


@pytest.fixture(scope="module")
def site():
    return load_site(DirSource(ROOT / "examples" / "lunch"))


def _check(site, visits, deliveries):
    f = fly_day(site.world, site.home, visits)
    return check_flight(site.world, site.home, f.flight.frm, f.flight.angle, f.flight.to,
                        f.order_no, deliveries)


def test_one_order_at_a_time(site):
    # two orders picked up at one shop, then both delivered: every hover is there, each
    # in its order's sequence, so it passed; the drone carries one order at a time
    shop = site.shops[0].lonlat
    a, b = site.locate("brook.boat.brick"), site.locate("tulip.fable.marble")
    deliveries = [("0000000a", [shop, a]), ("0000000b", [shop, b])]
    assert _check(site, deliveries, deliveries) == []  # one after the other
    mixed = [("0000000a", [shop]), ("0000000b", [shop]), ("0000000a", [a]),
             ("0000000b", [b])]
    assert _check(site, mixed, deliveries) == [
        "order 0000000a: its stops are split by another order's (the drone carries one "
        "order at a time)"]
