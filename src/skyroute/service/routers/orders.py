"""``GET /orders?date=``: the orders stored for a day (empty on a day without any)."""

from __future__ import annotations

import datetime as dt
from typing import Annotated

from fastapi import APIRouter, Query
from pydantic import BaseModel

from skyroute.service.dates import IsoDate
from skyroute.service.problems import responses
from skyroute.service.resources import EngineDep

router = APIRouter(tags=["days"])


class OrderOut(BaseModel):
    order_no: str
    date: dt.date
    customer: str
    deliver_to: str
    items: list[str]


@router.get("/orders", response_model=list[OrderOut], responses=responses(422, 503),
            summary="The stored orders of a day")
def list_orders(date: Annotated[IsoDate, Query(description="The day, YYYY-MM-DD.")],
                eng: EngineDep) -> list[dict]:
    from skyroute.delivery.store import orders_between

    return [{"order_no": o.order_no, "date": o.date, "customer": o.customer,
             "deliver_to": o.deliver_to, "items": list(o.items)}
            for o in orders_between(eng, date, date).get(date, [])]
