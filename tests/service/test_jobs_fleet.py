"""Jobs and fleet runs through the service. The routers are checked here against a
stand-in for ``skyroute.jobs`` (its interface: ``runner.submit/get``,
``executor.open_executor``, ``store.get_fleet_run/open_fleet_file/list_fleet_runs``) so
they are tested whether or not that package is installed; the tests marked ``needs_jobs``
run the real jobs and skip while it is missing."""

from __future__ import annotations

import datetime as dt
import importlib.util
import itertools
import json
import sys
import time
import types
import uuid

import pytest

from tests.fleet.test_nofly import ringed
from tests.jobs.conftest import part_reads, slow_days
from tests.service.conftest import AUTH, DAY, EXAMPLE, make_client
from tests.service.test_app import assert_problem

HAVE_JOBS = importlib.util.find_spec("skyroute.jobs") is not None
needs_jobs = pytest.mark.skipif(not HAVE_JOBS, reason="skyroute.jobs is not installed "
                                "(branch jobs not merged yet)")


# -- a stand-in for skyroute.jobs -------------------------------------------------------
FILES = ("events_jsonl", "tracks_csv", "packages_csv", "fleet_geojson")  # the store's
ALIASES = {"events": "events_jsonl", "tracks": "tracks_csv", "packages": "packages_csv",
           "geojson": "fleet_geojson"}  # the same files under the brief's keys


class FakeJobs:
    def __init__(self):
        self.jobs: dict[str, dict] = {}
        self.runs: dict[str, dict] = {}
        self.submitted: list[tuple[str, dict]] = []
        self.reads: list[tuple[str, tuple]] = []  # (run id, the files read) per lookup

    def get_fleet_run(self, engine, run_id, *, files=True):
        """As the store's: the run's head and only the files asked for."""
        wanted = FILES if files is True else () if files is False else tuple(files)
        assert set(wanted) <= set(FILES), wanted
        self.reads.append((run_id, wanted))
        run = self.runs.get(run_id)
        if run is None:
            return None
        return {k: v for k, v in run.items()
                if ALIASES.get(k, k) not in FILES or ALIASES.get(k, k) in wanted}

    def open_fleet_file(self, engine, run_id, name):
        """As the store's: the run's file ``name`` to stream (its size, then its bytes in
        parts of FakeFile.PART); None for an unknown run."""
        assert name in FILES, name
        self.reads.append((run_id, (name,)))
        run = self.runs.get(run_id)
        if run is None:
            return None
        data = next((v for k, v in run.items() if ALIASES.get(k, k) == name), b"")
        return FakeFile(data.encode() if isinstance(data, str) else bytes(data))

    def install(self, monkeypatch):
        pkg = types.ModuleType("skyroute.jobs")
        runner = types.ModuleType("skyroute.jobs.runner")
        store = types.ModuleType("skyroute.jobs.store")
        executor = types.ModuleType("skyroute.jobs.executor")
        runner.submit = self.submit
        runner.submit_once = self.submit_once
        runner.live_twin = self.live_twin
        runner.get = lambda engine, i: self.jobs.get(i)
        store.get_fleet_run = self.get_fleet_run
        store.open_fleet_file = self.open_fleet_file
        store.RunChangedError = type("RunChangedError", (Exception,), {})
        store.list_fleet_runs = lambda engine, *, offset=0, limit=100: \
            list(self.runs.values())[offset:offset + limit]
        executor.open_executor = lambda kind="local", address=None, workers=None: \
            types.SimpleNamespace(kind=kind, close=lambda: None)
        for name, mod in (("skyroute.jobs", pkg), ("skyroute.jobs.runner", runner),
                          ("skyroute.jobs.store", store), ("skyroute.jobs.executor", executor)):
            monkeypatch.setitem(sys.modules, name, mod)
        pkg.runner, pkg.store, pkg.executor = runner, store, executor
        return self

    def submit(self, engine, kind, params, *, executor):
        from skyroute.errors import OptionError

        if params.get("hours") == 23.5:
            raise OptionError("hours=23.5 is refused by the runner", param="hours")
        i = str(uuid.uuid4())
        self.submitted.append((kind, params))
        self.jobs[i] = {"id": i, "kind": kind, "state": "queued", "progress": 0.0,
                        "result": None, "error": None}
        return i


    def live_twin(self, engine, kind, params):
        return next((i for i, (k, p) in zip(self.jobs, self.submitted, strict=True)
                     if (k, p) == (kind, params)
                     and self.jobs[i]["state"] in ("queued", "running")), None)

    def submit_once(self, engine, kind, params, *, executor):
        twin = self.live_twin(engine, kind, params)
        if twin is not None:
            return twin, False
        return self.submit(engine, kind, params, executor=executor), True


class FakeFile:
    PART = 1000
    created = None  # as the stand-in's runs say (they have no "created")

    def __init__(self, data: bytes):
        self.data, self.size = data, len(data)

    def lines(self, offset: int, limit: int) -> tuple[list[bytes], int]:
        lines = self.data.splitlines()
        return lines[offset:offset + limit], len(lines)

    def __iter__(self):
        for a in range(0, max(1, self.size), self.PART):
            yield self.data[a:a + self.PART]


@pytest.fixture
def fake(monkeypatch):
    return FakeJobs().install(monkeypatch)


@pytest.fixture
def site_client(tmp_path):
    with make_client(db_url=f"sqlite:///{tmp_path / 'j.db'}", data_dir=EXAMPLE,
                     job_queue=2) as c:
        yield c


def test_deliver_job_is_202_with_an_id(site_client, fake):
    r = site_client.post("/jobs/deliver", json={"date": DAY}, headers=AUTH)
    assert r.status_code == 202 and r.headers["location"] == f"/jobs/{r.json()['id']}"
    assert fake.submitted[-1] == ("deliver", {"from": DAY, "to": DAY, "method": "milp",
                                              "replace": False, "data": str(EXAMPLE)})
    r = site_client.post("/jobs/deliver", json={"from": "2024-01-01", "to": "2024-01-02",
                                                "method": "greedy"}, headers=AUTH)
    assert r.status_code == 202
    assert fake.submitted[-1][1]["from"] == "2024-01-01"
    job = site_client.get(f"/jobs/{r.json()['id']}").json()
    assert job == {"id": r.json()["id"], "kind": "deliver", "state": "queued",
                   "progress": 0.0, "result": None, "error": None}


