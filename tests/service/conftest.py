"""Service fixtures: an app over an empty store, and one over a store holding the
examples/lunch day 2024-01-03 flown by the CLI (once per session, sharing the day flown
by the CLI tests through ``caching_plan_day``)."""

from __future__ import annotations

import contextlib
import io
import json
import sys
import warnings

import pytest

from tests.conftest import ROOT, caching_plan_day

EXAMPLE = ROOT / "examples" / "lunch"
DAY = "2024-01-03"
TOKEN = "test-token-0123456789"
AUTH = {"Authorization": f"Bearer {TOKEN}"}

with warnings.catch_warnings():  # starlette would rather see httpx2; httpx still works
    warnings.simplefilter("ignore")
    from fastapi.testclient import TestClient


def make_client(**settings) -> TestClient:
    """A client of an app with ``settings``; the app skips the warm-up (tests/service/
    test_warm.py tests it) unless ``warm=True``: about 0.1 s an app, hundreds of apps."""
    from skyroute.service.app import create_app
    from skyroute.service.settings import Settings

    settings.setdefault("warm", False)
    return TestClient(create_app(Settings(token=TOKEN, **settings)))


@pytest.fixture
def client(tmp_path):
    """An app over an empty SQLite store, without a delivery site."""
    with make_client(db_url=f"sqlite:///{tmp_path / 'empty.db'}") as c:
        yield c


def cli(*args: str) -> tuple[int, str]:
    """``skyroute *args`` in this process: (exit code, stdout)."""
    from skyroute.cli.app import main

    out = io.StringIO()
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(sys, "argv", ["skyroute", *args])
        with contextlib.redirect_stdout(out), pytest.raises(SystemExit) as exit_info:
            main()
    return exit_info.value.code, out.getvalue()


@pytest.fixture(scope="session")
def lunch(tmp_path_factory, _flown_days):
    """(db URL, the CLI's report of DAY, its GeoJSON file's text, the out folder): the
    day flown by ``skyroute deliver DAY --data examples/lunch``, plus 2024-02-01 (a day
    without orders)."""
    from skyroute.jobs import deliver

    folder = tmp_path_factory.mktemp("lunch")
    db = f"sqlite:///{folder / 'lunch.db'}"
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(deliver, "plan_day", caching_plan_day(_flown_days))
        code, out = cli("deliver", DAY, "--data", str(EXAMPLE), "--db", db, "--out",
                        str(folder), "--no-plot", "--json")
        assert code == 0, out
        report = json.loads(out)
        code, _ = cli("deliver", "2024-02-01", "--data", str(EXAMPLE), "--db", db, "--out",
                      str(folder), "--no-plot", "--json")
        assert code == 0
    geojson = (folder / "drone-03-01-2024.geojson").read_text()
    return db, report, geojson, folder


@pytest.fixture
def day_client(lunch):
    """An app over the lunch store with the examples/lunch site."""
    with make_client(db_url=lunch[0], data_dir=EXAMPLE) as c:
        yield c
