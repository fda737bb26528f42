"""The SQL store: migrations make the issue's tables, import is idempotent, a day is
written whole (a killed run leaves the previous day) and rerunning replaces it."""

from __future__ import annotations

import datetime as dt
import re
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest
import sqlalchemy as sa

from skyroute.delivery import store
from skyroute.delivery.orders import Order
from skyroute.errors import SkyrouteError
from tests.conftest import PG, new_pg_database

DAY = dt.date(2024, 1, 1)
COLUMNS = {
    "orders": ["order_no", "delivery_date", "customer", "deliver_to"],
    "order_details": ["order_no", "line", "item"],
    "deliveries": ["delivery_date", "order_no", "delivered_to", "cost_in_pence"],
    "flightpath": ["delivery_date", "seq", "order_no", "from_lon", "from_lat", "angle",
                   "to_lon", "to_lat"],
    "runs": ["delivery_date", "started", "finished", "moves", "orders_placed",
             "orders_delivered", "orders_invalid", "money_delivered", "money_placed",
             "settings"],
}


def run_row(moves: int) -> dict:
    now = dt.datetime(2024, 1, 1, 12)
    return {"started": now, "finished": now, "moves": moves, "orders_placed": 1,
            "orders_delivered": 1, "orders_invalid": 0, "money_delivered": 100,
            "money_placed": 100, "settings": {"method": "test"}}


def moves(n: int, label: str = "aaaaaaaa"):
    for k in range(n):
        yield {"seq": k, "order_no": label, "from_lon": -3.0, "from_lat": 55.0,
               "angle": -999, "to_lon": -3.0, "to_lat": 55.0}


@pytest.fixture
def engine(tmp_path):
    e = store.connect(f"sqlite:///{tmp_path / 'store.db'}")
    assert store.init(e) == "0006"
    return e


def test_init_makes_the_issues_tables_and_is_repeatable(engine):
    insp = sa.inspect(engine)
    for table, cols in COLUMNS.items():
        assert [c["name"] for c in insp.get_columns(table)] == cols
    assert store.init(engine) == "0006"  # again: nothing to do


def test_the_csv_readers_widths_are_the_stores_columns(engine):
    # the reader refuses a value too long for its column before any store is opened
    from skyroute.delivery.orders import WIDTHS

    t = store.tables(engine)
    columns = {"orderNo": t["orders"].c.order_no, "customer": t["orders"].c.customer,
               "deliverTo": t["orders"].c.deliver_to, "item": t["order_details"].c.item}
    assert {k: c.type.length for k, c in columns.items()} == WIDTHS


def test_import_is_idempotent(engine):
    orders = [Order("0000000a", DAY, "s2400001", "a.b.c", ("x", "y", "x")),
              Order("0000000b", DAY, "s2400002", "a.b.d", ("z",))]
    assert store.import_orders(engine, orders)[:2] == (2, 0)
    assert store.import_orders(engine, orders)[:2] == (0, 2)
    back = store.orders_between(engine, DAY, DAY)[DAY]
    assert back == orders  # items, repeats and order kept


def test_rerun_replaces_the_day(engine):
    store.write_day(engine, DAY, run_row(5), [], moves(5))
    store.write_day(engine, DAY, run_row(3), [], moves(3, "bbbbbbbb"))
    rows = store.day_rows(engine, DAY)["flightpath"]
    assert len(rows) == 3 and {r[2] for r in rows} == {"bbbbbbbb"}