def test_a_failed_jobs_error_is_shown_in_full_only_with_the_token(site_client, fake,
                                                                  tmp_path):
    """``GET /jobs/{id}`` is open, and a failed job's error may name the server's data
    folder or store (a site without its menus, another site's orders ``stored for ...
    in sqlite:////srv/...``): it was shown to anyone who had a job's id. Without the
    token (or with a wrong one) the error now says only that the job failed."""
    where = f"{tmp_path}/site/website/menus/menus.json: no such file"
    fake.jobs["j-failed"] = {"id": "j-failed", "kind": "deliver", "state": "failed",
                             "progress": 0.0, "result": None, "error": where}
    fake.jobs["j-done"] = {"id": "j-done", "kind": "fleet", "state": "done",
                           "progress": 1.0, "result": {"fleet_run": "r"}, "error": None}
    for headers in ({}, {"Authorization": "Bearer wrong-token-0123456789"},
                    {"Authorization": AUTH["Authorization"].replace("Bearer", "Basic")}):
        job = site_client.get("/jobs/j-failed", headers=headers)
        assert job.status_code == 200, job.text
        assert job.json()["state"] == "failed" and job.json()["error"] == (
            "the job failed; its error is shown with the server's token (Authorization: "
            "Bearer TOKEN)")
        assert str(tmp_path) not in job.text
    assert site_client.get("/jobs/j-failed", headers=AUTH).json()["error"] == where
    for headers in ({}, AUTH):  # a job that did not fail: as it was, either way
        assert site_client.get("/jobs/j-done", headers=headers).json() == {
            "id": "j-done", "kind": "fleet", "state": "done", "progress": 1.0,
            "result": {"fleet_run": "r"}, "error": None}


def test_a_deliver_job_can_replace_a_kept_flight(site_client, fake):
    # a day whose every order is invalid keeps its stored flight and fails the job; the
    # job had no way to store it anyway, as the CLI's --replace does
    r = site_client.post("/jobs/deliver", json={"date": DAY, "replace": True}, headers=AUTH)
    assert r.status_code == 202, r.text
    assert fake.submitted[-1] == ("deliver", {"from": DAY, "to": DAY, "method": "milp",
                                              "replace": True, "data": str(EXAMPLE)})
    for bad in ("yes", 1, None):  # a switch is true or false, as the plan route's are
        assert_problem(site_client.post("/jobs/deliver", json={"date": DAY, "replace": bad},
                                        headers=AUTH), 422, "replace")


def test_the_queue_limit_is_429_until_a_job_ends(site_client, fake):
    # three different jobs (the same one again would be answered with the first's id)
    days = [{"date": DAY}, {"date": "2024-01-01"}, {"date": "2024-01-02"}]
    ids = [site_client.post("/jobs/deliver", json=d, headers=AUTH).json()["id"]
           for d in days[:2]]
    r = site_client.post("/jobs/deliver", json=days[2], headers=AUTH)
    assert_problem(r, 429, words="2 jobs are queued or running")
    assert r.headers["retry-after"] == "10"
    fake.jobs[ids[0]].update(state="done", progress=1.0, result={"days": 1})
    assert site_client.post("/jobs/deliver", json=days[2],
                            headers=AUTH).status_code == 202
    done = site_client.get(f"/jobs/{ids[0]}").json()
    assert done["state"] == "done" and done["result"] == {"days": 1}
    assert len(fake.submitted) == 3


def test_the_same_deliver_job_again_is_the_live_one(site_client, fake):
    """The same days with the same method and replace, submitted while the first is
    queued or running (a client retrying a POST that timed out, a double click), were
    a second job flying the days again: they are answered 200 with the live job's id
    and queue nothing, even with the queue full. Other options, or after it ended, are a
    new job."""
    first = site_client.post("/jobs/deliver", json={"date": DAY}, headers=AUTH)
    assert first.status_code == 202
    job_id = first.json()["id"]
    again = site_client.post("/jobs/deliver", json={"date": DAY, "method": "milp",
                                                     "replace": False}, headers=AUTH)
    assert again.status_code == 200 and again.json() == {"id": job_id}
    assert again.headers["location"] == f"/jobs/{job_id}"
    assert len(fake.submitted) == 1
    # a range of the one day is the same job; another method is another
    same = site_client.post("/jobs/deliver", json={"from": DAY, "to": DAY}, headers=AUTH)
    assert same.status_code == 200 and same.json() == {"id": job_id}
    other = site_client.post("/jobs/deliver", json={"date": DAY, "method": "greedy"},
                             headers=AUTH)
    assert other.status_code == 202 and other.json()["id"] != job_id
    # the queue (2) is full now: the same job is still its id, a new one a 429
    fake.jobs[job_id]["state"] = "running"
    full = site_client.post("/jobs/deliver", json={"date": DAY}, headers=AUTH)
    assert full.status_code == 200 and full.json() == {"id": job_id}
    assert_problem(site_client.post("/jobs/deliver", json={"date": "2024-01-01"},
                                    headers=AUTH), 429)
    fake.jobs[job_id].update(state="done", progress=1.0)
    after = site_client.post("/jobs/deliver", json={"date": DAY}, headers=AUTH)
    assert after.status_code == 202 and after.json()["id"] != job_id
    assert len(fake.submitted) == 3


def test_fleet_job_params(site_client, fake):
    r = site_client.post("/jobs/fleet", json={"preset": "seed-3x3", "hours": 0.5, "seed": 4,
                                              "scheduler": "optimal", "rate": 30},
                         headers=AUTH)
    assert r.status_code == 202
    assert fake.submitted[-1] == ("fleet", {"preset": "seed-3x3", "hours": 0.5, "seed": 4,
                                            "scheduler": "optimal", "rate_per_hour": 30.0})
    from skyroute.fleet.scenario import preset

    scenario = preset("seed-3x3").model_dump(mode="json")
    r = site_client.post("/jobs/fleet", json={"scenario": scenario, "airspace": "shared"},
                         headers=AUTH)
    assert r.status_code == 202
    _, params = fake.submitted[-1]
    assert params["scenario"] == scenario and params["airspace"] == "shared"


