"""The store's read side for the service and its viewer: which days are stored, a day's
run (its report), its deliveries in flying order, and its moves as columns.

Reads only; a day's rows are written in one transaction by
:func:`skyroute.delivery.store.write_day`, so a day read here is whole.
"""

from __future__ import annotations

import datetime as dt
import hashlib
import json

import numpy as np
import sqlalchemy as sa

from skyroute.delivery.store import tables
from skyroute.delivery.validate import BATTERY


def _pct(delivered: int, placed: int) -> float | None:
    return 100.0 * delivered / placed if placed else None


def stored_days(engine: sa.Engine) -> list[dict]:
    """Every day with a stored run, oldest first: date, orders, money and moves."""
    runs = tables(engine)["runs"]
    cols = (runs.c.delivery_date, runs.c.moves, runs.c.orders_placed,
            runs.c.orders_delivered, runs.c.money_delivered, runs.c.money_placed)
    with engine.connect() as conn:
        rows = conn.execute(sa.select(*cols).order_by(runs.c.delivery_date)).all()
    return [{"date": r.delivery_date.isoformat(), "moves": r.moves,
             "orders_placed": r.orders_placed, "orders_delivered": r.orders_delivered,
             "money_pct": _pct(r.money_delivered, r.money_placed)} for r in rows]


def day_report(engine: sa.Engine, date: dt.date) -> dict | None:
    """A stored day's report with the CLI's fields (``DayResult.report``) that the store
    keeps, or None when the day was never flown. ``invalid`` (the reasons) is not stored;
    the caller adds it when it has the site."""
    runs = tables(engine)["runs"]
    with engine.connect() as conn:
        r = conn.execute(sa.select(runs).where(runs.c.delivery_date == date)).first()
    if r is None:
        return None
    return {"date": date.isoformat(), "orders_placed": r.orders_placed,
            "orders_delivered": r.orders_delivered, "orders_invalid": r.orders_invalid,
            "money_placed": r.money_placed, "money_delivered": r.money_delivered,
            "money_pct": _pct(r.money_delivered, r.money_placed), "moves": r.moves,
            "moves_left": BATTERY - r.moves,
            "seconds": (r.finished - r.started).total_seconds(),
            "started": r.started.isoformat(), "finished": r.finished.isoformat(),
            "settings": json.loads(r.settings or "{}")}


def day_deliveries(engine: sa.Engine, date: dt.date) -> list[dict]:
    """The day's delivered orders, in the order the flight delivered them."""
    t = tables(engine)
    deliveries, flightpath = t["deliveries"], t["flightpath"]
    first = sa.select(flightpath.c.order_no, sa.func.min(flightpath.c.seq).label("seq")) \
        .where(flightpath.c.delivery_date == date).group_by(flightpath.c.order_no).subquery()
    q = sa.select(deliveries.c.order_no, deliveries.c.delivered_to,
                  deliveries.c.cost_in_pence, first.c.seq) \
        .join(first, first.c.order_no == deliveries.c.order_no, isouter=True) \
        .where(deliveries.c.delivery_date == date) \
        .order_by(first.c.seq, deliveries.c.order_no)
    with engine.connect() as conn:
        return [{"order_no": r.order_no, "delivered_to": r.delivered_to,
                 "cost_in_pence": r.cost_in_pence} for r in conn.execute(q)]


def day_moves(engine: sa.Engine, date: dt.date) -> dict[str, np.ndarray]:
    """The day's moves as columns in flying order: ``frm`` and ``to`` (N, 2) lon/lat,
    ``angle`` (ILP degrees, -999 hover), ``order_no``."""
    with engine.connect() as conn:
        return _moves(conn, tables(engine)["flightpath"], date)


def day_flight(engine: sa.Engine, date: dt.date) -> tuple[str, dict] | None:
    """(version, moves) of a stored day, read in one transaction, or None when the day
    was never flown. ``moves`` as :func:`day_moves`; ``version`` changes whenever they
    do: the day and a SHA-256 of its moves (every value the flight file is made of), a
    key for caching that file and its ETag. It was the run's finish time and move count,
    which two flights of the day can share (a coarse or stepped-back clock, a worker on
    another host): the second was then served as the first. The same moves stored again
    keep their version."""
    t = tables(engine)
    runs = t["runs"]
    with engine.connect() as conn:
        if conn.scalar(sa.select(runs.c.moves).where(runs.c.delivery_date == date)) is None:
            return None
        m = _moves(conn, t["flightpath"], date)
    digest = hashlib.sha256()
    for part in (m["frm"], m["to"], m["angle"]):
        digest.update(np.ascontiguousarray(part, dtype="<f8").tobytes())
    digest.update("\0".join(m["order_no"]).encode())
    return f"{date}:{len(m['angle'])}:{digest.hexdigest()}", m


def _moves(conn: sa.Connection, fp: sa.Table, date: dt.date) -> dict:
    q = sa.select(fp.c.from_lon, fp.c.from_lat, fp.c.angle, fp.c.to_lon, fp.c.to_lat,
                  fp.c.order_no).where(fp.c.delivery_date == date).order_by(fp.c.seq)
    rows = conn.execute(q).all()
    a = np.array([r[:5] for r in rows], dtype=float).reshape(-1, 5)
    return {"frm": a[:, 0:2], "angle": a[:, 2].astype(int), "to": a[:, 3:5],
            "order_no": [r[5] for r in rows]}