def test_a_run_that_must_not_replace_a_delivering_day_keeps_it(engine):
    # a day flown with another site's menus (every order invalid) replaced the day's
    # real flight; with ``keep`` a stored run that delivered is kept, read in the
    # transaction that would replace it
    import pickle

    store.write_day(engine, DAY, run_row(5), [], moves(5))
    nothing = {**run_row(0), "orders_delivered": 0, "orders_invalid": 1}
    with pytest.raises(store.DayKeptError) as info:
        store.write_day(engine, DAY, nothing, [], moves(0), keep="every order is invalid")
    assert str(info.value) == ("2024-01-01: every order is invalid, so the day's stored "
                               "flight, which delivered 1 order, is kept (nothing was "
                               "written for the day)")
    assert len(store.day_rows(engine, DAY)["flightpath"]) == 5
    again = pickle.loads(pickle.dumps(info.value))  # raised in worker processes
    assert type(again) is store.DayKeptError and str(again) == str(info.value)
    assert (again.date, again.delivered) == (DAY, 1)
    store.write_day(engine, DAY, nothing, [], moves(0))  # no reason given: replaced
    assert store.day_rows(engine, DAY)["flightpath"] == []
    store.write_day(engine, DAY, nothing, [], moves(2), keep="every order is invalid")
    assert len(store.day_rows(engine, DAY)["flightpath"]) == 2  # it delivered nothing


def test_killed_run_leaves_no_partial_day(engine, tmp_path):
    store.write_day(engine, DAY, run_row(5), [], moves(5))
    script = textwrap.dedent(f"""
        import datetime as dt, sys, time
        from skyroute.delivery import store
        from tests.delivery.test_store import moves, run_row
        e = store.connect({str(engine.url)!r})
        def slow():
            for k, m in enumerate(moves(3000, "cccccccc")):
                if k == 1200:  # two batches inserted, the old rows deleted
                    print("midway", flush=True)
                    time.sleep(120)
                yield m
        store.write_day(e, dt.date(2024, 1, 1), run_row(3000), [], slow())
    """)
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True,
                            cwd=str(Path(__file__).parents[2]))
    assert proc.stdout.readline().strip() == "midway"
    proc.kill()
    proc.wait()
    engine.dispose()
    rows = store.day_rows(engine, DAY)["flightpath"]
    assert len(rows) == 5 and {r[2] for r in rows} == {"aaaaaaaa"}
    with engine.connect() as c:
        assert c.execute(sa.text("select moves from runs")).scalar_one() == 5


def test_bad_urls_are_one_line_errors(tmp_path):
    with pytest.raises(SkyrouteError, match="not a database URL"):
        store.connect("nonsense")
    for url in ("sqlite://u:sekret@/tmp/x.db", "nonsense://u:sekret@h"):  # not echoed
        with pytest.raises(SkyrouteError, match=r"u:\*\*\*@") as err:
            store.connect(url)
        assert "sekret" not in str(err.value)
    with pytest.raises(SkyrouteError, match="cannot connect"):
        store.connect("postgresql+psycopg://nobody@127.0.0.1:1/none")
    e = store.connect(f"sqlite:///{tmp_path / 'empty.db'}")
    with pytest.raises(SkyrouteError, match="skyroute db init"):
        store.orders_between(e, DAY, DAY)


@pytest.mark.parametrize("url, words", [
    # SQLAlchemy reads the port with int(): a ValueError traceback
    ("postgresql+psycopg://u:sekret@127.0.0.1:54x2/db", "not a database URL: its port is "
     "not a number"),
    ("postgresql+psycopg://u:sekret@[::1:5432/db", "not a database URL: its port is not a "
     "number"),
    # the driver's own refusals of an option: a ValueError traceback (SQLite) and "the
    # store's database failed" (psycopg's ProgrammingError), which named no URL
    ("sqlite:///{tmp}/x.db?timeout=soon", "cannot connect: a bad option value in the URL "
     "(could not convert string to float: 'soon')"),
    ("postgresql+psycopg://u:sekret@127.0.0.1:1/db?nosuch=1", "cannot connect: invalid "
     'connection option "nosuch"'),
])
def test_a_url_with_a_bad_port_or_option_is_one_line(tmp_path, url, words):
    with pytest.raises(SkyrouteError) as err:
        store.connect(url.format(tmp=tmp_path))
    msg = str(err.value)
    assert words in msg and err.value.param == "url", msg
    assert "sekret" not in msg and "\n" not in msg
    assert not (tmp_path / "x.db").exists()