def _seed3() -> dict:
    from skyroute.fleet.scenario import preset

    return preset("seed-3x3").model_dump(mode="json")


SEED3 = _seed3()
RINGED = ringed()


@pytest.mark.parametrize("path, body, field, words", [
    ("/jobs/deliver", {}, "body", "give date, or both from and to"),
    ("/jobs/deliver", {"date": DAY, "from": DAY}, "body", "give date, or both"),
    ("/jobs/deliver", {"from": "2024-01-02", "to": "2024-01-01"}, "body", "is before from"),
    ("/jobs/deliver", {"date": "2024-02-30"}, "date", "date"),
    ("/jobs/deliver", {"date": 0}, "date", "YYYY-MM-DD"),
    ("/jobs/deliver", {"from": 1704240000, "to": DAY}, "from", "YYYY-MM-DD"),
    ("/jobs/deliver", {"date": DAY, "method": "magic"}, "method", "'milp'"),
    ("/jobs/deliver", {"date": DAY, "jobs": 4}, "jobs", "Extra inputs"),
    # the field's Python name is no key of the API (the schema already refused it)
    ("/jobs/deliver", {"from_": "2024-01-01", "to": DAY}, "from_", "Extra inputs"),
    ("/jobs/fleet", {}, "body", "exactly one of preset and scenario"),
    ("/jobs/fleet", {"preset": "seed-2x2"}, "preset", "'seed-3x3'"),
    ("/jobs/fleet", {"preset": "seed-3x3", "hours": 0}, "hours", "greater than 0"),
    ("/jobs/fleet", {"preset": "seed-3x3", "hours": 100}, "hours", "less than or equal"),
    ("/jobs/fleet", {"preset": "seed-3x3", "seed": -1}, "seed", "greater than or equal"),
    ("/jobs/fleet", {"preset": "seed-3x3", "scheduler": "fifo"}, "scheduler", "'seed'"),
    ("/jobs/fleet", {"scenario": {"drones": 2}}, "scenario.airports", "Field required"),
    ("/jobs/fleet", {"scenario": {**SEED3, "packages": {"csv": "/etc/passwd"}}},
     "scenario.packages.csv", "cannot name a file"),
    ("/jobs/fleet", {"preset": "seed-3x3", "hours": 23.5}, "hours", "refused by the runner"),
    ("/jobs/fleet", {"scenario": {**SEED3, "packages": {"rate_per_hour": 1e9}}},
     "scenario.packages.rate_per_hour", "1e+09 packages per hour is over the limit of 100,000"),
    ("/jobs/fleet", {"scenario": {**SEED3, "drones": 10**7}}, "scenario.drones",
     "1e+07 drones is over the limit of 1,000"),
    ("/jobs/fleet", {"scenario": {**SEED3, "airports": SEED3["airports"] * 34}},
     "scenario.airports", "102 airports is over the limit of 100"),
    # refused before a zone is read: 1000 zones took about 10 s here, 125,000 minutes
    ("/jobs/fleet", {"scenario": {**SEED3, "no_fly_zones": [
        {"points": [[0, 0], [0, 9], [9, 0]]}] * 1001}},
     "scenario.no_fly_zones", "1,001 zones is over the limit of 1,000"),
    ("/jobs/fleet", {"scenario": {**SEED3, "no_fly_zones": [
        {"points": [[0, 0], [0, 9], [9, 0]] * 33_334}]}},
     "scenario.no_fly_zones", "100,002 corners in all is over the limit of 100,000"),
    ("/jobs/fleet", {"scenario": {**SEED3, "airports": [
        {**SEED3["airports"][0], "east": 1e12}, *SEED3["airports"][1:]]}},
     "scenario.airports[0].east", "1e+12 m from home is over the limit of 100,000 m"),
    # the work a run multiplies to (skyroute.fleet.limits, as on the command line)
    ("/jobs/fleet", {"preset": "seed-3x3", "rate": 1e5, "hours": 2}, "rate",
     "would spawn about 2e+05 packages (limit 100,000)"),
    ("/jobs/fleet", {"scenario": {**SEED3, "packages": {"rate_per_hour": 1e4}}, "hours": 24},
     "hours", "(the scenario's packages.rate_per_hour) for 24 h would spawn about 2.4e+05"),
    ("/jobs/fleet", {"scenario": {**SEED3, "drones": 1000}, "hours": 24}, "hours",
     "1000 drones for 24 h would store up to 8.6e+07 track rows"),
    ("/jobs/fleet", {"preset": "seed-3x3", "rate": 1e9, "hours": 0.01}, "rate",
     "less than or equal"),
    ("/jobs/fleet", {"scenario": {**SEED3, "packages": "x"}}, "scenario.packages",
     "expected a mapping"),
    # a ring of no-fly zones round an airport: refused now, not when it is first flown
    ("/jobs/fleet", {"scenario": RINGED}, "scenario.no_fly_zones",
     "no cruise can join airports C and A: zones 'west', 'east' close a ring round C"),
    ("/jobs/fleet", {"scenario": {**SEED3, "packages": [1]}}, "scenario.packages",
     "expected a mapping"),
    # pydantic's own message named the Python class ("instance of PostedScenario")
    ("/jobs/fleet", {"scenario": 5}, "scenario", "expected a mapping of scenario fields, not 5"),
    ("/jobs/fleet", {"scenario": {**SEED3, "drone": [1]}}, "scenario.drone",
     "expected a mapping of fields, not [1]"),
    # ran on SQLite; on PostgreSQL the run was flown, then not stored: a raw SQL error
    ("/jobs/fleet", {"scenario": {**SEED3, "name": "Zoë\x00"}}, "scenario.name",
     "'Zoë\\x00' holds a NUL character, which a PostgreSQL store cannot keep"),
    ("/jobs/fleet", {"scenario": {**SEED3, "airports": [
        {**SEED3["airports"][0], "id": "A\x00"}, *SEED3["airports"][1:]]}},
     "scenario.airports[0].id", "holds a NUL character"),
])
def test_bad_job_input_is_422(site_client, fake, path, body, field, words):
    assert_problem(site_client.post(path, json=body, headers=AUTH), 422, field, words)


