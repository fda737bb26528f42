"""Stored delivery days through the service: the CLI's report and files, read back from
the store the CLI filled (examples/lunch, 2024-01-03), and the site in lon/lat."""

from __future__ import annotations

import json
import time

import pytest

from tests.service.conftest import AUTH, DAY, EXAMPLE, make_client
from tests.service.test_app import assert_problem


def test_days_lists_the_stored_days(day_client, lunch):
    _, report, _, _ = lunch
    days = day_client.get("/days").json()
    assert [d["date"] for d in days] == [DAY, "2024-02-01"]
    assert days[0]["money_pct"] == report["money_pct"] and days[0]["moves"] == report["moves"]
    assert days[1]["money_pct"] is None and days[1]["moves"] == 0


def test_a_day_has_the_clis_report(day_client, lunch):
    _, report, _, _ = lunch
    doc = day_client.get(f"/days/{DAY}").json()
    assert doc["date"] == DAY
    rep = doc["report"]
    for key in ("date", "orders_placed", "orders_delivered", "orders_invalid", "invalid",
                "money_placed", "money_delivered", "money_pct", "moves", "moves_left",
                "settings"):
        assert rep[key] == report[key], key
    assert rep["seconds"] == pytest.approx(report["seconds"], abs=1e-5)
    delivered = doc["deliveries"]
    assert len(delivered) == report["orders_delivered"]
    assert sum(d["cost_in_pence"] for d in delivered) == report["money_delivered"]
    orders = doc["orders"]
    assert len(orders) == report["orders_placed"] == 36
    status = {o["order_no"]: o["status"] for o in orders}
    assert {d["order_no"] for d in delivered} == {k for k, v in status.items()
                                                  if v == "delivered"}
    assert sum(v == "invalid" for v in status.values()) == report["orders_invalid"]
    assert sum(o["value"] for o in orders if o["status"] != "invalid") == \
        report["money_placed"] - sum(50 for o in orders if o["status"] == "invalid") \
        - _invalid_items(orders)
    assert all(o["lonlat"] is not None for o in orders if o["status"] != "invalid")


def _invalid_items(orders) -> int:
    """Money placed counts the known items of invalid orders too (DayResult.money_placed)."""
    from skyroute.delivery.day import _placed_value
    from skyroute.delivery.orders import Order
    from skyroute.delivery.site import load_site
    from skyroute.delivery.source import DirSource

    site = load_site(DirSource(EXAMPLE))
    return sum(_placed_value(site, Order(o["order_no"], None, o["customer"], o["deliver_to"],
                                         tuple(o["items"]))) - 50
               for o in orders if o["status"] == "invalid")


def test_deliveries_come_in_flying_order(day_client):
    doc = day_client.get(f"/days/{DAY}").json()
    angles_orders = day_client.get(f"/days/{DAY}/flightpath.geojson").json()[
        "features"][0]["properties"]["orders"]
    flown = list(dict.fromkeys(o for o in angles_orders if o))
    assert [d["order_no"] for d in doc["deliveries"]] == \
        [o for o in flown if o in {d["order_no"] for d in doc["deliveries"]}]


def test_flightpath_is_the_clis_file(day_client, lunch):
    _, report, geojson, _ = lunch
    r = day_client.get(f"/days/{DAY}/flightpath.geojson")
    assert r.status_code == 200 and r.headers["content-type"] == "application/geo+json"
    mine, cli = r.json()["features"][0], json.loads(geojson)["features"][0]
    assert mine["geometry"] == cli["geometry"]  # the same floats, to the last bit
    assert mine["properties"]["moves"] == report["moves"]
    assert len(mine["properties"]["angles"]) == report["moves"]
    again = day_client.get(f"/days/{DAY}/flightpath.geojson",
                           headers={"If-None-Match": r.headers["etag"]})
    assert again.status_code == 304 and not again.content
    empty = day_client.get("/days/2024-02-01/flightpath.geojson").json()["features"][0]
    assert empty["geometry"] == json.loads((lunch[3] / "drone-01-02-2024.geojson")
                                           .read_text())["features"][0]["geometry"]