def test_a_server_that_never_answers_is_one_line_not_a_hang():
    # a server (or a proxy before it) that took the connection and said nothing: libpq
    # waited for ever, so 'db init' hung and so did each request of the service
    import socket

    with socket.socket() as silent:
        silent.bind(("127.0.0.1", 0))
        silent.listen(8)
        url = f"postgresql+psycopg://u@127.0.0.1:{silent.getsockname()[1]}/db"
        script = textwrap.dedent(f"""
            from skyroute.delivery import store
            from skyroute.errors import SkyrouteError
            store.CONNECT_SECONDS = 2
            try:
                store.connect({url!r})
            except SkyrouteError as exc:
                print(exc)
        """)
        try:
            out = subprocess.run([sys.executable, "-c", script], capture_output=True,
                                 text=True, timeout=60, cwd=str(Path(__file__).parents[2]))
        except subprocess.TimeoutExpired:
            pytest.fail("connecting to a silent server never gave up")
    assert out.stdout == f"url={url}: cannot connect: connection timeout expired\n", out


def test_a_store_folder_that_cannot_be_made_is_one_line(tmp_path):
    # a file where the folder should be: the OSError of mkdir was a traceback (the CLI's
    # exit 1, the service's 500)
    (tmp_path / "taken").write_text("a file, not a folder\n")
    with pytest.raises(SkyrouteError, match=r"cannot make the store's folder .*taken/sub"
                       ) as err:
        store.connect(f"sqlite:///{tmp_path / 'taken' / 'sub' / 'x.db'}")
    assert err.value.param == "url" and "\n" not in str(err.value)


def test_a_file_that_is_not_a_store_is_one_line(tmp_path):
    path = tmp_path / "not.db"
    path.write_text("garbage\n")
    e = store.connect(f"sqlite:///{path}")  # SQLite opens lazily: the schema step finds it
    with pytest.raises(SkyrouteError, match="not a usable store: file is not a database"):
        store.init(e)


def test_a_store_at_an_unknown_revision_is_one_line(tmp_path):
    e = store.connect(f"sqlite:///{tmp_path / 'new.db'}")
    store.init(e)
    with e.begin() as conn:
        conn.execute(sa.text("update alembic_version set version_num = '9999'"))
    with pytest.raises(SkyrouteError, match=r"schema is unknown.*'9999'.*newer version"):
        store.init(e)


@pytest.mark.parametrize("field, value, words", [
    ("order_no", "123456789", "order '123456789': order_no '123456789' is 9 characters"),
    ("customer", "s24000011", "order '0000000a': customer 's24000011' is 9 characters"),
    ("deliver_to", "a." * 40 + "b", "order '0000000a': deliver_to 'a.a."),
])
def test_an_order_wider_than_its_column_is_refused_on_any_store(engine, field, value,
                                                                 words):
    # PostgreSQL refused it with a DataError traceback; SQLite stored it, so the two
    # stores held different orders
    good = {"order_no": "0000000a", "date": DAY, "customer": "s2400001",
            "deliver_to": "a.b.c", "items": ("x",)}
    orders = [Order(**{**good, "order_no": "0000000b"}), Order(**{**good, field: value})]
    with pytest.raises(SkyrouteError, match=re.escape(words) + ".*holds at most"):
        store.import_orders(engine, orders)
    with engine.connect() as c:
        assert c.execute(sa.text("select count(*) from orders")).scalar_one() == 0


def test_an_item_wider_than_its_column_is_refused(engine):
    orders = [Order("0000000a", DAY, "s2400001", "a.b.c", ("x", "y" * 101))]
    with pytest.raises(SkyrouteError, match=r"order '0000000a': item 'y+' is 101 characters, "
                                            r"order_details\.item holds at most 100"):
        store.import_orders(engine, orders)


@pytest.mark.parametrize("field", ["money_delivered", "money_placed"])
def test_money_over_sql_integer_is_one_line_and_no_rows(engine, field):
    # an INTEGER column is 32 bits on PostgreSQL (a DataError traceback after the day
    # was flown), 64 on SQLite (an OverflowError traceback past 2**63)
    store.write_day(engine, DAY, run_row(5), [], moves(5))
    with pytest.raises(SkyrouteError, match=rf"2024-01-01: runs\.{field} 3000000000 is "
                                            r"outside the store's INTEGER range"):
        store.write_day(engine, DAY, {**run_row(3), field: 3_000_000_000}, [], moves(3))
    rows = store.day_rows(engine, DAY)["flightpath"]
    assert len(rows) == 5  # the day as it was