@pytest.mark.parametrize("scenario, field, words", [
    # accepted, flown, then not stored (SQLite and PostgreSQL alike): the job failed with
    # a raw UnicodeEncodeError after the whole run
    ({**SEED3, "name": "x\ud800"}, "scenario.name",
     "scenario.name: 'x\\ud800' holds U+D800, half of a UTF-16 surrogate pair"),
    # a key that is no text: the whole message was the field
    ({**SEED3, "\ud800": 1}, "scenario", "scenario: Input should be a valid string"),
])
def test_a_lone_surrogate_in_a_scenario_is_422(site_client, fake, scenario, field, words):
    body = json.dumps({"scenario": scenario, "hours": 0.5}).encode()  # the escape kept
    r = site_client.post("/jobs/fleet", content=body,
                         headers={**AUTH, "Content-Type": "application/json"})
    assert_problem(r, 422, field, words)
    assert fake.submitted == []


def test_unknown_job_is_404(site_client, fake):
    assert_problem(site_client.get("/jobs/nope"), 404, words="no job 'nope'")


def test_a_deliver_job_needs_a_site(client, fake):
    assert_problem(client.post("/jobs/deliver", json={"date": DAY}, headers=AUTH), 404,
                   words="no delivery site")


def test_without_the_jobs_package_jobs_are_503(site_client, monkeypatch):
    # skipped whenever skyroute.jobs was installed (always, since it was merged): the
    # package is now hidden from import instead (None in sys.modules: ImportError)
    for name in [m for m in sys.modules if m == "skyroute.jobs" or
                 m.startswith("skyroute.jobs.")]:
        monkeypatch.setitem(sys.modules, name, None)
    monkeypatch.setitem(sys.modules, "skyroute.jobs", None)
    assert_problem(site_client.post("/jobs/deliver", json={"date": DAY}, headers=AUTH), 503,
                   words="skyroute.jobs is missing")
    assert_problem(site_client.get("/jobs/x"), 503)
    assert_problem(site_client.get("/fleet/runs"), 503)


# -- fleet runs against the stand-in store, filled by a real run ------------------------
@pytest.fixture(scope="module")
def small_run():
    from skyroute.fleet.report import report
    from skyroute.fleet.scenario import preset
    from skyroute.fleet.simulate import run
    from skyroute.io.fleet_out import events_jsonl, fleet_geojson, tracks_csv

    sim = run(preset("seed-3x3"), hours=0.25, seed=1)
    return {"sim": sim, "report": report(sim), "events": events_jsonl(sim),
            "tracks": tracks_csv(sim).decode(), "geojson": fleet_geojson(sim)}


@pytest.mark.parametrize("layout", ["brief", "store"])
def test_fleet_run_pages_and_files(client, fake, small_run, layout):
    rid = "run-1"
    if layout == "brief":  # the keys of the interface the service was built against
        from skyroute.fleet.scenario import preset

        fake.runs[rid] = {"id": rid, "scenario": preset("seed-3x3").model_dump(mode="json"),
                          "params": {"preset": "seed-3x3", "hours": 0.25, "seed": 1},
                          "report": small_run["report"], "events": small_run["events"],
                          "tracks": small_run["tracks"]}
    else:  # the jobs branch's store: files under their names, the scenario by name
        fake.runs[rid] = {"id": rid, "scenario": "seed-3x3",
                          "params": {"preset": "seed-3x3", "hours": 0.25, "seed": 1},
                          "report": small_run["report"],
                          "events_jsonl": small_run["events"],
                          "tracks_csv": small_run["tracks"].encode(),
                          "fleet_geojson": json.dumps(small_run["geojson"])}
    runs = client.get("/fleet/runs").json()
    assert runs[0]["id"] == rid and runs[0]["scenario"] == "seed-3x3"
    lines = small_run["events"].splitlines()
    doc = client.get(f"/fleet/runs/{rid}?offset=3&limit=5").json()
    assert doc["events"] == [json.loads(x) for x in lines[3:8]]
    assert doc["events_total"] == len(lines) and doc["report"] == json.loads(
        json.dumps(small_run["report"]))
    assert doc["scenario"]["name"] == "seed-3x3" and len(doc["scenario"]["airports"]) == 3
    assert client.get(f"/fleet/runs/{rid}").json()["events"] == \
        [json.loads(x) for x in lines[:1000]]
    ev = client.get(doc["files"]["events.jsonl"])
    assert ev.text == small_run["events"] and ev.headers["content-type"].startswith(
        "application/x-ndjson")
    tr = client.get(doc["files"]["tracks.csv"])
    assert tr.text == small_run["tracks"] and tr.headers["content-type"].startswith(
        "text/csv")
    gj = client.get(doc["files"]["fleet.geojson"]).json()
    kinds = [f["properties"]["kind"] for f in gj["features"]]
    assert kinds.count("airport") == 3 and kinds.count("gate") == 6
    flights = [f for f in small_run["geojson"]["features"]
               if f["properties"]["kind"] in ("delivery", "reposition")]
    assert len(gj["features"]) == len(small_run["geojson"]["features"])
    if layout == "store":
        assert gj == small_run["geojson"]
    else:  # rebuilt from the tracks: one airborne stretch per flight
        assert sum(k == "track" for k in kinds) == len(flights)


