"""The SQL store: orders in, deliveries and flight paths out (SQLAlchemy 2 Core).

Tables (the course's schemas plus the day and order of moves):

- ``orders(order_no, delivery_date, customer, deliver_to)``, ``order_details(order_no,
  line, item)``
- ``deliveries(delivery_date, order_no, delivered_to, cost_in_pence)``
- ``flightpath(delivery_date, seq, order_no, from_lon, from_lat, angle, to_lon, to_lat)``
- ``runs(delivery_date, started, finished, moves, money_delivered, money_placed, ...)``

and, from revision 0002, ``jobs`` and ``fleet_runs`` (:mod:`skyroute.jobs.store`); from
0003, ``jobs.owner`` and ``servers``; from 0004, ``fleet_run_files`` (in parts from 0005,
with their line counts from 0006).

A SQLite file by default, PostgreSQL (or any SQLAlchemy URL) by ``--db``. The schema is
made and upgraded by Alembic migrations shipped in the package (``db init`` runs them).
A day's results go in one transaction: its old rows are deleted and the new ones
inserted together, so a run killed midway leaves the previous state of that day. The
delivery runs commit it together with the day's files (:mod:`skyroute.jobs.deliver`).
"""

from __future__ import annotations

import datetime as dt
import json
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import NamedTuple

import sqlalchemy as sa

from skyroute.caches import register
from skyroute.errors import SkyrouteError, StoreBusyError, StoreSchemaError

DEFAULT_DB = "sqlite:///skyroute.db"
# How long a store waits for another process's write to finish before it is an error
# (StoreBusyError): a cron job's import or a day being stored by another 'skyroute
# deliver'. SQLite: its busy timeout (Python's sqlite3 waits 5 s), a URL's own
# '?timeout=SECONDS' wins. PostgreSQL: the session's lock_timeout (it waited for ever,
# e.g. behind a psql session left in a transaction), a URL's own
# '?options=-c lock_timeout=MS' wins.
BUSY_SECONDS = 30.0
# How long connecting to a database server may take before it is an error (libpq waits
# for ever: a server or proxy that took the connection and never answered held 'db init'
# and every request of the service). A URL's own '?connect_timeout=SECONDS' wins.
CONNECT_SECONDS = 10
SQL_INT = (-2**31, 2**31 - 1)  # an INTEGER column: 32 bits on PostgreSQL, 64 on SQLite
TABLES = ("orders", "order_details", "deliveries", "flightpath", "runs")
# The PostgreSQL advisory lock that :func:`init` holds while it makes or upgrades the
# schema (any fixed 64-bit number other programs on the database are unlikely to use)
SCHEMA_LOCK = 0x736B79726F757465  # "skyroute"
# ... and the pair (DAY_LOCK, the day's ordinal) that :func:`write_day` and a replacing
# :func:`import_orders` hold while they replace a day's rows (:func:`_lock_day`)
DAY_LOCK = 0x736B7964  # "skyd"
_REFLECTED: dict[tuple[str, tuple[str, ...]], dict[str, sa.Table]] = {}
register(_REFLECTED.clear)


def tables(engine: sa.Engine, names: tuple[str, ...] = TABLES) -> dict[str, sa.Table]:
    """The tables ``names`` (default the delivery tables) as the migrations made them,
    reflected once per database: the migrations are the one definition of the schema.
    Other packages' tables (``jobs``, ``fleet_runs``) live in the same store. A store
    without them is a :class:`~skyroute.errors.StoreSchemaError` naming its URL."""
    key = (str(engine.url), names)
    if key not in _REFLECTED:
        have = set(sa.inspect(engine).get_table_names())
        if "runs" not in have:
            raise StoreSchemaError(f"{_safe(key[0])}: no skyroute tables; run 'skyroute "
                                   "db init' first")
        missing = [n for n in names if n not in have]
        if missing:
            raise StoreSchemaError(f"{_safe(key[0])}: no table {', '.join(missing)} (an "
                                   "older schema); run 'skyroute db init' to upgrade it")
        md = sa.MetaData()
        md.reflect(engine, only=names)
        _REFLECTED[key] = dict(md.tables)
    return _REFLECTED[key]