def test_a_delivery_cost_over_sql_integer_names_the_order(engine):
    big = {"order_no": "0000000a", "delivered_to": "a.b.c", "cost_in_pence": 2**63 + 50}
    with pytest.raises(SkyrouteError, match=r"2024-01-01: order '0000000a': deliveries\."
                                            r"cost_in_pence 9223372036854775858 is outside"):
        store.write_day(engine, DAY, run_row(1), [big], moves(1))
    assert store.day_rows(engine, DAY) == {"deliveries": [], "flightpath": []}


def _import_meanwhile(engine, other, orders) -> list:
    """Arrange that ``other`` imports ``orders`` just before ``engine`` inserts its own
    (after it has read which are stored): two ``skyroute db import`` or ``deliver
    --data`` runs at once. What the other import did (returned or raised) is listed."""
    seen: list = []

    def meanwhile(conn, cursor, statement, *args):
        if statement.lstrip().upper().startswith("INSERT INTO ORDERS") and not seen:
            try:
                seen.append(store.import_orders(other, orders))
            except SkyrouteError as exc:
                seen.append(exc)

    sa.event.listen(engine, "before_cursor_execute", meanwhile)
    return seen


TWO = [Order("0000000a", DAY, "s2400001", "a.b.c", ("x",)),
       Order("0000000b", DAY, "s2400002", "a.b.d", ("z",))]


def test_two_imports_at_once_wait_for_each_other(engine):
    # the second read "not stored" too and its insert was an IntegrityError traceback;
    # on SQLite the first now holds the write lock from its read, so the other waits
    # (here past its 0.2 s busy timeout: a one-line error, nothing written)
    other = store.connect(f"{engine.url}?timeout=0.2")
    seen = _import_meanwhile(engine, other, TWO)
    assert store.import_orders(engine, TWO) == (2, 0, ())
    assert len(seen) == 1 and isinstance(seen[0], SkyrouteError)
    assert re.search(r"store\.db\?timeout=0\.2: the store is busy: another process kept it "
                     r"locked", str(seen[0]))
    assert store.import_orders(other, TWO) == (0, 2, ())


def test_an_import_that_lost_the_race_adds_the_rest(engine, monkeypatch):
    # PostgreSQL does not serialise the two: the later insert collides, is read again
    monkeypatch.setattr(store, "writing", lambda e: e.begin(), raising=False)
    seen = _import_meanwhile(engine, store.connect(str(engine.url)), TWO[:1])
    assert store.import_orders(engine, TWO) == (1, 1, ())
    assert seen == [(1, 0, ())]
    assert store.orders_between(engine, DAY, DAY)[DAY] == TWO


def test_a_new_store_made_by_two_processes_at_once(tmp_path):
    # the second saw no schema and made it again: "not a usable store: table orders
    # already exists"; making it now holds the write lock, so the second finds it made
    url = f"sqlite:///{tmp_path / 'new.db'}"
    script = textwrap.dedent(f"""
        from skyroute.delivery import store
        print(store.init(store.connect({url!r})))
    """)
    procs = [subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True,
                              cwd=str(Path(__file__).parents[2])) for _ in range(3)]
    outs = [p.communicate(timeout=60)[0] for p in procs]
    done = [(p.returncode, out) for p, out in zip(procs, outs, strict=True)]
    assert done == [(0, "0006\n")] * 3


def test_a_store_locked_too_long_is_one_line(tmp_path):
    import sqlite3

    path = tmp_path / "busy.db"
    store.init(store.connect(f"sqlite:///{path}"))
    holder = sqlite3.connect(path, isolation_level=None)
    holder.execute("BEGIN IMMEDIATE")  # another process writing, for longer than we wait
    try:
        e = store.connect(f"sqlite:///{path}?timeout=0.1")
        with pytest.raises(SkyrouteError, match=r"busy\.db\?timeout=0\.1: the store is busy"):
            store.write_day(e, DAY, run_row(1), [], moves(1))
        with pytest.raises(SkyrouteError, match="the store is busy"):
            store.init(e)
    finally:
        holder.rollback()
        holder.close()
    assert store.day_rows(e, DAY) == {"deliveries": [], "flightpath": []}