@pytest.mark.parametrize("path, reads", [
    ("", [("events_jsonl",), (), ("packages_csv",)]),  # a page; packages.csv listed?
    ("?offset=5&limit=2", [("events_jsonl",), (), ("packages_csv",)]),
    ("/events.jsonl", [("events_jsonl",)]),
    ("/tracks.csv", [("tracks_csv",)]),
    ("/packages.csv", [("packages_csv",)]),
    ("/fleet.geojson", [("fleet_geojson",)]),
])
def test_each_run_route_reads_only_what_it_answers(client, fake, small_run, path, reads):
    """The viewer pages a run's events again and again: the summary and each file read
    their own columns, never the tracks (a big run's are about 150 MB)."""
    fake.runs["r"] = {"id": "r", "scenario": "seed-3x3", "params": {"preset": "seed-3x3"},
                      "report": small_run["report"], "events_jsonl": small_run["events"],
                      "tracks_csv": small_run["tracks"].encode(), "packages_csv": "id\n",
                      "fleet_geojson": json.dumps(small_run["geojson"])}
    assert client.get(f"/fleet/runs/r{path}").status_code == 200
    assert [files for _, files in fake.reads] == reads


def test_a_geojson_rebuilt_from_the_tracks_reads_them_only_then(client, fake, small_run):
    fake.runs["r"] = {"id": "r", "scenario": "seed-3x3", "params": {"preset": "seed-3x3"},
                      "report": {}, "tracks": small_run["tracks"]}
    gj = client.get("/fleet/runs/r/fleet.geojson").json()
    assert [f["properties"]["kind"] for f in gj["features"]].count("airport") == 3
    assert [files for _, files in fake.reads] == [("fleet_geojson",), ("tracks_csv",)]


@pytest.mark.parametrize("query, field", [("offset=-1", "offset"), ("limit=0", "limit"),
                                          ("limit=100000", "limit")])
def test_fleet_run_paging_is_checked(client, fake, query, field):
    fake.runs["r"] = {"id": "r", "scenario": "seed-3x3", "params": {}, "report": {},
                      "events_jsonl": ""}
    assert_problem(client.get(f"/fleet/runs/r?{query}"), 422, field)


@pytest.mark.parametrize("suffix", ["", "/events.jsonl", "/tracks.csv", "/fleet.geojson"])
def test_unknown_fleet_run_is_404(client, fake, suffix):
    assert_problem(client.get(f"/fleet/runs/nope{suffix}"), 404, words="no fleet run")


# -- the real jobs -------------------------------------------------------------------
def wait(c, job_id: str, timeout: float = 600) -> dict:
    end = time.monotonic() + timeout
    seen = []
    while time.monotonic() < end:
        job = c.get(f"/jobs/{job_id}").json()
        seen.append((job["state"], job["progress"]))
        assert 0 <= job["progress"] <= 1
        if job["state"] in ("done", "failed"):
            job["seen"] = seen
            return job
        time.sleep(0.05)
    raise AssertionError(f"job {job_id} did not end in {timeout} s")


@needs_jobs
@pytest.mark.slow
def test_a_delivery_job_stores_the_clis_rows(tmp_path, lunch):
    import datetime as dt

    from skyroute.delivery.days import open_store
    from skyroute.delivery.orders import read_csv_orders
    from skyroute.delivery.store import day_rows, import_orders, init

    db = f"sqlite:///{tmp_path / 'job.db'}"
    eng = open_store(db)
    init(eng)
    import_orders(eng, read_csv_orders(EXAMPLE))
    with make_client(db_url=db, data_dir=EXAMPLE, job_workers=1) as c:
        r = c.post("/jobs/deliver", json={"date": DAY}, headers=AUTH)
        assert r.status_code == 202, r.text
        job = wait(c, r.json()["id"])
        assert job["state"] == "done", job
        assert c.get("/days").json()[0]["date"] == DAY
    cli = open_store(lunch[0])
    d = dt.date.fromisoformat(DAY)
    assert day_rows(eng, d) == day_rows(cli, d)


@needs_jobs
@pytest.mark.slow
def test_a_range_job_shows_its_progress_while_running(tmp_path, monkeypatch):
    from skyroute.delivery.days import open_store
    from skyroute.delivery.orders import read_csv_orders
    from skyroute.delivery.store import import_orders, order_dates

    db = f"sqlite:///{tmp_path / 'range.db'}"
    eng = open_store(db)
    import_orders(eng, read_csv_orders(EXAMPLE))
    dates = order_dates(eng)
    first, last = min(dates).isoformat(), max(dates).isoformat()
    slow_days(monkeypatch)
    with make_client(db_url=db, data_dir=EXAMPLE, job_workers=1) as c:
        r = c.post("/jobs/deliver", json={"from": first, "to": last}, headers=AUTH)
        assert r.status_code == 202, r.text
        job = wait(c, r.json()["id"])
        assert job["state"] == "done" and job["progress"] == 1, job
        states = [s for s, _ in job["seen"]]
        assert "running" in states and "queued" not in states[states.index("running"):]
        # some days stored while the job still ran, seen through GET /jobs/{id}
        assert any(s == "running" and 0 < p < 1 for s, p in job["seen"]), job["seen"]
        assert {d["date"] for d in c.get("/days").json()} >= {d.isoformat() for d in dates}


