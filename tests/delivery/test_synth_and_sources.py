"""Synthetic days fly legal flights; a day read over HTTP is the day read from the folder;
unreachable servers and missing files are clear errors. (That the shipped synthetic set
is what ``data synth`` writes is checked by the README replay in tests/test_docs.py,
whose own ``data synth`` command writes it.)"""

from __future__ import annotations

import json
import shutil

import pytest

from skyroute.delivery.day import plan_day
from skyroute.delivery.orders import read_csv_orders
from skyroute.delivery.serve import serve_in_thread
from skyroute.delivery.site import load_site
from skyroute.delivery.source import DirSource, HttpSource
from skyroute.errors import InputFormatError, SkyrouteError
from tests.cli.test_cli import run
from tests.conftest import ROOT
from tests.delivery.flight_check import check_day, order_book, website

EXAMPLE = ROOT / "examples" / "lunch"


@pytest.mark.slow
def test_synthetic_days_fly_legal_flights(monkeypatch, capsys, tmp_path, fly_once):
    url = f"sqlite:///{tmp_path / 's.db'}"
    code, out, err = run(monkeypatch, capsys, "deliver", "--from", "2024-01-01", "--to",
                         "2024-01-03", "--data", str(EXAMPLE), "--db", url, "--out",
                         str(tmp_path), "--jobs", "2", "--json")
    assert code == 0, err
    summary = json.loads(out)
    assert summary["days"] == 3 and summary["jobs"] == 2 and summary["moves_max"] <= 1500
    from tests.delivery.test_ilp_days import rows

    site, book = website(EXAMPLE), order_book(EXAMPLE)
    for d in ("2024-01-01", "2024-01-02", "2024-01-03"):
        deliveries, flight = rows(url, d)
        assert flight and check_day(site, book, d, deliveries, flight) == []


def test_http_source_gives_the_same_day(tmp_path, fly_once):
    server, url = serve_in_thread(EXAMPLE)
    try:
        by_http = load_site(HttpSource(url))
        by_dir = load_site(DirSource(EXAMPLE))
        assert by_http.menu == by_dir.menu and by_http.home == by_dir.home
        orders = [o for o in read_csv_orders(EXAMPLE) if o.date.day == 2]
        a = plan_day(by_http, orders[0].date, orders)
        b = fly_once(by_dir, orders[0].date, orders)  # the folder's day, flown once
        assert a.flight.flight.rows() == b.flight.flight.rows()
        with pytest.raises(InputFormatError, match=r"/words/no/such/place/details.json: no "
                                                   r"such file \(HTTP 404\)"):
            by_http.locate("no.such.place")
    finally:
        server.shutdown()
        server.server_close()
    with pytest.raises(SkyrouteError, match="cannot reach the data server"):
        load_site(HttpSource(url))


@pytest.fixture
def bom_data(tmp_path):
    """examples/lunch with every CSV, JSON and GeoJSON file saved as Excel's "CSV UTF-8"
    and Notepad save it: a byte-order mark first, CRLF line ends."""
    data = tmp_path / "lunch"
    shutil.copytree(EXAMPLE, data)
    for p in data.rglob("*"):
        if p.is_file():
            p.write_bytes(b"\xef\xbb\xbf" + p.read_bytes().replace(b"\n", b"\r\n"))
    return data


def test_orders_saved_with_a_byte_order_mark_read_the_same(bom_data):
    # the mark was read as part of the first column's name: header ['\\ufefforderNo', ...]
    assert read_csv_orders(bom_data) == read_csv_orders(EXAMPLE)


@pytest.mark.parametrize("over_http", [False, True])
def test_a_website_saved_with_byte_order_marks_reads_the_same(bom_data, over_http):
    # menus.json, area.json and every details.json failed json.loads: "Unexpected UTF-8 BOM"
    plain = load_site(DirSource(EXAMPLE))
    server, url = serve_in_thread(bom_data) if over_http else (None, None)
    try:
        site = load_site(HttpSource(url) if over_http else DirSource(bom_data))
        assert site.menu == plain.menu and site.shops == plain.shops
        assert site.home == plain.home
        assert list(site.world.obstacles) == list(plain.world.obstacles)
    finally:
        if server is not None:
            server.shutdown()
            server.server_close()