def test_sqlite_waits_longer_than_pythons_five_seconds(tmp_path):
    e = store.connect(f"sqlite:///{tmp_path / 'x.db'}")
    with e.connect() as c:
        assert c.exec_driver_sql("pragma busy_timeout").scalar() == store.BUSY_SECONDS * 1000


def test_a_new_postgresql_store_made_by_two_runs_at_once(fresh_pg):
    # both saw no schema and made it: the later ones failed ("not a usable store:
    # relation "alembic_version" already exists"); making it now takes a
    # transaction-level advisory lock first, so the others wait and find it made
    script = textwrap.dedent(f"""
        from skyroute.delivery import store
        print(store.init(store.connect({fresh_pg!r})))
    """)
    procs = [subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True,
                              cwd=str(Path(__file__).parents[2])) for _ in range(4)]
    done = [(p.communicate(timeout=60), p.returncode) for p in procs]
    assert [(out, rc) for (out, _), rc in done] == [("0006\n", 0)] * 4, done


@pytest.mark.parametrize("encoding", ["SQL_ASCII", "LATIN1"])
def test_a_postgresql_database_not_in_utf8_is_refused_in_one_line(encoding):
    # SQL_ASCII: a TypeError traceback on connecting (the driver read text as bytes);
    # LATIN1: connected, then an order of 'Zoë😀' was a UnicodeEncodeError traceback
    with new_pg_database("skyroute_enc", encoding=encoding) as url:
        with pytest.raises(SkyrouteError) as err:
            store.connect(url)
        name = sa.engine.make_url(url).database
        assert str(err.value) == (
            f"url={url}: the database's encoding is {encoding}; skyroute stores text of any "
            "language, as SQLite does: make the database in UTF8 (createdb -E UTF8 -T "
            f"template0 {name}, or CREATE DATABASE {name} ENCODING 'UTF8' TEMPLATE "
            "template0)")
        assert err.value.param == "url"


def test_postgresql_stores_any_text_as_sqlite_does(fresh_pg, engine):
    given = [Order("ü1234567", DAY, "Zoë😀ß", "ŵ.日本.ø", ("Crème brûlée 🍮" + "x" * 85,))]
    pg = store.connect(fresh_pg)
    store.init(pg)
    for e in (engine, pg):
        assert store.import_orders(e, given) == (1, 0, ())
        assert store.orders_between(e, DAY, DAY) == {DAY: given}
    pg.dispose()


def test_a_connection_the_server_ended_is_replaced_not_an_error(fresh_pg):
    # the pool handed out a connection the server had ended (a restart, a proxy's idle
    # timeout): the read failed ('terminating connection due to administrator command',
    # the service's 500) until every pooled connection had failed once
    e = store.connect(fresh_pg)
    store.init(e)
    with e.connect() as c:  # the one connection of the pool
        pid = c.exec_driver_sql("select pg_backend_pid()").scalar()
    admin = sa.create_engine(PG, isolation_level="AUTOCOMMIT")
    with admin.connect() as c:
        assert c.execute(sa.text("select pg_terminate_backend(:p)"), {"p": pid}).scalar()
        for _ in range(600):  # until it has gone
            if not c.execute(sa.text("select count(*) from pg_stat_activity where pid = :p"),
                             {"p": pid}).scalar():
                break
            time.sleep(0.05)
        else:
            pytest.fail("the server never ended the connection")
    admin.dispose()
    assert store.order_dates(e) == []
    with e.connect() as c:
        assert c.exec_driver_sql("select pg_backend_pid()").scalar() != pid
    e.dispose()


