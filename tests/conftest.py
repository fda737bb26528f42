"""Shared test fixtures: where the outside reference data lives.

Tests that read the reference data (MovingAI maps, the FCND city, the ILP 2021 delivery
data) carry the ``shared_data`` marker. It lives in ``../shared/data`` beside the
repository, or wherever ``$SKYROUTE_SHARED_DATA`` points; when that directory is missing,
every marked test is skipped with one reason, and the rest of the suite still runs.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import subprocess
import sys
import uuid
from pathlib import Path

import pytest
import sqlalchemy as sa

ROOT = Path(__file__).resolve().parents[1]
SHARED = Path(os.environ.get("SKYROUTE_SHARED_DATA") or ROOT.parent / "shared" / "data")
MOVINGAI = SHARED / "movingai"


def movingai_pairs() -> list[tuple[Path, Path]]:
    """The 18 (map, scen) pairs of the shared movingai/ folder (see its SOURCES.md); none
    when the shared data is missing (the tests using them are then skipped)."""
    if not MOVINGAI.is_dir():
        return []
    from skyroute.bench.grid import find_pairs

    return find_pairs(MOVINGAI)


_TERMINAL = ("COLUMNS", "LINES")


@pytest.hookimpl(optionalhook=True)
def pytest_configure_node(node):
    """pytest-xdist (controller): send each worker the terminal size variables as the run
    was started with. A library loaded here has by then set COLUMNS=80 and LINES=24 in
    the C environment, which the workers inherit into their ``os.environ``; the CLI's
    tables would then be cut to 80 columns in every worker and every process it starts."""
    node.workerinput["skyroute_terminal"] = {k: os.environ.get(k) for k in _TERMINAL}


def pytest_configure(config):
    sent = getattr(config, "workerinput", {}).get("skyroute_terminal")
    for k, v in (sent or {}).items():  # an xdist worker: the run's own values
        if v is None:
            os.environ.pop(k, None)
        else:
            os.environ[k] = v


def pytest_collection_modifyitems(config, items):
    if SHARED.is_dir():
        return
    skip = pytest.mark.skip(reason=f"shared_data: no reference data at {SHARED} "
                                   "(put it in ../shared/data or set SKYROUTE_SHARED_DATA)")
    for item in items:
        if item.get_closest_marker("shared_data"):
            item.add_marker(skip, append=False)  # before parametrize's 'empty parameter set'


@pytest.fixture(scope="session", autouse=True)
def _early_processes(request, tmp_path_factory, leg_cache):
    """The separate processes that the selected tests marked ``early_process(*args)`` check,
    all started (``python *args``, each in a folder of its own) when the run begins: they
    then run on the second core beside the in-process tests, not after them. Each test
    waits for its own through the ``early_process`` fixture. Their environment is
    ``os.environ`` as Python holds it: a library loaded in this process sets COLUMNS=80
    and LINES=24 in the C environment (not in ``os.environ``), which a child inherits
    by default and which the CLI's tables honour. Under pytest-xdist a worker does not
    know which tests it will be sent, so there each process starts when its test asks
    for it (the other worker is the second core then)."""
    started = {}
    xdist_worker = hasattr(request.config, "workerinput")
    for item in () if xdist_worker else request.session.items:
        mark = item.get_closest_marker("early_process")
        if mark is not None and item.get_closest_marker("skip") is None:
            cwd = tmp_path_factory.mktemp("process")
            started[item.nodeid] = cwd, _start(mark.args, cwd)
    yield started
    for _, proc in started.values():  # a test that never ran (-x, Ctrl-C): stop its process
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def _start(args, cwd: Path) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, *args], cwd=cwd, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=dict(os.environ))


@pytest.fixture
def early_process(request, _early_processes, tmp_path_factory):
    """(exit code, stdout, stderr, folder) of this test's ``early_process``, once it ends."""
    if request.node.nodeid not in _early_processes:  # an xdist worker: start it now
        cwd = tmp_path_factory.mktemp("process")
        mark = request.node.get_closest_marker("early_process")
        _early_processes[request.node.nodeid] = cwd, _start(mark.args, cwd)
    cwd, proc = _early_processes[request.node.nodeid]
    out, err = proc.communicate(timeout=300)
    return proc.returncode, out, err, cwd