def test_orders_not_in_utf8_are_one_line_naming_the_file(monkeypatch, capsys, tmp_path):
    # an orders.csv saved as Latin-1 (an accented name) was a UnicodeDecodeError traceback
    data = tmp_path / "data"
    shutil.copytree(EXAMPLE, data)
    p = data / "database" / "orders.csv"
    p.write_bytes(p.read_bytes().replace(b"\n", b"\xe9\n", 2))
    code, out, err = run(monkeypatch, capsys, "deliver", "2024-01-01", "--data", str(data),
                         "--db", f"sqlite:///{tmp_path / 'x.db'}", "--out",
                         str(tmp_path / "out"), "--no-plot")
    assert code == 2 and out == ""
    assert err.strip() == f"skyroute: error: {p}: cannot read: not UTF-8 text " \
        f"(invalid continuation byte at byte {p.read_bytes().index(0xE9)})"
    assert not (tmp_path / "out").exists()


def test_missing_words_file_makes_the_order_invalid_not_the_day(monkeypatch, capsys, tmp_path):
    import shutil

    data = tmp_path / "data"
    shutil.copytree(EXAMPLE, data)
    p = data / "database" / "orders.csv"
    lines = p.read_text().splitlines()
    no = lines[1].split(",")[0]
    lines[1] = ",".join([*lines[1].split(",")[:3], "gone.missing.place"])
    p.write_text("\n".join(lines) + "\n")
    code, out, err = run(monkeypatch, capsys, "deliver", "2024-01-01", "--data", str(data),
                         "--db", f"sqlite:///{tmp_path / 'x.db'}", "--out", str(tmp_path),
                         "--json", "--no-plot")
    assert code == 0, err
    report = json.loads(out)
    assert report["orders_invalid"] == 1
    bad = report["invalid"][0]
    assert bad["order_no"] == no and "gone/missing/place/details.json" in bad["reason"]


def test_an_order_no_flight_can_reach_is_invalid_with_its_reason(monkeypatch):
    """As if a customer's place were walled in: every leg into it has no flight."""
    from skyroute.delivery import day as day_module

    site = load_site(DirSource(EXAMPLE))
    orders = [o for o in read_csv_orders(EXAMPLE) if o.date.day == 1][:6]
    walled = site.locate(orders[0].deliver_to)
    real = day_module.leg_table

    def table(world, places):
        legs = real(world, places)
        k = [tuple(p) for p in places].index(walled)
        legs[:, k] = -1
        legs[k, k] = 0
        return legs

    monkeypatch.setattr(day_module, "leg_table", table)
    r = plan_day(site, orders[0].date, orders)
    walled_orders = {o.order_no for o in orders if o.deliver_to == orders[0].deliver_to}
    assert {o.order_no for o, _ in r.invalid} == walled_orders
    assert all("no legal flight" in why for _, why in r.invalid)
    assert {p.order.order_no for p in r.delivered} == \
        {o.order_no for o in orders} - walled_orders


def test_a_small_battery_is_never_exceeded():
    """Re-planning lowers the budget until the real flight fits, however tight."""
    site = load_site(DirSource(EXAMPLE))
    orders = [o for o in read_csv_orders(EXAMPLE) if o.date.day == 3]
    book, ref = order_book(EXAMPLE), website(EXAMPLE)
    for battery in (60, 250):
        r = plan_day(site, orders[0].date, orders, battery=battery)
        assert 0 < r.flight.moves <= battery and r.delivered
        f = r.flight.flight
        rows = [("2024-01-03", k, r.flight.order_no[k], *map(float, f.frm[k]),
                 int(f.angle[k]), *map(float, f.to[k])) for k in range(f.moves)]
        deliveries = [("2024-01-03", p.order.order_no, p.order.deliver_to, p.cost)
                      for p in r.delivered]
        assert check_day(ref, book, "2024-01-03", deliveries, rows) == []


def test_only_the_integer_program_reports_a_proven_optimum():
    """The greedy insertion proves nothing: its report said ``proven_optimal: true``, as
    the integer program's, to a user comparing the two methods."""
    site = load_site(DirSource(EXAMPLE))
    orders = [o for o in read_csv_orders(EXAMPLE) if o.date.day == 2][:8]
    greedy = plan_day(site, orders[0].date, orders, method="greedy")
    assert greedy.report()["settings"] == {"method": "greedy", "battery": 1500,
                                           "rounds": greedy.settings["rounds"],
                                           "proven_optimal": False}
    assert plan_day(site, orders[0].date, orders).report()["settings"]["proven_optimal"]