def connect(url: str = DEFAULT_DB) -> sa.Engine:
    """An engine for ``url``; a bad URL, an unreachable server (one that does not answer
    within :data:`CONNECT_SECONDS`) or a PostgreSQL database that cannot hold every
    text SQLite does (:func:`_encoding`) is one clear error.

    On a server, a pooled connection is tested before each use (``pool_pre_ping``): one
    the server has ended (a restart, an idle timeout of a proxy or firewall) was handed
    out as it was, and the read or day on it failed ("terminating connection due to
    administrator command": the service's 500) until the pool had dropped each."""
    parsed = _parse(url)
    try:
        sqlite = parsed.drivername.startswith("sqlite")
        if sqlite and parsed.database not in (None, "", ":memory:"):
            folder = Path(parsed.database).parent
            try:
                folder.mkdir(parents=True, exist_ok=True)
            except OSError as exc:  # a file in the way, no such place, no permission
                raise SkyrouteError(f"url={_safe(url)}: cannot make the store's folder "
                                    f"{folder}: {exc.strerror or exc}", param="url") from None
        args: dict = {}
        if sqlite and "timeout" not in parsed.query:
            args["timeout"] = BUSY_SECONDS
        if parsed.drivername in LIBPQ:
            if "client_encoding" not in parsed.query:
                # text as UTF-8 whatever the database's encoding, so that a SQL_ASCII one
                # is read as str (the driver gave bytes: a TypeError traceback on
                # connecting) and judged by _encoding
                args["client_encoding"] = "utf8"
            if "connect_timeout" not in parsed.query:
                args["connect_timeout"] = CONNECT_SECONDS
            options = str(parsed.query.get("options", ""))
            if "lock_timeout" not in options:  # added to the URL's (connect_args win)
                args["options"] = (f"{options} -c lock_timeout="
                                   f"{round(BUSY_SECONDS * 1000)}").strip()
        engine = sa.create_engine(url, connect_args=args, pool_pre_ping=not sqlite)
        with engine.connect() as conn:
            encoding = _encoding(conn)
    except sa.exc.NoSuchModuleError:  # a URL, of a kind or a driver SQLAlchemy does not know
        raise SkyrouteError(f"url={_safe(url)!r}: {_unknown_kind(url)} ({EXAMPLE_URLS})",
                            param="url") from None
    except sa.exc.ArgumentError:  # one the dialect refuses: sqlite://user@/x.db
        raise SkyrouteError(f"url={_safe(url)!r}: not a database URL ({EXAMPLE_URLS})",
                            param="url") from None
    except sa.exc.DBAPIError as exc:  # refused, no such database or role, a bad option
        raise SkyrouteError(f"url={_safe(url)}: cannot connect: "
                            f"{str(exc.orig).strip().splitlines()[0]}", param="url") from None
    except ValueError as exc:  # an option's value the driver cannot read: ?timeout=abc
        raise SkyrouteError(f"url={_safe(url)}: cannot connect: a bad option value in the "
                            f"URL ({exc})", param="url") from None
    except ModuleNotFoundError as exc:
        raise SkyrouteError(f"url={_safe(url)}: driver {exc.name!r} is not installed",
                            param="url") from None
    if encoding not in (None, "UTF8"):
        engine.dispose()
        raise SkyrouteError(f"url={_safe(url)}: the database's encoding is {encoding}; "
                            "skyroute stores text of any language, as SQLite does: make "
                            f"the database in UTF8 (createdb -E UTF8 -T template0 "
                            f"{parsed.database}, or CREATE DATABASE {parsed.database} "
                            "ENCODING 'UTF8' TEMPLATE template0)", param="url")
    return engine


