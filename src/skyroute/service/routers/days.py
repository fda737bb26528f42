"""Stored delivery days: ``GET /days``, ``GET /days/{date}`` (report, deliveries and
every order's fate), ``GET /days/{date}/flightpath.geojson`` (the flight, as the
``deliver`` command writes it) and ``DELETE /days/{date}`` (a day without a flight)."""

from __future__ import annotations

import datetime as dt
import hashlib
import re
import time
from typing import Annotated

from fastapi import APIRouter, Depends, Header, Path, Response
from fastapi.concurrency import run_in_threadpool
from pydantic import BaseModel, Field

from skyroute.io.json_text import to_json
from skyroute.service.auth import require_token
from skyroute.service.dates import IsoDate
from skyroute.service.problems import Problem, responses
from skyroute.service.resources import EngineDep, Resources, ResourcesDep

router = APIRouter(tags=["days"])
GEOJSON = "application/geo+json"

LonLat = Annotated[list[float], Field(min_length=2, max_length=2)]
DayDate = Annotated[IsoDate, Path(description="The day, YYYY-MM-DD.")]


class DaySummary(BaseModel):
    date: dt.date
    moves: int
    orders_placed: int
    orders_delivered: int
    money_pct: float | None = Field(description="Money delivered as % of money placed; "
                                    "null on a day without orders.")


class InvalidOrder(BaseModel):
    order_no: str
    reason: str


class DayReport(BaseModel):
    """The CLI's report fields (``deliver --json``) as the store keeps them."""

    date: dt.date
    orders_placed: int
    orders_delivered: int
    orders_invalid: int
    invalid: list[InvalidOrder] | None = Field(
        description="Each invalid order's reason, where the server has the site to price "
                    "them (null without one).")
    money_placed: int
    money_delivered: int
    money_pct: float | None
    moves: int
    moves_left: int
    seconds: float
    started: str
    finished: str
    settings: dict


class Delivery(BaseModel):
    order_no: str
    delivered_to: str
    cost_in_pence: int


class DayOrder(BaseModel):
    order_no: str
    customer: str
    deliver_to: str
    items: list[str]
    status: str = Field(description="delivered, invalid, or not_delivered (valid, but "
                        "not flown within the battery); invalid is known only with the site.")
    value: int | None = Field(description="Pence: the delivery's cost, or the priced order "
                              "where the site is known.")
    reason: str | None = None
    lonlat: LonLat | None = Field(None, description="The customer's place where the site "
                                  "is known.")


class Day(BaseModel):
    date: dt.date
    report: DayReport
    deliveries: list[Delivery] = Field(description="Delivered orders in flying order.")
    orders: list[DayOrder] = Field(description="Every order of the day.")


@router.get("/days", response_model=list[DaySummary], responses=responses(503),
            summary="Stored delivery days")
def list_days(eng: EngineDep) -> list[dict]:
    from skyroute.delivery.reads import stored_days

    return stored_days(eng)


def _report(eng, date: dt.date) -> dict:
    from skyroute.delivery.reads import day_report

    rep = day_report(eng, date)
    if rep is None:
        raise _not_stored(date)
    return rep


def _not_stored(date: dt.date) -> Problem:
    return Problem(404, f"day {date} is not stored; GET /days lists the stored days",
                   kind="unknown-date")


@router.get("/days/{date}", response_model=Day, responses=responses(404, 422, 503),
            summary="A stored day: report, deliveries, orders")
def get_day(date: DayDate, eng: EngineDep,
            res: ResourcesDep) -> dict:
    from skyroute.delivery.orders import Priced, price
    from skyroute.delivery.reads import day_deliveries
    from skyroute.delivery.store import orders_between

    rep = _report(eng, date)
    delivered = day_deliveries(eng, date)
    cost = {d["order_no"]: d["cost_in_pence"] for d in delivered}
    orders = orders_between(eng, date, date).get(date, [])
    site = res.site() if res.settings.has_site else None
    rows, invalid = [], []
    for o in orders:
        row = {"order_no": o.order_no, "customer": o.customer, "deliver_to": o.deliver_to,
               "items": list(o.items), "value": cost.get(o.order_no), "reason": None,
               "lonlat": None,
               "status": "delivered" if o.order_no in cost else "not_delivered"}
        if site is not None:
            p = price(site, o)
            if isinstance(p, Priced):
                row["value"], row["lonlat"] = p.cost, p.lonlat
            else:
                row["status"], row["reason"] = "invalid", p
                invalid.append({"order_no": o.order_no, "reason": p})
        rows.append(row)
    rep["invalid"] = invalid if site is not None else None
    return {"date": date, "report": rep, "deliveries": delivered, "orders": rows}


@router.delete("/days/{date}", status_code=204, response_class=Response,
               dependencies=[Depends(require_token)],
               responses=responses(401, 403, 404, 409, 422, 503),
               summary="Delete a stored day without a flight")