@pytest.mark.parametrize("stored_before", [False, True])
def test_two_runs_of_one_day_at_once_on_postgresql(fresh_pg, stored_before):
    # the later writer's insert of the run was an IntegrityError ('duplicate key value
    # violates unique constraint "runs_pkey"'): both had deleted the day as it was
    e = store.connect(fresh_pg)
    store.init(e)
    if stored_before:
        store.write_day(e, DAY, run_row(2), [], moves(2, "old00000"))
    inside, release, errors = threading.Event(), threading.Event(), []

    def held(n):  # the first writer's moves: it waits with its run row written
        for k, m in enumerate(moves(n, "first000")):
            if k == 1:
                inside.set()
                release.wait(30)
            yield m

    def write(n, rows):
        try:
            store.write_day(e, DAY, run_row(n), [], rows)
        except Exception as exc:  # the test reports what it was
            errors.append(f"{type(exc).__name__}: {exc}")

    first = threading.Thread(target=write, args=(3, held(3)))
    first.start()
    assert inside.wait(30)
    second = threading.Thread(target=write, args=(4, moves(4, "second00")))
    second.start()
    with e.connect() as c:  # the second is waiting for the first's transaction
        for _ in range(300):
            if c.execute(sa.text("select count(*) from pg_locks where not granted")
                         ).scalar_one():
                break
            time.sleep(0.05)
        else:
            pytest.fail("the second writer never waited")
    release.set()
    first.join(30)
    second.join(30)
    assert errors == []
    with e.connect() as c:  # the later run's rows, whole
        assert c.execute(sa.text("select moves from runs")).all() == [(4,)]
    assert {r[2] for r in store.day_rows(e, DAY)["flightpath"]} == {"second00"}
    assert len(store.day_rows(e, DAY)["flightpath"]) == 4
    e.dispose()


def test_a_lock_held_past_the_busy_timeout_is_busy_on_postgresql(fresh_pg, monkeypatch):
    # a session that kept a lock the day needs (a psql session left in a transaction
    # that touched runs, a stalled writer): the day waited for ever on PostgreSQL, where
    # SQLite's busy timeout made it StoreBusyError
    from skyroute.errors import StoreBusyError

    monkeypatch.setattr(store, "BUSY_SECONDS", 1.0)
    e = store.connect(fresh_pg)
    store.init(e)
    outcome: list = []

    def write():
        try:
            store.write_day(e, DAY, run_row(2), [], moves(2))
            outcome.append("written")
        except Exception as exc:  # the test reports what it was
            outcome.append(exc)

    holder = sa.create_engine(fresh_pg)
    with holder.connect() as h:
        h.execute(sa.text("lock table runs in exclusive mode"))  # held to its rollback
        writer = threading.Thread(target=write, daemon=True)
        writer.start()
        writer.join(60)
        if writer.is_alive():
            h.rollback()
            writer.join(60)
            pytest.fail(f"the day waited for the lock past the busy timeout ({outcome})")
    holder.dispose()
    assert len(outcome) == 1 and isinstance(outcome[0], StoreBusyError), outcome
    assert "the store is busy" in str(outcome[0])
    assert store.day_rows(e, DAY) == {"deliveries": [], "flightpath": []}
    e.dispose()


NEXT = DAY + dt.timedelta(1)
DAYS = [*TWO, Order("0000000c", NEXT, "s2400003", "a.b.e", ("y",))]


def fix(orders: list, no: str, **changed) -> list:
    """``orders`` with order ``no`` changed (a corrected line of the CSV)."""
    return [Order(**{**o.__dict__, **changed}) if o.order_no == no else o for o in orders]


def counts(engine) -> dict[str, int]:
    with engine.connect() as c:
        return {t: c.execute(sa.text(f"select count(*) from {t}")).scalar_one()
                for t in store.TABLES}