EXAMPLE_URLS = "e.g. sqlite:///skyroute.db or postgresql+psycopg://user@127.0.0.1:5432/test"


def _parse(url: str) -> sa.engine.URL:
    """``url`` parsed, or a SkyrouteError: not a URL, or a port that is not a number
    (SQLAlchemy reads it with int(): a ValueError traceback for ':5432x', '[::1:5432')."""
    try:
        return sa.engine.make_url(url)
    except ValueError:
        why = "its port is not a number"
    except sa.exc.ArgumentError:
        why = None
    raise SkyrouteError(f"url={_safe(url)!r}: not a database URL" +
                        (f": {why}" if why else "") + f" ({EXAMPLE_URLS})", param="url")


# SQLAlchemy's PostgreSQL drivers over libpq, which take libpq's client_encoding
LIBPQ = ("postgresql", "postgresql+psycopg", "postgresql+psycopg2",
         "postgresql+psycopg2cffi")


def _encoding(conn: sa.Connection) -> str | None:
    """A PostgreSQL database's encoding (``UTF8``, ``LATIN1``, ...; None on another
    kind of store). :func:`connect` refuses any but UTF8: SQLite holds any text, and a
    store on a server must hold what it does. A LATIN1 database refused an order whose
    text it has no letter for ('Zoë😀': a UnicodeEncodeError traceback), and SQL_ASCII
    counted a ``String(8)`` in bytes ('Zoë😀ß' is 5 letters and 9 bytes: refused) and
    could not be connected to without the client encoding :func:`connect` sets."""
    if conn.dialect.name != "postgresql":
        return None
    return str(conn.exec_driver_sql("show server_encoding").scalar()).upper()


def exists(url: str) -> bool:
    """Whether ``url`` holds a store already (made by :func:`init`, perhaps at an older
    revision), found without making anything: a SQLite file is made by connecting to
    it, so only its path is looked at. A bad URL or an unreachable server is the error
    of :func:`connect`."""
    try:
        parsed = sa.engine.make_url(url)
    except (sa.exc.ArgumentError, ValueError):  # connect() says what is wrong
        parsed = None
    if parsed is not None and parsed.drivername.startswith("sqlite"):
        db = parsed.database
        return db not in (None, "", ":memory:") and Path(db).exists()
    engine = connect(url)
    try:
        return sa.inspect(engine).has_table("orders")
    finally:
        engine.dispose()


def _unknown_kind(url: str) -> str:
    """What SQLAlchemy lacks for ``url``: the database (``postgres://``), or only the
    driver after its ``+`` (``postgresql+psycopg3://``: it knows PostgreSQL)."""
    kind, _, driver = sa.engine.make_url(url).drivername.partition("+")
    try:
        sa.engine.URL.create(kind).get_dialect()
    except sa.exc.NoSuchModuleError:
        return f"SQLAlchemy knows no database {kind!r}"
    return f"SQLAlchemy has no driver {driver!r} for {kind}"


def safe_url(url: str) -> str:
    """``url`` with its password as ``***``: for messages and logs (also a string
    SQLAlchemy cannot parse, whose ``user:password@`` is masked as text)."""
    try:
        return sa.engine.make_url(url).render_as_string(hide_password=True)
    except (sa.exc.ArgumentError, ValueError):  # ValueError: a port that is no number
        import re

        return re.sub(r"(://[^:/@]*:)[^@/]*@", r"\1***@", str(url))


_safe = safe_url


def is_busy(exc: BaseException) -> bool:
    """Whether ``exc`` is SQLite's "database is locked" (or "... table is locked"):
    another connection held a lock past the busy timeout, a read's too (a writer whose
    transaction outgrew its page cache holds the lock that keeps readers out); or
    PostgreSQL's lock timeout (SQLSTATE 55P03, lock_not_available: :data:`BUSY_SECONDS`
    waited for a lock another session held)."""
    if not isinstance(exc, sa.exc.OperationalError):
        return False
    orig = exc.orig
    code = getattr(orig, "sqlstate", None) or getattr(orig, "pgcode", None)
    return code == "55P03" or (code is None and "locked" in str(orig))