@needs_jobs
@pytest.mark.parametrize("db", ["sqlite", "postgresql"])
def test_the_same_deliver_job_is_found_in_the_store(tmp_path, request, monkeypatch, db):
    """The live twin is looked for in the store: a job another server (sharing it) runs
    is answered too; one a stopped server left is failed as an orphan, not answered."""
    import sqlalchemy as sa

    from skyroute.jobs import deliver, runner, store
    from skyroute.service.resources import make_engine

    url = (f"sqlite:///{tmp_path / 'twin.db'}" if db == "sqlite"
           else request.getfixturevalue("fresh_pg"))
    params = deliver.check_params({"from": DAY, "to": DAY, "method": "milp",
                                   "replace": False, "data": str(EXAMPLE)})
    eng = make_engine(url)
    store.beat(eng, "other-server:1:a")
    live = store.create_job(eng, "deliver", params, owner="other-server:1:a")
    dead = store.create_job(eng, "deliver", {**params, "method": "greedy"},
                            owner="stopped-server:2:b")  # never beat: an orphan
    with eng.begin() as c:  # the stopped server's last beat, long ago
        c.execute(sa.text("INSERT INTO servers (id, started, heartbeat) VALUES "
                          "('stopped-server:2:b', :t, :t)"),
                  {"t": store.db_now(c) - dt.timedelta(hours=1)})
    # the jobs queued here are never run (a lane of their own that takes one and stops)
    queued = []
    monkeypatch.setattr(runner, "_work", lambda jobs: queued.append(jobs.get()))
    for name in ("_lanes", "_stores"):
        monkeypatch.setattr(runner, name, {})
    monkeypatch.setattr(runner, "_pending", runner._pending)
    with make_client(db_url=url, data_dir=EXAMPLE) as c:
        r = c.post("/jobs/deliver", json={"date": DAY}, headers=AUTH)
        assert r.status_code == 200 and r.json() == {"id": live}, r.text
        r = c.post("/jobs/deliver", json={"date": DAY, "method": "greedy"}, headers=AUTH)
        assert r.status_code == 202 and r.json()["id"] not in (live, dead), r.text
        assert store.get_job(eng, dead)["state"] == "failed"
        again = c.post("/jobs/deliver", json={"date": DAY, "method": "greedy"},
                       headers=AUTH)
        assert again.status_code == 200 and again.json() == r.json()
    with eng.connect() as c:
        assert c.execute(sa.text("SELECT count(*) FROM jobs")).scalar_one() == 3
    eng.dispose()


@needs_jobs
def test_fleet_runs_say_when_each_was_stored(tmp_path):
    """Two runs of the same preset, hours and seed differ in the list by when they were
    stored (the viewer's run list showed them as the same line)."""
    from skyroute.jobs import store
    from skyroute.service.resources import make_engine

    db = f"sqlite:///{tmp_path / 'runs.db'}"
    eng = make_engine(db)
    for _ in range(2):
        store.save_fleet_run(eng, scenario="seed-3x3", params={"preset": "seed-3x3",
                             "hours": 0.25, "seed": 1}, report={}, events_jsonl="",
                             tracks_csv=b"", packages_csv="", fleet_geojson="")
    want = {r["id"]: r["created"] for r in store.list_fleet_runs(eng)}
    eng.dispose()
    with make_client(db_url=db) as c:
        runs = c.get("/fleet/runs").json()
    assert {r["id"]: r["created"] for r in runs} == want
    assert all(want.values()) and len(set(want.values())) == 2


@needs_jobs
def test_the_real_store_selects_the_tracks_only_for_tracks_csv(tmp_path, small_run):
    """Every SELECT a run's routes send, seen by SQLAlchemy: only GET tracks.csv names
    the tracks (the file's name is a parameter of the query)."""
    import sqlalchemy as sa

    from skyroute.jobs import store
    from skyroute.service.resources import make_engine

    db = f"sqlite:///{tmp_path / 'runs.db'}"
    eng = make_engine(db)
    rid = store.save_fleet_run(eng, scenario="seed-3x3", params={"preset": "seed-3x3"},
                               report=small_run["report"], events_jsonl=small_run["events"],
                               tracks_csv=small_run["tracks"].encode(), packages_csv="id\n",
                               fleet_geojson=json.dumps(small_run["geojson"]))
    eng.dispose()
    seen: list[str] = []

    def record(conn, cursor, statement, parameters, *args):
        if statement.lstrip().upper().startswith("SELECT") and "fleet_runs" in statement:
            seen.append(f"{statement} {parameters!r}")

    sa.event.listen(sa.engine.Engine, "before_cursor_execute", record)
    try:
        with make_client(db_url=db) as c:
            for path in ("", "?offset=3&limit=2", "/events.jsonl", "/packages.csv",
                         "/fleet.geojson", "/tracks.csv"):
                del seen[:]
                r = c.get(f"/fleet/runs/{rid}{path}")
                assert r.status_code == 200, r.text
                assert seen, path
                assert any("tracks_csv" in q for q in seen) == (path == "/tracks.csv"), \
                    (path, seen)
            assert r.text == small_run["tracks"]
    finally:
        sa.event.remove(sa.engine.Engine, "before_cursor_execute", record)