def delete_day(date: DayDate, res: ResourcesDep) -> Response:
    """Delete a day the drone did not fly: a mistyped date, a day without orders, or one
    whose orders could not be flown (its run; 204). A day with a flight is kept (409):
    its flight and deliveries are what was flown, and flying the day again replaces
    them. The day's orders stay in the store either way."""
    from skyroute.delivery.store import delete_unflown_day

    got = delete_unflown_day(res.engine(), date)
    if got is None:
        raise Problem(404, f"day {date} is not stored; GET /days lists the stored days",
                      kind="unknown-date")
    if not got["deleted"]:
        raise Problem(409, f"day {date} has a flight ({got['moves']} moves, "
                      f"{got['delivered']} orders delivered) and is kept: only a day "
                      "without a flight is deleted; fly the day again to replace it",
                      kind="day-flown")
    res.cache.pop(f"flightpath:{date}", None)  # this process's copy of the day's file
    return Response(status_code=204)


ETAG = {"ETag": {"description": "The flight's version (a digest of its stored moves): "
                 "it changes whenever the flight does.", "schema": {"type": "string"}}}


@router.get("/days/{date}/flightpath.geojson", response_class=Response,
            responses={200: {"content": {GEOJSON: {"schema": {"type": "object"}}},
                             "description": "The flight as one LineString in lon/lat "
                             "(the file `deliver` writes), with each move's ILP angle and "
                             "order number in its properties.", "headers": ETAG},
                       304: {"description": "Not modified: `If-None-Match` names the "
                             "flight's ETag; no body.", "headers": ETAG},
                       **responses(404, 422, 503)},
            summary="A stored day's flight as GeoJSON")
async def get_flightpath(date: DayDate, res: ResourcesDep,
                         if_none_match: Annotated[str | None, Header(
                             description="ETags held (`\"...\"`, `W/\"...\"`, a list, "
                             "or `*`): 304 when one is the flight's.")] = None
                         ) -> Response:
    # The file is made once per stored version of the day and served from memory; the
    # store is asked again whether the day changed once fresh_seconds have passed (on
    # the thread pool, so the event loop never waits for the database).
    key = f"flightpath:{date}"
    entry = res.cache.get(key)
    if entry is None or time.monotonic() - entry[0] > res.settings.fresh_seconds:
        if entry is not None:  # one request asks; the others meanwhile serve what is held
            res.cache[key] = (time.monotonic(), *entry[1:])
        entry = await run_in_threadpool(_flightpath_entry, date, res, entry)
        res.cache[key] = entry
    _, _, etag, body = entry
    if if_none_match is not None and _names(if_none_match, etag):
        return Response(status_code=304, headers={"ETag": etag})
    return Response(body, media_type=GEOJSON, headers={"ETag": etag})


def _names(if_none_match: str, etag: str) -> bool:
    """Whether an ``If-None-Match`` value names ``etag`` (RFC 9110 13.1.2): ``*``, or a
    list of ETags compared weakly (``W/"x"`` is ``"x"``). A proxy that compresses the
    file (nginx's gzip) hands the client ``W/"x"``, which the client sends back; only
    the exact ``"x"`` was a 304, so such a client always fetched the whole flight."""
    if if_none_match.strip() == "*":
        return True
    return etag in re.findall(r'"[^"]*"', if_none_match)


def _flightpath_entry(date: dt.date, res: Resources, old: tuple | None) -> tuple:
    """(checked at, version, ETag, body) of the day's file, made again only when the
    day's version (a digest of its stored moves) changed; the version and the body come
    from one read, so an ETag never names another flight's body."""
    from skyroute.delivery.reads import day_flight

    eng = res.engine()
    got = day_flight(eng, date)
    if got is None:
        raise _not_stored(date)
    version, moves = got
    if old is not None and old[1] == version:
        return (time.monotonic(), *old[1:])
    etag = '"' + hashlib.sha1(version.encode()).hexdigest()[:20] + '"'
    return time.monotonic(), version, etag, _flightpath(moves, date, res)


def _flightpath(m: dict, date: dt.date, res: Resources) -> bytes:
    """The file of the day's moves ``m`` (:func:`~skyroute.delivery.reads.day_moves`)."""
    import numpy as np

    n = len(m["angle"])
    if n:
        geometry = {"type": "LineString",
                    "coordinates": np.vstack([m["frm"][:1], m["to"]]).tolist()}
    elif res.settings.has_site:  # as the CLI writes a day without moves: home to home
        home = list(res.site().home)
        geometry = {"type": "LineString", "coordinates": [home, home]}
    else:
        geometry = None
    doc = {"type": "FeatureCollection", "features": [{
        "type": "Feature", "geometry": geometry,
        "properties": {"date": date.isoformat(), "moves": n, "angles": m["angle"].tolist(),
                       "orders": m["order_no"]}}]}
    return to_json(doc, separators=(",", ":")).encode()