@contextmanager
def writing(engine: sa.Engine) -> Iterator[sa.Connection]:
    """``engine.begin()`` for a transaction that reads, then writes what it read was
    missing. On SQLite it takes the write lock first (``BEGIN IMMEDIATE``): two processes
    importing the same orders, or making the schema of a new store, at once both read
    "not there" and the second's insert was an IntegrityError traceback ("table orders
    already exists" for the schema); now the second waits and reads the first's rows. A
    lock held by another process past the busy timeout is a :class:`StoreBusyError`, not
    a "database is locked" traceback."""
    try:
        with engine.begin() as conn:
            if conn.dialect.name == "sqlite":
                conn.exec_driver_sql("BEGIN IMMEDIATE")
            yield conn
    except sa.exc.OperationalError as exc:
        if not is_busy(exc):
            raise
        raise StoreBusyError(f"{_safe(str(engine.url))}: the store is busy: another process "
                             "kept it locked for too long (its busy timeout); try again when "
                             "it is done") from None


def init(engine: sa.Engine) -> str:
    """Create or upgrade the schema to the newest migration; return its revision. One
    transaction that holds the write lock (SQLite) or the advisory lock
    :data:`SCHEMA_LOCK` (PostgreSQL) throughout, so two first runs at once on a new store
    make it once: the second waits, then finds it made."""
    from alembic import command
    from alembic.config import Config
    from alembic.runtime.migration import MigrationContext
    from alembic.util.exc import CommandError

    cfg = Config()
    cfg.set_main_option("script_location", str(Path(__file__).parent / "migrations"))
    url = _safe(str(engine.url))
    try:
        with writing(engine) as conn:
            if conn.dialect.name == "postgresql":
                # PostgreSQL's counterpart of SQLite's BEGIN IMMEDIATE here: two first
                # runs on an empty database both saw no schema and made it, and the later
                # failed ('relation "alembic_version" already exists'); the lock is held
                # to the end of this transaction, so the other waits and finds it made
                conn.execute(sa.select(sa.func.pg_advisory_xact_lock(SCHEMA_LOCK)))
            cfg.attributes["connection"] = conn
            command.upgrade(cfg, "head")
    except sa.exc.DatabaseError as exc:  # e.g. a file that is not SQLite's
        raise SkyrouteError(f"url={url}: not a usable store: "
                            f"{str(exc.orig).strip().splitlines()[0]}", param="url") from None
    except CommandError as exc:  # a revision this version does not know
        raise SkyrouteError(f"url={url}: the store's schema is unknown to this skyroute "
                            f"({exc}); was it written by a newer version?",
                            param="url") from None
    for key in [k for k in _REFLECTED if k[0] == str(engine.url)]:
        del _REFLECTED[key]
    with engine.connect() as conn:
        return MigrationContext.configure(conn).get_current_revision()


def check_fits(table: sa.Table, row: dict, where: str) -> None:
    """A SkyrouteError naming ``where``, the column and the value unless every value of
    ``row`` fits ``table``'s column on any store: text within its length, a whole number
    within :data:`SQL_INT` for an INTEGER. PostgreSQL refused such a value with a
    traceback, SQLite stored it (so the two stores differed) or overflowed past 2**63."""
    for name, value in row.items():
        typ = table.c[name].type
        if isinstance(value, str) and getattr(typ, "length", None) \
                and len(value) > typ.length:
            raise SkyrouteError(f"{where}{name} {value!r} is {len(value)} characters, "
                                f"{table.name}.{name} holds at most {typ.length}")
        if isinstance(value, int) and isinstance(typ, sa.Integer) \
                and not isinstance(typ, sa.BigInteger) \
                and not SQL_INT[0] <= value <= SQL_INT[1]:
            raise SkyrouteError(f"{where}{table.name}.{name} {value} is outside the store's "
                                f"INTEGER range ({SQL_INT[0]:,} to {SQL_INT[1]:,})")