@needs_jobs
@pytest.mark.parametrize("db", ["sqlite", "postgresql"])
def test_a_runs_files_are_streamed_as_stored(tmp_path, request, db):
    """Each file route sends the stored bytes part by part (no piece larger than a
    stored part, the length up front, the file's name and type), a file of a size not
    a multiple of the part and an empty one alike; an unknown run is a 404 problem."""
    import numpy as np

    from skyroute.jobs import store
    from skyroute.service.resources import make_engine

    url = (f"sqlite:///{tmp_path / 'runs.db'}" if db == "sqlite"
           else request.getfixturevalue("fresh_pg"))
    eng = make_engine(url)
    part = 1 << 20  # store.PART_BYTES, checked at the end
    rng = np.random.default_rng(3)
    tracks = rng.integers(0, 256, 2 * part + 12345, dtype=np.uint8).tobytes()
    events = '{"t":0,"kind":"spawn","at":"Café"}\n' * (part // 20)  # over a part
    files = {"events_jsonl": events, "tracks_csv": tracks, "packages_csv": "id\n0\n",
             "fleet_geojson": '{"type":"FeatureCollection","features":[]}'}
    full = store.save_fleet_run(eng, scenario="seed-3x3", params={}, report={}, **files)
    empty = store.save_fleet_run(eng, scenario="seed-3x3", params={}, report={},
                                 events_jsonl="", tracks_csv=b"", packages_csv="",
                                 fleet_geojson="{}")
    eng.dispose()
    want = {"tracks.csv": (tracks, "text/csv; charset=utf-8"),
            "events.jsonl": (events.encode(), "application/x-ndjson"),
            "packages.csv": (b"id\n0\n", "text/csv; charset=utf-8"),
            "fleet.geojson": (files["fleet_geojson"].encode(), "application/geo+json")}
    with make_client(db_url=url) as c:
        for name, (body, media) in [*want.items(), ("tracks.csv", (b"", None)),
                                    ("events.jsonl", (b"", None))]:
            rid = full if body else empty
            with c.stream("GET", f"/fleet/runs/{rid}/{name}") as r:
                pieces = list(r.iter_raw())
            assert r.status_code == 200, name
            assert b"".join(pieces) == body, name
            sizes = [len(p) for p in pieces]
            assert max(sizes, default=0) <= part, (name, sizes)
            assert r.headers["content-length"] == str(len(body))
            assert r.headers["content-disposition"] == f'attachment; filename="{name}"'
            if media:
                assert r.headers["content-type"] == media
        assert sizes in ([], [0])
        assert_problem(c.get(f"/fleet/runs/{empty}/packages.csv"), 404,
                       words="has no packages.csv")
        for name in want:
            assert_problem(c.get(f"/fleet/runs/nope/{name}"), 404, words="no fleet run 'nope'")
    assert part == store.PART_BYTES


def _store_big_run(url: str) -> tuple[str, dict]:
    """A run whose files span parts: 2.1 MB of tracks, 2.5 MB of events (lines that
    cross the parts' boundaries); its id and files as saved."""
    import numpy as np

    from skyroute.jobs import store
    from skyroute.service.resources import make_engine

    eng = make_engine(url)
    part = store.PART_BYTES
    tracks = np.random.default_rng(3).integers(0, 256, 2 * part + 12345,
                                               dtype=np.uint8).tobytes()
    events, i = [], 0
    while sum(map(len, events)) < 2.5 * part:
        events.append(json.dumps({"t": i / 8, "kind": "spawn", "at": "Café " * (i % 40),
                                  "drone": i % 997}, separators=(",", ":")) + "\n")
        i += 1
    files = {"events_jsonl": "".join(events), "tracks_csv": tracks,
             "packages_csv": "id\n0\n", "fleet_geojson": '{"type":"FeatureCollection"}'}
    run = store.save_fleet_run(eng, scenario="seed-3x3", params={}, report={}, **files)
    eng.dispose()
    return run, files


@needs_jobs
@pytest.mark.parametrize("db", ["sqlite", "postgresql"])
def test_a_head_of_a_runs_file_reads_no_part(tmp_path, request, db):
    """HEAD on each file route is GET's status and headers (the length among them) from
    the file's size alone: not one part read, where GET reads each part once."""
    url = (f"sqlite:///{tmp_path / 'runs.db'}" if db == "sqlite"
           else request.getfixturevalue("fresh_pg"))
    run, files = _store_big_run(url)
    with make_client(db_url=url) as c:
        for name, key in [("tracks.csv", "tracks_csv"), ("events.jsonl", "events_jsonl"),
                          ("packages.csv", "packages_csv"),
                          ("fleet.geojson", "fleet_geojson")]:
            size = len(files[key] if isinstance(files[key], bytes)
                       else files[key].encode())
            with part_reads() as reads:
                head = c.head(f"/fleet/runs/{run}/{name}")
            assert head.status_code == 200 and head.content == b"", name
            assert reads == [], name
            with part_reads() as reads:
                get = c.get(f"/fleet/runs/{run}/{name}")
            assert reads == list(range(-(-size // (1 << 20)))), name
            assert len(get.content) == size == int(head.headers["content-length"])
            assert ({k: v for k, v in head.headers.items() if k != "server-timing"}
                    == {k: v for k, v in get.headers.items() if k != "server-timing"})
        nope = c.head(f"/fleet/runs/nope/{name}")
        assert nope.status_code == 404 and nope.content == b""
        assert nope.headers["content-type"] == "application/problem+json"


@needs_jobs
@pytest.mark.parametrize("db", ["sqlite", "postgresql"])
def test_an_id_with_a_nul_character_is_an_unknown_job_or_run(tmp_path, request, db):
    """A job or run id holding NUL (``%00`` in the path) is a 404 on either store: no id
    holds one, and PostgreSQL refuses the character in any text value, which was a 500
    of every job and run route (schemathesis puts no NUL in a path)."""
    url = (f"sqlite:///{tmp_path / 'runs.db'}" if db == "sqlite"
           else request.getfixturevalue("fresh_pg"))
    from skyroute.jobs import store
    from skyroute.service.resources import make_engine

    eng = make_engine(url)
    run = store.save_fleet_run(eng, scenario="seed-3x3", params={}, report={},
                               events_jsonl="", tracks_csv=b"", packages_csv="id\n0\n",
                               fleet_geojson="{}")
    eng.dispose()
    with make_client(db_url=url) as c:
        assert c.get(f"/fleet/runs/{run}/packages.csv").status_code == 200
        assert_problem(c.get("/jobs/a%00b"), 404, words="no job")
        for suffix in ("", "/events.jsonl", "/tracks.csv", "/fleet.geojson",
                       "/packages.csv"):
            assert_problem(c.get(f"/fleet/runs/{run}%00{suffix}"), 404,
                           words="no fleet run")


@needs_jobs
@pytest.mark.parametrize("db", ["sqlite", "postgresql"])
def test_a_page_of_events_reads_the_parts_it_lies_in(tmp_path, request, db):
    """GET /fleet/runs/{id} pages events.jsonl from its stored parts: a page from the
    start reads the first part alone, a page across a part boundary the two parts, a
    page past the end none; each page is what splitlines() of the whole file gave (the
    same events and events_total), lines crossing parts included."""
    url = (f"sqlite:///{tmp_path / 'runs.db'}" if db == "sqlite"
           else request.getfixturevalue("fresh_pg"))
    run, files = _store_big_run(url)
    data = files["events_jsonl"].encode()
    lines = files["events_jsonl"].splitlines()
    ends = list(itertools.accumulate(len(x.encode()) + 1 for x in lines))  # after "\n"
    part = 1 << 20
    # the first line that crosses each boundary between parts
    crossing = [next(i for i, e in enumerate(ends) if e > b) for b in (part, 2 * part)]
    assert all(ends[i] - len(lines[i].encode()) - 1 < b
               for i, b in zip(crossing, (part, 2 * part), strict=True))
    with make_client(db_url=url) as c:
        for offset, limit, want_reads in [
                (0, 1000, [0]), (0, 1, [0]), (5, 3, [0]),
                (crossing[0] - 1, 3, [0, 1]), (crossing[0], 1, [0, 1]),
                (crossing[0] + 1, 10, [1]), (crossing[1], 2, [1, 2]),
                (len(lines) - 3, 10, [2]), (len(lines), 10, []),
                (0, 10_000, [0, 1, 2])]:
            with part_reads() as reads:
                r = c.get(f"/fleet/runs/{run}?offset={offset}&limit={limit}")
            assert r.status_code == 200, r.text
            doc = r.json()
            assert doc["events"] == [json.loads(x) for x in lines[offset:offset + limit]]
            assert doc["events_total"] == len(lines)
            assert reads == want_reads, (offset, limit, reads)
        assert "packages.csv" in doc["files"]
    assert len(data) > 2 * part


@needs_jobs
@pytest.mark.parametrize("times", [1, 3])
def test_a_page_of_a_run_replaced_while_read_is_of_one_version(tmp_path, monkeypatch,
                                                              times):
    """A run saved again under its id while a page of its events is read: the page and
    the report are read again, both of the new run (never the old run's events under
    the new report); a run replaced on every read is a 409 problem."""
    from skyroute.jobs import store
    from skyroute.service.resources import make_engine

    url = f"sqlite:///{tmp_path / 'runs.db'}"
    eng = make_engine(url)
    args = dict(scenario="seed-3x3", params={}, tracks_csv=b"", packages_csv="",
                fleet_geojson="", run_id="r")
    store.save_fleet_run(eng, report={"v": 0}, events_jsonl='{"v":0}\n', **args)
    versions = iter(range(1, times + 1))
    lines = store.StoredFile.lines

    def replaced_meanwhile(self, offset, limit):
        page = lines(self, offset, limit)
        v = next(versions, None)
        if v is not None:
            store.save_fleet_run(eng, report={"v": v}, events_jsonl=f'{{"v":{v}}}\n',
                                 **args)
        return page

    monkeypatch.setattr(store.StoredFile, "lines", replaced_meanwhile)
    with make_client(db_url=url) as c:
        r = c.get("/fleet/runs/r")
        if times == 3:
            assert_problem(r, 409, words="fleet run 'r' was replaced again and again")
        else:
            assert r.status_code == 200, r.text
            assert (r.json()["report"], r.json()["events"]) == ({"v": 1}, [{"v": 1}])
    eng.dispose()


@needs_jobs
@pytest.mark.slow
def test_a_fleet_job_stores_a_run(tmp_path, small_run):
    with make_client(db_url=f"sqlite:///{tmp_path / 'f.db'}", job_workers=1) as c:
        r = c.post("/jobs/fleet", json={"preset": "seed-3x3", "hours": 0.25, "seed": 1},
                   headers=AUTH)
        assert r.status_code == 202, r.text
        job = wait(c, r.json()["id"])
        assert job["state"] == "done", job
        runs = c.get("/fleet/runs").json()
        assert len(runs) == 1
        doc = c.get(f"/fleet/runs/{runs[0]['id']}").json()
        assert c.get(doc["files"]["events.jsonl"]).text == small_run["events"]
        assert c.get(doc["files"]["tracks.csv"]).text == small_run["tracks"]
        assert c.get(doc["files"]["fleet.geojson"]).status_code == 200


@needs_jobs
@pytest.mark.parametrize("db", ["sqlite", "postgresql"])
def test_fleet_runs_are_listed_a_page_at_a_time(tmp_path, request, db):
    """GET /fleet/runs pages the runs, newest first (?offset&limit, a Link to the next
    page while there is one); the pages together are every run once. Before, it answered
    the newest 100 and ignored offset and limit: run 101 could not be listed."""
    from skyroute.jobs import store
    from skyroute.service.resources import make_engine

    url = (f"sqlite:///{tmp_path / 'runs.db'}" if db == "sqlite"
           else request.getfixturevalue("fresh_pg"))
    eng = make_engine(url)
    saved = [store.save_fleet_run(eng, scenario="seed-3x3", params={"n": i}, report={},
                                  events_jsonl="", tracks_csv=b"", packages_csv="",
                                  fleet_geojson="{}") for i in range(102)]
    eng.dispose()
    with make_client(db_url=url) as c:
        first = c.get("/fleet/runs")
        assert first.status_code == 200 and len(first.json()) == 100
        assert first.headers["link"] == '</fleet/runs?offset=100&limit=100>; rel="next"'
        rest = c.get("/fleet/runs?offset=100&limit=100")
        assert len(rest.json()) == 2 and "link" not in rest.headers
        newest_first = [r["id"] for r in first.json() + rest.json()]
        assert sorted(newest_first) == sorted(saved)
        assert newest_first == [r["id"] for r in
                                sorted(first.json() + rest.json(),
                                       key=lambda r: r["created"], reverse=True)]
        pages, url_ = [], "/fleet/runs?limit=30"
        while url_:
            r = c.get(url_)
            pages.append([x["id"] for x in r.json()])
            link = r.headers.get("link")
            url_ = link.split(">")[0].removeprefix("<") if link else None
        assert [len(p) for p in pages] == [30, 30, 30, 12]
        assert list(itertools.chain(*pages)) == newest_first
        assert c.get("/fleet/runs?offset=500").json() == []
        for query, field in [("limit=0", "limit"), ("limit=1001", "limit"),
                             ("offset=-1", "offset"), (f"offset={2**63}", "offset"),
                             ("limit=ten", "limit")]:
            assert_problem(c.get(f"/fleet/runs?{query}"), 422, field)



@needs_jobs
def test_a_run_under_a_millisecond_is_refused_before_it_is_queued(tmp_path):
    """The runner's own check (the stand-in runner above skips it): hours=1e-7 was
    accepted (202), queued, and failed in its run, "hours=1e-07 is 0.00036 s, under the
    millisecond a run's times are written to"."""
    with make_client(db_url=f"sqlite:///{tmp_path / 'h.db'}", job_workers=1) as c:
        r = c.post("/jobs/fleet", json={"preset": "seed-3x3", "hours": 1e-7}, headers=AUTH)
        assert_problem(r, 422, "hours", "hours=1e-07 is 0.00036 s, under the millisecond")
