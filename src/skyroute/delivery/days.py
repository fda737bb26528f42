"""Before many delivery days: the leg table for every place they need, filled once by the
caller so that the days (in worker processes, see :mod:`skyroute.jobs.deliver`) only
read it; and the store opened and upgraded.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Callable

from skyroute.delivery import store
from skyroute.delivery.legs import leg_table, missing_legs
from skyroute.delivery.orders import Priced, price
from skyroute.errors import InputFormatError, SkyrouteError


def places_of(site, orders) -> list[tuple[float, float]]:
    """Home, the shops and every valid order's customer point."""
    custs = sorted({p.lonlat for p in (price(site, o) for o in orders)
                    if isinstance(p, Priced)})
    return [site.home, *(s.lonlat for s in site.shops), *custs]


def foreign_days(site, by_date: dict[dt.date, list]) -> list[dt.date]:
    """The days of ``by_date`` with orders none of which ``site`` knows: no order has
    every item on its menus, and no order goes to a place of its ``words/``. They are
    another site's orders (a store filled from one data folder, flown with another's
    site): flown, every order is invalid ('unknown item'), and storing that replaced the
    day's real flight. Two sites may share an item name or two, so one item is not
    enough; a day of this site with some orders made invalid (a menu that lost an item)
    still has its places, so is not one."""
    return sorted(d for d, orders in by_date.items()
                  if any(o.items for o in orders)
                  and not any(o.items and all(i in site.menu for i in o.items)
                              for o in orders)
                  and not any(_known_place(site, o.deliver_to) for o in orders))


def refuse_foreign(site, by_date: dict[dt.date, list], *, stored_in: str,
                   given: dict | None = None, data=None, option: str = "--data folder",
                   param: str | None = None) -> None:
    """Raise one line naming ``site``'s menus and the first of :func:`foreign_days`, if
    any: ``stored_in`` the store's URL (password hidden) for days read from it, ``given``
    the days read from ``data``'s ``orders.csv`` instead, ``option`` what the user gives
    the site by (the CLI's --data folder, a job's data folder or source). Nothing is
    imported or flown before it: flown, the orders were stored as 'unknown item' over
    the day's flight. Shared by ``skyroute deliver`` and the deliver job."""
    bad = foreign_days(site, by_date)
    if not bad:
        return
    day = bad[0]
    orders = by_date[day]
    item = next(i for o in orders for i in o.items if i not in site.menu)
    if given and day in given:  # the folder's own orders: its CSVs and website disagree
        whence = f"of {day} in {data / 'database' / 'orders.csv'}"
        hint = "the folder's orders and website are not of one site"
    else:
        whence = f"stored for {day} in {store.safe_url(stored_in)}"
        hint = f"they are another site's orders: give the {option} they were imported from"
    more = f" (and {len(bad) - 1:,} more of the days)" if len(bad) > 1 else ""
    raise SkyrouteError(f"{site.source.where('menus/menus.json')}: none of the "
                        f"{len(orders):,} orders {whence}{more} is on these menus or goes to "
                        f"a place of this site (e.g. item {item!r}, deliverTo "
                        f"{orders[0].deliver_to!r}); {hint}; nothing was imported or flown",
                        param=param)


def _known_place(site, words: str) -> bool:
    try:
        site.locate(words)
    except InputFormatError:
        return False
    return True


def prepare_legs(site, orders, on_leg: Callable | None = None,
                 on_total: Callable | None = None) -> None:
    """Fill the leg cache for every place of ``orders``."""
    pts = places_of(site, orders)
    if on_total:
        on_total(missing_legs(site.world, pts))
    leg_table(site.world, pts, on_leg=on_leg)


def open_store(url: str, *, create: bool = True):
    """An engine for ``url`` with the schema created or upgraded to the newest migration.

    ``create=False``: ``None`` when there is no store at ``url`` yet (no SQLite file, or
    a database without skyroute's tables), and nothing is made: a command judges what
    it was given against the stored days first, and opens the store with ``create``
    once nothing refuses it (a refused command left a new store, its file, folder and
    tables, behind)."""
    if not create and not store.exists(url):
        return None
    engine = store.connect(url)
    store.init(engine)
    return engine