def test_if_none_match_is_compared_as_http_says_and_the_304_is_documented(day_client):
    """If-None-Match names the flight's ETag also weakly (``W/"x"``: what a proxy that
    compresses the file hands out and the client sends back), in a list, or as ``*``;
    only the exact ETag was a 304. The 304 and the ETag are in the OpenAPI: the answer
    was a status the schema did not list (schemathesis never sends If-None-Match)."""
    url = f"/days/{DAY}/flightpath.geojson"
    etag = day_client.get(url).headers["etag"]
    for held in (etag, f"W/{etag}", f'"0123", {etag}', f'W/"0123", W/{etag}', "*"):
        r = day_client.get(url, headers={"If-None-Match": held})
        assert r.status_code == 304 and not r.content and r.headers["etag"] == etag, held
    for held in ('"0123"', f'"{etag}"', 'W/"0123"', ""):
        assert day_client.get(url, headers={"If-None-Match": held}).status_code == 200, held
    op = day_client.get("/openapi.json").json()["paths"][
        "/days/{date}/flightpath.geojson"]["get"]
    assert {"200", "304"} <= set(op["responses"])
    assert "ETag" in op["responses"]["304"]["headers"]
    assert "ETag" in op["responses"]["200"]["headers"]
    assert [p["name"] for p in op["parameters"] if p["in"] == "header"] == ["if-none-match"]


def test_a_day_stored_again_is_served_fresh(tmp_path, lunch):
    """The flight path is cached by the day's run: storing the day again changes it."""
    import shutil

    import sqlalchemy as sa

    from skyroute.delivery.store import connect

    db = tmp_path / "copy.db"
    shutil.copy(lunch[0].removeprefix("sqlite:///"), db)
    with make_client(db_url=f"sqlite:///{db}", fresh_seconds=0.2) as c:
        first = c.get(f"/days/{DAY}/flightpath.geojson")
        eng = connect(f"sqlite:///{db}")
        with eng.begin() as conn:
            conn.execute(sa.text("update flightpath set to_lon = to_lon + 1 where seq = 0 "
                                 "and delivery_date = :d"), {"d": DAY})
            conn.execute(sa.text("update runs set finished = '2030-01-01 00:00:00.000000' "
                                 "where delivery_date = :d"), {"d": DAY})
        assert c.get(f"/days/{DAY}/flightpath.geojson").content == first.content
        time.sleep(0.25)  # fresh_seconds later the store is asked again
        second = c.get(f"/days/{DAY}/flightpath.geojson")
        assert second.headers["etag"] != first.headers["etag"]
        a = first.json()["features"][0]["geometry"]["coordinates"][1]
        b = second.json()["features"][0]["geometry"]["coordinates"][1]
        assert b[0] == pytest.approx(a[0] + 1)


def test_two_flights_of_a_day_stored_at_one_clock_tick_have_two_etags(tmp_path):
    """The flight file's ETag (and the server's cached copy) was keyed by the run's
    finish time and move count: a day flown again with the same number of moves and the
    same finish time (a coarse or frozen clock, a clock stepped back, a worker on another
    host) kept the first flight's ETag, so the server went on serving the first flight
    and a client's ``If-None-Match`` kept it too. The version is now a digest of the
    stored moves: another flight, another ETag; the same flight, the same one."""
    import datetime as dt

    from skyroute.delivery.store import write_day
    from skyroute.service.resources import make_engine

    db = f"sqlite:///{tmp_path / 'tick.db'}"
    eng = make_engine(db)
    date, frozen = dt.date(2024, 1, 5), dt.datetime(2024, 1, 5, 12, 0, 0)

    def store(lon: float) -> None:  # three moves, the same clock reading every time
        moves = [{"seq": k, "order_no": "1AFFE082", "from_lon": lon + k * 1.5e-4,
                  "from_lat": 55.944, "angle": 0, "to_lon": lon + (k + 1) * 1.5e-4,
                  "to_lat": 55.944} for k in range(3)]
        write_day(eng, date, {"started": frozen, "finished": frozen, "moves": 3,
                              "orders_placed": 1, "orders_delivered": 0,
                              "orders_invalid": 0, "money_delivered": 0,
                              "money_placed": 100, "settings": {}}, [], moves)

    url = f"/days/{date}/flightpath.geojson"
    with make_client(db_url=db, fresh_seconds=0) as c:  # the store asked every time
        store(-3.1870)
        first = c.get(url)
        store(-3.1900)  # another flight, at the same tick with as many moves
        second = c.get(url)
        assert second.status_code == 200
        assert second.json()["features"][0]["geometry"]["coordinates"][0][0] == -3.19
        assert second.headers["etag"] != first.headers["etag"]
        cached = c.get(url, headers={"If-None-Match": first.headers["etag"]})
        assert cached.status_code == 200 and cached.content == second.content
        store(-3.1900)  # the same flight stored again: the same ETag
        assert c.get(url).headers["etag"] == second.headers["etag"]
    eng.dispose()


@pytest.mark.parametrize("path", ["/days/2023-06-01", "/days/2023-06-01/flightpath.geojson"])
def test_unknown_date_is_404(day_client, path):
    assert_problem(day_client.get(path), 404, words="2023-06-01 is not stored")


