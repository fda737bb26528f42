"""Before many delivery days: the leg table for every place they need, filled once by the
caller so that the days (in worker processes, see :mod:`skyroute.jobs.deliver`) only
read it; and the store opened and upgraded.
"""

from __future__ import annotations

from collections.abc import Callable

from skyroute.delivery import store
from skyroute.delivery.legs import leg_table, missing_legs
from skyroute.delivery.orders import Priced, price


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


def open_store(url: str):
    """An engine for ``url`` with the schema created or upgraded to the newest migration."""
    engine = store.connect(url)
    store.init(engine)
    return engine