class OrdersChangedError(SkyrouteError):
    """Orders given for import differ from the stored orders of their days: an order of
    the same number with another date, customer, place or items, or a stored order of
    a given day that is not given (a corrected file). Nothing was written. ``changes``:
    ``(day, order_no, field, stored, given)`` in day order, ``field`` one of
    :data:`ORDER_FIELDS` or None for a stored order that is not given (``given`` None);
    ``days``: the days whose orders differ (the days ``replace=True`` replaces)."""

    def __init__(self, changes: list[tuple], days: list[dt.date]) -> None:
        day, no, field, old, new = changes[0]
        first = (f"order {no} is stored but not given" if field is None else
                 f"order {no}: {field} {shown(new)}, stored {shown(old)}")
        more = f" (and {len(days) - 1} more day(s))" if len(days) > 1 else ""
        super().__init__(f"{day}: the orders differ from the stored ones ({first}){more}; "
                         "import with replace=True to store the given orders of those days",
                         param="replace")
        self.changes, self.days = changes, days


ORDER_FIELDS = ("date", "customer", "deliver_to", "items")


def shown(value) -> str:
    """An order's field value for a message: a date as YYYY-MM-DD, items as a list."""
    if isinstance(value, dt.date):
        return str(value)
    return repr(list(value) if isinstance(value, tuple) else value)


class Imported(NamedTuple):
    """What :func:`import_orders` did: orders ``added`` (new, or of a replaced day),
    orders stored before and kept (``had``; the store now holds ``added + had``), and
    the days whose stored orders were ``replaced``."""

    added: int
    had: int
    replaced: tuple[dt.date, ...] = ()


def import_orders(engine: sa.Engine, all_orders: Iterable, *,
                  replace: bool = False) -> Imported:
    """Insert the orders (and their items) not already stored. An order already stored
    as given is left as it is; an order stored differently (another date, customer,
    place or items), or a stored order of a given day that is not given, is
    :class:`OrdersChangedError` naming the days, unless ``replace``: then each such day's
    stored deliveries, flight path and run (flown from the old orders) are deleted, and
    the stored orders of each such day the given orders hold are replaced by the given
    ones; a day they do not hold (an order moved from it to another day) loses only the
    moved orders. One transaction: an
    error leaves the store as it was; a value wider than its column is an error naming
    the order (:func:`check_fits`), checked before anything is written."""
    t = tables(engine)
    all_orders = list(all_orders)
    for o in all_orders:
        where = f"order {o.order_no!r}: "
        check_fits(t["orders"], {"order_no": o.order_no, "customer": o.customer,
                                 "deliver_to": o.deliver_to}, where)
        for k, item in enumerate(o.items):
            check_fits(t["order_details"], {"line": k, "item": item}, where)
    try:
        return _import(engine, t, all_orders, replace)
    except sa.exc.IntegrityError:
        # another process added some of these orders after this one read what was there
        # (PostgreSQL; SQLite serialises the two in writing()): read again, add the rest
        return _import(engine, t, all_orders, replace)