@pytest.mark.parametrize("given, words", [
    (fix(DAYS, "0000000b", deliver_to="a.b.x"),
     "2024-01-01: the orders differ from the stored ones (order 0000000b: deliver_to "
     "'a.b.x', stored 'a.b.d')"),
    (fix(DAYS, "0000000a", items=("x", "z")),
     "(order 0000000a: items ['x', 'z'], stored ['x'])"),
    (fix(DAYS, "0000000c", customer="s2400009"),
     "2024-01-02: the orders differ from the stored ones (order 0000000c: customer"),
    (DAYS[1:], "2024-01-01: the orders differ from the stored ones (order 0000000a is "
               "stored but not given)"),
    (fix(DAYS, "0000000a", date=NEXT), "2024-01-01: the orders differ from the stored "
     "ones (order 0000000a: date 2024-01-02, stored 2024-01-01) (and 1 more day(s))"),
])
def test_a_corrected_order_is_refused_naming_the_day(engine, given, words):
    # the stored (wrong) orders were kept and used, and nothing said so
    store.import_orders(engine, DAYS)
    store.write_day(engine, DAY, run_row(3), [], moves(3))
    before = counts(engine)
    with pytest.raises(store.OrdersChangedError, match=re.escape(words)):
        store.import_orders(engine, given)
    assert counts(engine) == before
    assert [o for v in store.orders_between(engine, DAY, NEXT).values() for o in v] == DAYS


def test_replace_stores_the_corrected_days_whole(engine):
    store.import_orders(engine, DAYS)
    for day in (DAY, NEXT):
        store.write_day(engine, day, run_row(2), [], moves(2))
    given = [*fix(DAYS, "0000000b", deliver_to="a.b.x"),
             Order("0000000d", NEXT, "s2400004", "a.b.f", ("z",))]
    assert store.import_orders(engine, given, replace=True) == (3, 1, (DAY,))
    assert store.orders_between(engine, DAY, NEXT) == {DAY: given[:2], NEXT: given[2:]}
    # the day replaced lost what was flown from its old orders; the other kept its own
    assert store.day_rows(engine, DAY) == {"deliveries": [], "flightpath": []}
    assert len(store.day_rows(engine, NEXT)["flightpath"]) == 2
    assert store.import_orders(engine, given) == (0, 4, ())  # now as stored
    moved = fix(given, "0000000a", date=NEXT)
    assert store.import_orders(engine, moved, replace=True) == (4, 0, (DAY, NEXT))
    assert store.orders_between(engine, DAY, NEXT) == {
        DAY: [moved[1]], NEXT: sorted([moved[0], *moved[2:]], key=lambda o: o.order_no)}


def test_replace_keeps_the_other_orders_of_a_day_the_file_does_not_give(engine):
    """A file of the next day only, whose order moved there from DAY: DAY is no day of
    the file, so it keeps its other order; only what was flown from its old orders goes."""
    store.import_orders(engine, DAYS)
    store.write_day(engine, DAY, run_row(2), [], moves(2))
    moved = Order("0000000a", NEXT, "s2400001", "a.b.c", ("x",))
    with pytest.raises(store.OrdersChangedError):
        store.import_orders(engine, [moved, DAYS[2]])
    assert store.import_orders(engine, [moved, DAYS[2]], replace=True) == (2, 1, (DAY, NEXT))
    assert store.orders_between(engine, DAY, NEXT) == {DAY: [TWO[1]], NEXT: [moved, DAYS[2]]}
    assert store.day_rows(engine, DAY) == {"deliveries": [], "flightpath": []}


def test_new_orders_of_a_stored_day_are_added(engine):
    # orders that arrived since the last import: nothing stored differs
    store.import_orders(engine, DAYS[:1])
    assert store.import_orders(engine, DAYS) == (2, 1, ())


def test_a_replace_that_fails_leaves_the_days_as_they_were(engine):
    store.import_orders(engine, DAYS)
    store.write_day(engine, DAY, run_row(3), [], moves(3))
    before = counts(engine)

    def fail(conn, cursor, statement, *args):
        if statement.lstrip().upper().startswith("INSERT INTO ORDER_DETAILS"):
            raise RuntimeError("killed")

    sa.event.listen(engine, "before_cursor_execute", fail)
    with pytest.raises(RuntimeError, match="killed"):
        store.import_orders(engine, fix(DAYS, "0000000b", deliver_to="a.b.x"), replace=True)
    sa.event.remove(engine, "before_cursor_execute", fail)
    assert counts(engine) == before
    assert store.orders_between(engine, DAY, DAY)[DAY] == TWO