@pytest.mark.parametrize("path, field", [
    ("/days/2024-13-01", "date"), ("/days/yesterday/flightpath.geojson", "date"),
    ("/orders?date=2024-02-30", "date"), ("/orders", "date"),
    # numbers and other spellings pydantic's lax dates would take: only YYYY-MM-DD
    ("/orders?date=0", "date"), ("/orders?date=20240103", "date"),
    ("/orders?date=2024-1-3", "date"), ("/orders?date=2024-01-03T00:00", "date"),
    ("/days/1704240000", "date"), ("/days/1704240000/flightpath.geojson", "date"),
])
def test_bad_date_is_422(day_client, path, field):
    assert_problem(day_client.get(path), 422, field)


def test_orders_of_a_day(day_client):
    orders = day_client.get(f"/orders?date={DAY}").json()
    assert len(orders) == 36 and all(o["date"] == DAY for o in orders)
    assert all(len(o["items"]) >= 1 for o in orders if o["order_no"])
    assert day_client.get("/orders?date=1999-01-01").json() == []


def test_site_in_lonlat(day_client):
    r = day_client.get("/site.geojson")
    assert r.status_code == 200 and r.headers["content-type"] == "application/geo+json"
    kinds: dict[str, list] = {}
    for f in r.json()["features"]:
        kinds.setdefault(f["properties"]["kind"], []).append(f)
    menus = json.loads((EXAMPLE / "website" / "menus" / "menus.json").read_text())
    zones = json.loads((EXAMPLE / "website" / "buildings" / "no-fly-zones.geojson")
                       .read_text())
    assert len(kinds["shop"]) == len(menus) and len(kinds["home"]) == 1
    assert len(kinds["no_fly_zone"]) == len(zones["features"])
    assert len(kinds["confinement"]) == 1
    assert kinds["confinement"][0]["geometry"]["type"] == "Polygon"
    customers = {f["properties"]["words"] for f in kinds["customer"]}
    day = day_client.get(f"/days/{DAY}").json()
    assert {o["deliver_to"] for o in day["orders"] if o["lonlat"]} <= customers
    for f in kinds["shop"] + kinds["customer"]:
        lon, lat = f["geometry"]["coordinates"]
        assert -3.3 < lon < -3.1 and 55.9 < lat < 56.0  # Edinburgh, not (lat, lon)


def test_without_a_site(lunch):
    with make_client(db_url=lunch[0]) as c:
        assert_problem(c.get("/site.geojson"), 404, words="--data DIR or --source URL")
        doc = c.get(f"/days/{DAY}").json()
        assert doc["report"]["invalid"] is None
        assert all(o["status"] in ("delivered", "not_delivered") for o in doc["orders"])
        empty = c.get("/days/2024-02-01/flightpath.geojson").json()["features"][0]
        assert empty["geometry"] is None and empty["properties"]["moves"] == 0


def test_a_broken_site_is_503(tmp_path, lunch, caplog):
    (tmp_path / "website").mkdir()
    with make_client(db_url=lunch[0], data_dir=tmp_path) as c:
        r = c.get("/site.geojson")
        assert_problem(r, 503, words="the delivery site cannot be read; the server's log")
        assert str(tmp_path) not in r.text  # the folder's path is for the log alone
    assert any("menus.json" in r.getMessage() for r in caplog.records), caplog.records



# -- DELETE /days/{date}: a day without a flight (a mistyped date) ----------------------

@pytest.fixture
def copy_client(tmp_path, lunch):
    """(client, store URL): the app over a copy of the lunch store, with a long
    fresh_seconds (a flight path read is served from the cache meanwhile)."""
    import shutil

    db = f"sqlite:///{shutil.copy(lunch[0].removeprefix('sqlite:///'), tmp_path / 'c.db')}"
    with make_client(db_url=db, data_dir=EXAMPLE, fresh_seconds=3600) as c:
        yield c, db


def _rows(db: str, date: str) -> dict[str, list]:
    """The day's rows of each delivery table, read with plain SQL."""
    import sqlalchemy as sa

    eng = sa.create_engine(db)
    try:
        with eng.connect() as conn:
            return {t: sorted(tuple(r) for r in conn.execute(
                sa.text(f"SELECT * FROM {t} WHERE delivery_date = :d"), {"d": date}))
                for t in ("runs", "deliveries", "flightpath", "orders")}
    finally:
        eng.dispose()


