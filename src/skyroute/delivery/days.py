"""Many delivery days: orders read from the store once, days planned in worker processes,
each finished day stored (one transaction) and written out by the parent as it comes in.

The leg table for every place the days need is filled first, in the parent, so the
workers only read it.
"""

from __future__ import annotations

import datetime as dt
import os
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, as_completed

from skyroute.delivery import store
from skyroute.delivery.day import DayResult, plan_day
from skyroute.delivery.legs import leg_table, missing_legs
from skyroute.delivery.orders import Priced, price
from skyroute.delivery.site import load_site
from skyroute.delivery.source import DirSource, HttpSource

_SITE = None


def places_of(site, orders) -> list[tuple[float, float]]:
    """Home, the shops and every valid order's customer point."""
    custs = sorted({p.lonlat for p in (price(site, o) for o in orders)
                    if isinstance(p, Priced)})
    return [site.home, *(s.lonlat for s in site.shops), *custs]


def prepare_legs(site, orders, on_leg: Callable | None = None,
                 on_total: Callable | None = None) -> None:
    """Fill the leg cache for every place of ``orders``."""
    pts = places_of(site, orders)
    if on_total:
        on_total(missing_legs(site.world, pts))
    leg_table(site.world, pts, on_leg=on_leg)


def _init(source: DirSource | HttpSource) -> None:
    global _SITE
    _SITE = load_site(source)


def _plan(date: dt.date, orders, method: str) -> DayResult:
    return plan_day(_SITE, date, orders, method=method)


def run_days(site, engine, by_date: dict[dt.date, list], *, jobs: int = 1,
             method: str = "milp",
             on_day: Callable[[DayResult], None] | None = None) -> list[DayResult]:
    """Plan and store every day of ``by_date`` (each in one transaction, as it finishes),
    then hand it to ``on_day`` (the CLI writes its files there); results in date
    order."""
    jobs = max(1, min(jobs, os.cpu_count() or 1, len(by_date) or 1))
    results = []

    def finish(r: DayResult) -> None:
        store.store_day(engine, r)
        results.append(r)
        if on_day:
            on_day(r)

    if jobs == 1:
        for d, orders in sorted(by_date.items()):
            finish(plan_day(site, d, orders, method=method))
    else:
        pool = ProcessPoolExecutor(jobs, initializer=_init, initargs=(site.source,))
        try:
            futures = [pool.submit(_plan, d, orders, method)
                       for d, orders in sorted(by_date.items())]
            for f in as_completed(futures):
                finish(f.result())
        except BaseException:  # an error or Ctrl-C: stop now, not after every queued day
            pool.shutdown(wait=False, cancel_futures=True)
            raise
        pool.shutdown()
    return sorted(results, key=lambda r: r.date)


def open_store(url: str):
    engine = store.connect(url)
    store.init(engine)
    return engine