@pytest.fixture(scope="session")
def _flown_days() -> dict:
    return {}


def _site_key(source) -> object:
    """What a site is loaded from: the bytes of every file of a data folder's website/
    (two folders with the same files are the same site), or the server's URL."""
    root = getattr(source, "root", None)
    if root is None:
        return source
    web = Path(root) / "website"
    digest = hashlib.sha256()
    for p in sorted(web.rglob("*")):
        if p.is_file():
            digest.update(str(p.relative_to(web)).encode() + b"\0" + p.read_bytes() + b"\0")
    return digest.hexdigest()


@pytest.fixture
def fly_once(monkeypatch, _flown_days):
    """``plan_day`` flying each delivery day once per session, put in place of the one
    ``skyroute deliver`` calls: a day of the same site (see ``_site_key``), date, orders,
    method and battery is the first flight of it. It reaches the days run in the test's
    own process (``--jobs 1``); spawned ``--jobs N`` workers and Dask workers fly theirs
    (skyroute.jobs.deliver calls ``plan_day`` there). For tests of what is done
    with a day (tables, files, stores, worker processes); every stored move of the
    synthetic and ILP days is checked independently (tests/delivery/flight_check.py) by
    the synthetic range and the ILP marker-day tests. Run alone, a test flies its days.
    Not for tests that change the planner's inputs by other means (e.g. a patched leg
    table): the key would not see it."""
    from skyroute.jobs import deliver

    plan_day = caching_plan_day(_flown_days)
    monkeypatch.setattr(deliver, "plan_day", plan_day)
    return plan_day


def caching_plan_day(flown: dict):
    """``plan_day`` that flies each day once into ``flown`` (see ``fly_once``); for
    fixtures wider than a test, which patch it in (at ``skyroute.jobs.deliver``) with
    ``pytest.MonkeyPatch.context()``."""
    from skyroute.delivery import day

    def plan_day(site, date, orders, *, method="milp", battery=day.BATTERY):
        key = (_site_key(site.source), date, tuple(orders), method, battery)
        if key not in flown:
            flown[key] = day.plan_day(site, date, orders, method=method, battery=battery)
        return flown[key]

    return plan_day


@pytest.fixture(scope="session", autouse=True)
def leg_cache(tmp_path_factory):
    """Delivery leg tables go to one temporary cache for the whole run, not ~/.cache."""
    path = tmp_path_factory.mktemp("skyroute-cache")
    old = os.environ.get("SKYROUTE_CACHE")
    os.environ["SKYROUTE_CACHE"] = str(path)
    yield path
    if old is None:
        os.environ.pop("SKYROUTE_CACHE", None)
    else:
        os.environ["SKYROUTE_CACHE"] = old


PG = os.environ.get("SKYROUTE_TEST_PG", "postgresql+psycopg://postgres@127.0.0.1:5432/test")


@contextlib.contextmanager
def new_pg_database(prefix: str, *, encoding: str | None = None):
    """The URL of a new, empty PostgreSQL database named ``prefix`` and a random suffix,
    dropped on leaving (a skip when no server answers, unless $CI is set); ``encoding``:
    made in that encoding (from template0, C locale) instead of the server's default."""
    base = sa.engine.make_url(PG)
    name = f"{prefix}_{uuid.uuid4().hex[:12]}"
    made_in = (f" encoding '{encoding}' template template0 lc_collate 'C' lc_ctype 'C'"
               if encoding else "")
    try:
        admin = sa.create_engine(base, isolation_level="AUTOCOMMIT")
        with admin.connect() as c:
            c.execute(sa.text(f"create database {name}{made_in}"))
    except sa.exc.OperationalError:
        if os.environ.get("CI"):
            raise
        pytest.skip("no PostgreSQL server")
    try:
        yield base.set(database=name).render_as_string(hide_password=False)
    finally:
        with admin.connect() as c:
            c.execute(sa.text(f"drop database if exists {name} with (force)"))
        admin.dispose()


@pytest.fixture
def fresh_pg():
    """The URL of a new, empty PostgreSQL database of this test's own, dropped after it."""
    with new_pg_database("skyroute_new") as url:
        yield url