def _import(engine: sa.Engine, t: dict[str, sa.Table], all_orders: list,
            replace: bool) -> Imported:
    orders, order_details = t["orders"], t["order_details"]
    with writing(engine) as conn:
        have = set(conn.scalars(sa.select(orders.c.order_no)))
        changes = _changes(conn, t, all_orders, have)
        days = sorted({c[0] for c in changes})
        if changes and not replace:
            raise OrdersChangedError(changes, days)
        if days:
            for day in days:  # a delivery of the day being stored waits (PostgreSQL)
                _lock_day(conn, day)
            # the days the file gives are replaced whole; a day it does not give (an
            # order moved from it) loses only the moved orders, not its others
            given = sorted({o.date for o in all_orders} & set(days))
            picked = orders.c.delivery_date.in_(given) | orders.c.order_no.in_(
                sorted({c[1] for c in changes if c[0] not in given}))
            gone = set(conn.scalars(sa.select(orders.c.order_no).where(picked)))
            for name in ("flightpath", "deliveries", "runs"):  # flown from the old orders
                conn.execute(t[name].delete().where(t[name].c.delivery_date.in_(days)))
            conn.execute(order_details.delete().where(order_details.c.order_no.in_(
                sa.select(orders.c.order_no).where(picked))))
            conn.execute(orders.delete().where(picked))
            have -= gone
        new = [o for o in all_orders if o.order_no not in have]
        heads = [{"order_no": o.order_no, "delivery_date": o.date, "customer": o.customer,
                  "deliver_to": o.deliver_to} for o in new]
        rows = [{"order_no": o.order_no, "line": k, "item": item}
                for o in new for k, item in enumerate(o.items)]
        if heads:
            conn.execute(orders.insert(), heads)
        if rows:
            conn.execute(order_details.insert(), rows)
    return Imported(len(new), len(have), tuple(days))


def _changes(conn: sa.Connection, t: dict[str, sa.Table], given: list,
             have: set[str]) -> list[tuple]:
    """How ``given`` differs from the stored orders of its days and numbers (see
    :class:`OrdersChangedError`); a day an order moved from differs too."""
    if not given:
        return []
    orders = t["orders"]
    days = {o.date for o in given}
    stored = {o.order_no: o for o in _orders_where(
        conn, t, orders.c.delivery_date.between(min(days), max(days)))}
    moved = sorted({o.order_no for o in given} & have - set(stored))
    for k in range(0, len(moved), 500):
        stored.update((o.order_no, o) for o in _orders_where(
            conn, t, orders.c.order_no.in_(moved[k:k + 500])))
    numbers = {o.order_no for o in given}
    out = []
    for o in given:
        old = stored.get(o.order_no)
        for field in ORDER_FIELDS if old is not None else ():
            if getattr(old, field) != getattr(o, field):
                out.append((o.date, o.order_no, field, getattr(old, field),
                            getattr(o, field)))
                if field == "date":
                    out.append((old.date, o.order_no, field, old.date, o.date))
    out += [(old.date, no, None, old, None) for no, old in stored.items()
            if old.date in days and no not in numbers]
    return sorted(out, key=lambda c: (c[0], c[1]))


def _orders_where(conn: sa.Connection, t: dict[str, sa.Table], where) -> list:
    """The stored orders that ``where`` (on ``orders``) picks, by order number, items in
    their original order."""
    from skyroute.delivery.orders import Order

    orders, order_details = t["orders"], t["order_details"]
    heads = conn.execute(sa.select(orders).where(where).order_by(orders.c.order_no)).all()
    items: dict[str, list[str]] = {h.order_no: [] for h in heads}
    q = sa.select(order_details.c.order_no, order_details.c.item) \
        .join(orders, orders.c.order_no == order_details.c.order_no).where(where) \
        .order_by(order_details.c.order_no, order_details.c.line)
    for no, item in conn.execute(q):
        items[no].append(item)
    return [Order(h.order_no, h.delivery_date, h.customer, h.deliver_to,
                  tuple(items[h.order_no])) for h in heads]


def orders_between(engine: sa.Engine, first: dt.date, last: dt.date) -> dict[dt.date, list]:
    """The stored orders of each day from ``first`` to ``last`` (days without orders are
    absent), items in their original order."""
    t = tables(engine)
    with engine.connect() as conn:
        found = _orders_where(conn, t, t["orders"].c.delivery_date.between(first, last))
    out: dict[dt.date, list] = {}
    for o in found:
        out.setdefault(o.date, []).append(o)
    return out


def order_dates(engine: sa.Engine) -> list[dt.date]:
    orders = tables(engine)["orders"]
    with engine.connect() as conn:
        return list(conn.scalars(sa.select(orders.c.delivery_date).distinct()
                                 .order_by(orders.c.delivery_date)))