def test_delete_removes_a_day_without_a_flight(copy_client):
    """A day stored by a mistyped date (no orders, no flight) could not be removed: no
    DELETE route (405). It is deleted now, the cached flight path with it."""
    c, db = copy_client
    empty = "2024-02-01"
    assert c.get(f"/days/{empty}/flightpath.geojson").status_code == 200  # cached
    assert_problem(c.delete(f"/days/{empty}"), 401, words="Bearer")
    assert_problem(c.delete(f"/days/{empty}", headers={"Authorization": "Bearer wrong"}),
                   403, words="token")
    assert _rows(db, empty)["runs"]  # still stored
    r = c.delete(f"/days/{empty}", headers=AUTH)
    assert r.status_code == 204 and r.content == b""
    assert _rows(db, empty) == {"runs": [], "deliveries": [], "flightpath": [], "orders": []}
    assert [d["date"] for d in c.get("/days").json()] == [DAY]
    assert_problem(c.get(f"/days/{empty}"), 404, words=f"{empty} is not stored")
    assert_problem(c.get(f"/days/{empty}/flightpath.geojson"), 404,
                   words=f"{empty} is not stored")
    assert_problem(c.delete(f"/days/{empty}", headers=AUTH), 404,
                   words=f"day {empty} is not stored")


def test_delete_keeps_a_flown_day(copy_client):
    """A day with a flight is refused (409) and left as it was: its flight and
    deliveries are what was flown; flying the day again replaces them."""
    c, db = copy_client
    before = _rows(db, DAY)
    assert before["flightpath"] and before["deliveries"]
    doc = assert_problem(c.delete(f"/days/{DAY}", headers=AUTH), 409, words="has a flight")
    assert doc["type"].endswith("day-flown")
    assert f"{len(before['flightpath'])} moves" in doc["detail"]
    assert f"{len(before['deliveries'])} orders delivered" in doc["detail"]
    assert _rows(db, DAY) == before


def test_delete_keeps_the_days_orders(copy_client):
    """A day whose orders could not be flown (a run of no moves) is deleted; its orders
    are input (``db import``) and stay."""
    import datetime as dt

    from skyroute.delivery.store import connect, write_day

    c, db = copy_client
    date = "2024-01-01"  # orders imported with the lunch day, not flown
    orders = _rows(db, date)["orders"]
    assert orders and not _rows(db, date)["runs"]
    eng = connect(db)
    now = dt.datetime(2024, 1, 1, 12)
    write_day(eng, dt.date(2024, 1, 1), {
        "started": now, "finished": now, "moves": 0, "orders_placed": len(orders),
        "orders_delivered": 0, "orders_invalid": 0, "money_delivered": 0,
        "money_placed": 100, "settings": {}}, [], [])
    eng.dispose()
    assert date in [d["date"] for d in c.get("/days").json()]
    assert c.delete(f"/days/{date}", headers=AUTH).status_code == 204
    after = _rows(db, date)
    assert after["runs"] == [] and after["orders"] == orders
    assert len(c.get("/orders", params={"date": date}).json()) == len(orders)


@pytest.mark.parametrize("date", ["2024-13-01", "yesterday", "1704240000"])
def test_delete_a_bad_date_is_422(copy_client, date):
    assert_problem(copy_client[0].delete(f"/days/{date}", headers=AUTH), 422, "date")


def test_a_finished_deliver_job_drops_the_cached_flights_of_its_days(copy_client):
    """A day's flight file is served from memory for fresh_seconds; the viewer loads the
    day as soon as GET /jobs/{id} says its job is done, and was shown the flight that
    job had just replaced (the replace test of the viewer failed about one run in
    three). Seeing a deliver job done drops the cached files of its days."""
    import sqlalchemy as sa

    from skyroute.jobs import store as jobs_store

    c, db = copy_client
    before = c.get(f"/days/{DAY}/flightpath.geojson").json()  # now cached for an hour
    assert before["features"][0]["properties"]["moves"] > 0
    eng = sa.create_engine(db)
    try:
        with eng.begin() as conn:  # the day flown again, delivering nothing
            conn.execute(sa.text("DELETE FROM flightpath WHERE delivery_date = :d"), {"d": DAY})
            conn.execute(sa.text("DELETE FROM deliveries WHERE delivery_date = :d"), {"d": DAY})
            conn.execute(sa.text("UPDATE runs SET moves = 0 WHERE delivery_date = :d"),
                         {"d": DAY})
        job = jobs_store.create_job(eng, "deliver", {"from": DAY, "to": DAY})
        assert jobs_store.finish_job(eng, job, {"from": DAY, "to": DAY})
    finally:
        eng.dispose()
    assert c.get(f"/days/{DAY}/flightpath.geojson").json() == before  # still cached
    assert c.get(f"/jobs/{job}").json()["state"] == "done"
    after = c.get(f"/days/{DAY}/flightpath.geojson").json()
    assert after["features"][0]["properties"]["moves"] == 0
