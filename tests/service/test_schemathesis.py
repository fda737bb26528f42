"""Schemathesis against /openapi.json: every operation with a bounded number of
generated requests (``MAX_EXAMPLES``), authorised, over the lunch store and site; no
answer is a 5xx and every answer matches its documented status, media type and schema.
Jobs go to the stand-in for ``skyroute.jobs`` (nothing is really flown or simulated)."""

from __future__ import annotations

import shutil
import tempfile
import warnings
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    import schemathesis
    from schemathesis.checks import not_a_server_error
    from schemathesis.specs.openapi.checks import (
        content_type_conformance,
        response_schema_conformance,
        status_code_conformance,
    )

from skyroute.service.app import create_app
from skyroute.service.settings import Settings
from tests.service.conftest import AUTH, EXAMPLE, TOKEN
from tests.service.test_jobs_fleet import FakeJobs

MAX_EXAMPLES = 20
CHECKS = [not_a_server_error, status_code_conformance, content_type_conformance,
          response_schema_conformance]


# The app is made at import, which opens nothing (the store opens on the first request):
# the fixture below puts the lunch store in place first.
STORE = Path(tempfile.mkdtemp(prefix="skyroute-schemathesis-")) / "lunch.db"
APP = create_app(Settings(token=TOKEN, db_url=f"sqlite:///{STORE}", data_dir=EXAMPLE,
                          max_expansions=20_000))
schema = schemathesis.openapi.from_asgi("/openapi.json", APP)


@pytest.fixture(autouse=True)
def _store_and_jobs(lunch, monkeypatch):
    if not STORE.exists():
        shutil.copy(lunch[0].removeprefix("sqlite:///"), STORE)
    fake = FakeJobs().install(monkeypatch)
    fake.runs["run-1"] = {"id": "run-1", "scenario": "seed-3x3",
                          "params": {"preset": "seed-3x3"}, "report": {"delivered": 0},
                          "events_jsonl": '{"t":1.0,"kind":"spawn"}\n',
                          "tracks_csv": b"t,drone,north,east,alt,phase\n"}


@schema.parametrize()
@settings(max_examples=MAX_EXAMPLES, deadline=None, derandomize=True,
          suppress_health_check=list(HealthCheck))
def test_api_conforms_to_its_schema(case):
    case.call_and_validate(headers=AUTH, checks=CHECKS)