class DayKeptError(SkyrouteError):
    """A day's new results were not stored because the day's stored run delivered
    orders and the new one must not replace it (:func:`write_day`'s ``keep``: e.g. every
    order of the new run is invalid, as when the orders are flown with another site's
    menus). Nothing was written; the stored day is as it was. ``date``, ``delivered``
    (orders the stored run delivered), ``why`` (the new run's fault)."""

    def __init__(self, date: dt.date, delivered: int, why: str) -> None:
        super().__init__(f"{date}: {why}, so the day's stored flight, which delivered "
                         f"{delivered:,} order{'' if delivered == 1 else 's'}, is kept "
                         "(nothing was written for the day)", param="replace")
        self.date, self.delivered, self.why = date, delivered, why


def write_day(engine: sa.Engine | sa.Connection, date: dt.date, run: dict,
              delivered: Iterable[dict], moves: Iterable[dict], *,
              keep: str | None = None) -> None:
    """Replace one day's results in one transaction (``moves`` may be a generator). The
    run and delivery rows are checked to fit their columns first (:func:`check_fits`:
    money beyond a 32-bit INTEGER), so a failure leaves the day as it was. Two writers
    of one day at once: the later waits for the earlier's transaction, then replaces its
    rows (SQLite: its write lock; PostgreSQL: an advisory lock on the day).

    ``engine``: an Engine (the day is committed here, in a transaction of its own), or
    a Connection in a transaction of :func:`writing`: the day is written in it and its
    owner commits it (with the day's files: :meth:`skyroute.files.Together.enter`).

    ``keep``: why this run must not replace a stored run of the day that delivered
    orders (None: it replaces any); such a stored run is kept, and
    :class:`DayKeptError` raised naming ``keep``, read in the same transaction."""
    t_ = tables(engine.engine)
    flightpath, deliveries, runs = t_["flightpath"], t_["deliveries"], t_["runs"]
    head = {**run, "delivery_date": date,
            "settings": json.dumps(run.get("settings", {}), sort_keys=True)}
    rows = [{**d, "delivery_date": date} for d in delivered]
    check_fits(runs, head, f"{date}: ")
    for row in rows:
        check_fits(deliveries, row, f"{date}: order {row.get('order_no')!r}: ")
    with _writing_in(engine) as conn:
        _lock_day(conn, date)
        if keep is not None:
            had = conn.scalar(sa.select(runs.c.orders_delivered)
                              .where(runs.c.delivery_date == date))
            if had:
                raise DayKeptError(date, had, keep)
        for t in (flightpath, deliveries, runs):
            conn.execute(t.delete().where(t.c.delivery_date == date))
        conn.execute(runs.insert(), [head])
        if rows:
            conn.execute(deliveries.insert(), rows)
        batch = []
        for m in moves:
            batch.append({**m, "delivery_date": date})
            if len(batch) >= 500:
                conn.execute(flightpath.insert(), batch)
                batch = []
        if batch:
            conn.execute(flightpath.insert(), batch)


@contextmanager
def _writing_in(engine: sa.Engine | sa.Connection) -> Iterator[sa.Connection]:
    """A Connection's own transaction as it is (its owner commits), or an Engine's new
    one (:func:`writing`)."""
    if isinstance(engine, sa.Connection):
        yield engine
    else:
        with writing(engine) as conn:
            yield conn


def delete_unflown_day(engine: sa.Engine, date: dt.date) -> dict | None:
    """Delete a stored day whose drone did not fly (a mistyped date, a day without
    orders, or one whose orders could not be flown): its run, in one transaction that
    holds the day as :func:`write_day` does. A day with a flight (moves or deliveries)
    is kept: its flight and deliveries are what was flown (fly the day again to replace
    them). The day's orders are input, imported by ``db import``, and always stay.

    Returns None for a day not stored, else ``{"moves", "delivered", "deleted"}`` as the
    store held them (``deleted`` False for a day with a flight)."""
    t_ = tables(engine)
    flightpath, deliveries, runs = t_["flightpath"], t_["deliveries"], t_["runs"]
    with writing(engine) as conn:
        _lock_day(conn, date)
        moves = conn.scalar(sa.select(runs.c.moves).where(runs.c.delivery_date == date))
        if moves is None:
            return None
        delivered = conn.scalar(sa.select(sa.func.count()).select_from(deliveries)
                                .where(deliveries.c.delivery_date == date))
        flown = moves > 0 or delivered > 0
        if not flown:
            for t in (flightpath, deliveries, runs):
                conn.execute(t.delete().where(t.c.delivery_date == date))
    return {"moves": moves, "delivered": delivered, "deleted": not flown}


def _lock_day(conn: sa.Connection, date: dt.date) -> None:
    """On PostgreSQL, hold the day's advisory lock to the end of ``conn``'s transaction.
    Two runs of one day at once both deleted the day's rows as they were, and the later's
    insert was an IntegrityError ('duplicate key value violates unique constraint
    "runs_pkey"'); an import replacing the day could let a delivery flown from the old
    orders land after its delete. With the lock the later waits, then replaces the
    earlier's rows (as SQLite's BEGIN IMMEDIATE in :func:`writing` does); other days are
    not held up."""
    if conn.dialect.name == "postgresql":
        conn.execute(sa.select(sa.func.pg_advisory_xact_lock(
            sa.cast(DAY_LOCK, sa.Integer), sa.cast(date.toordinal(), sa.Integer))))


def day_rows(engine: sa.Engine, date: dt.date) -> dict[str, list[tuple]]:
    """A day's stored deliveries and flightpath rows (for comparing stores)."""
    t = tables(engine)
    flightpath, deliveries = t["flightpath"], t["deliveries"]
    with engine.connect() as conn:
        return {
            "deliveries": [tuple(r) for r in conn.execute(
                sa.select(deliveries).where(deliveries.c.delivery_date == date)
                .order_by(deliveries.c.order_no))],
            "flightpath": [tuple(r) for r in conn.execute(
                sa.select(flightpath).where(flightpath.c.delivery_date == date)
                .order_by(flightpath.c.seq))]}


def store_day(engine: sa.Engine | sa.Connection, result, *, replace: bool = False) -> None:
    """Write a :class:`~skyroute.delivery.day.DayResult` (run, deliveries, moves) in
    one transaction (``engine``'s own, or a Connection's, as :func:`write_day`),
    replacing the day's stored results; but a day whose every order is
    invalid does not replace a stored run that delivered orders (:class:`DayKeptError`)
    unless ``replace``: flown with the wrong site's menus, every order is 'unknown
    item', and that silently replaced the day's real flight."""
    f = result.flight.flight
    run = {"started": dt.datetime.fromtimestamp(result.started),
           "finished": dt.datetime.fromtimestamp(result.started + result.seconds),
           "moves": f.moves, "orders_placed": len(result.orders),
           "orders_delivered": len(result.delivered), "orders_invalid": len(result.invalid),
           "money_delivered": result.money_delivered, "money_placed": result.money_placed,
           "settings": result.settings}
    delivered = [{"order_no": p.order.order_no, "delivered_to": p.order.deliver_to,
                  "cost_in_pence": p.cost} for p in result.delivered]
    moves = ({"seq": k, "order_no": result.flight.order_no[k],
              "from_lon": float(f.frm[k, 0]), "from_lat": float(f.frm[k, 1]),
              "angle": int(f.angle[k]), "to_lon": float(f.to[k, 0]),
              "to_lat": float(f.to[k, 1])} for k in range(f.moves))
    keep = None
    if not replace and result.orders and len(result.invalid) == len(result.orders):
        o, reason = result.invalid[0]
        keep = (f"every one of the day's {len(result.orders):,} orders is invalid (order "
                f"{o.order_no}: {reason})")
    write_day(engine, result.date, run, delivered, moves, keep=keep)
