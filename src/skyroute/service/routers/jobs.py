"""Long work as jobs: ``POST /jobs/deliver`` (a day or a range of stored orders),
``POST /jobs/fleet`` (a fleet run) -> 202 ``{"id"}`` (a delivery job the same as one
queued or running -> 200 and that job's id); ``GET /jobs/{id}`` -> its state, progress,
result or error (open to all, as every read; a failed job's error in full only with the
token, as it may name the server's data folder or store).

The jobs themselves (tables, Dask or local processes) live in :mod:`skyroute.jobs`,
imported on first use; without it these endpoints answer 503. A server holds at most
``job_queue`` jobs queued or running; one more is a 429 with ``Retry-After``.
"""

from __future__ import annotations

import logging
import threading
from typing import Annotated, Any, Literal

from fastapi import APIRouter, Depends, Path, Request
from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from skyroute.delivery.limits import MAX_DAYS
from skyroute.errors import SEED_MAX, SkyrouteError, StoreBusyError, StoreSchemaError
from skyroute.fleet.limits import (
    MAX_PACKAGES,
    MAX_RATE,
    MAX_TRACK_ROWS,
    expected_packages,
    track_rows,
)
from skyroute.service import fleet_scenario
from skyroute.service.alternatives import exactly_one
from skyroute.service.auth import has_token, require_token
from skyroute.service.dates import IsoDate
from skyroute.service.fleet_scenario import PostedScenario
from skyroute.service.json_response import FiniteJSONResponse
from skyroute.service.paths import url_path
from skyroute.service.problems import Problem, responses
from skyroute.service.resources import Resources, ResourcesDep

log = logging.getLogger("skyroute.service")

router = APIRouter(tags=["jobs"])
MAX_HOURS = 24.0  # this server's own limit: a job holds a worker (fleet.limits allows more)
# the size of a run (rate, drones, airports, packages, track rows) is limited where the
# CLI's is: skyroute.fleet.limits, in the scenario model and the runner's checks
_SUBMIT = threading.Lock()


class DeliverJob(BaseModel):
    """``{"date": D}`` for one day or ``{"from": D, "to": D}`` for a range, over the
    orders already in the store (the site is the server's --data or --source). Give
    ``date``, or both ``from`` and ``to`` (null counts as not given; the schema states
    it as ``oneOf``)."""

    # by its alias alone: "from_" is no field of the API (the schema forbids it too)
    model_config = ConfigDict(extra="forbid",
                              json_schema_extra=exactly_one("date", ("from", "to")))

    date: IsoDate | None = Field(None, description="One day. Give date, or both from "
                                 "and to.")
    from_: IsoDate | None = Field(None, alias="from", description="The range's first day "
                                  "(with to, without date).")
    to: IsoDate | None = Field(None, description="The range's last day, not before from, "
                               f"at most {MAX_DAYS} days in all (with from, without date).")
    method: Literal["milp", "greedy"] = "milp"
    # strict, as the plan route's switches: true or false, never "yes" or 1
    replace: bool = Field(False, strict=True, description="Store a day whose every order "
                          "is invalid over its stored flight that delivered (otherwise that "
                          "flight is kept and the job fails naming the day), as the CLI's "
                          "--replace.")

    @model_validator(mode="after")
    def _days(self) -> DeliverJob:
        ranged = self.from_ is not None or self.to is not None
        if (self.date is not None) == ranged or (ranged and None in (self.from_, self.to)):
            raise ValueError("give date, or both from and to")
        if ranged and self.to < self.from_:
            raise ValueError(f"to {self.to} is before from {self.from_}")
        if ranged and (self.to - self.from_).days >= MAX_DAYS:
            raise ValueError(f"at most {MAX_DAYS} days in one job")
        return self


class FleetJob(BaseModel):
    """A fleet run: a preset's or a posted scenario's drones for ``hours``. Give exactly
    one of ``preset`` and ``scenario`` (null counts as not given; the schema states it
    as ``oneOf``)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False,
                              json_schema_extra=exactly_one("preset", "scenario"))

    preset: Literal["seed-3x3", "seed-9x9", "seed-18x9"] | None = None
    scenario: PostedScenario | None = Field(None, description="A scenario: the fields of "
                                           "`skyroute fleet scenario`'s YAML, checked as "
                                           "`skyroute fleet simulate` checks a file.")
    hours: float = Field(1.0, gt=0, le=MAX_HOURS, description="Simulated hours; with the "
                         f"rate at most {MAX_PACKAGES:,g} packages in all, and with the "
                         f"drones at most {MAX_TRACK_ROWS:,.0f} track rows (one a second).")
    seed: int = Field(0, ge=0, le=SEED_MAX)
    scheduler: Literal["seed", "optimal"] = "seed"
    airspace: Literal["layers", "shared"] | None = None
    rate: float | None = Field(None, gt=0, le=MAX_RATE, description="Packages per hour "
                               "(default: the scenario's); rate x hours at most "
                               f"{MAX_PACKAGES:,g}.")

    @field_validator("scenario", mode="wrap")
    @classmethod
    def _scenario(cls, value, handler):
        return fleet_scenario.validate(value, handler)

    @model_validator(mode="after")
    def _one(self) -> FleetJob:
        if (self.preset is None) == (self.scenario is None):
            raise ValueError("give exactly one of preset and scenario")
        return self


class JobId(BaseModel):
    id: str


# a failed job's error to a reader without the token: the error itself may name the
# server's data folder, its store's file or URL (a bad site, another site's orders)
HIDDEN_ERROR = ("the job failed; its error is shown with the server's token "
                "(Authorization: Bearer TOKEN)")


class JobState(BaseModel):
    id: str
    kind: str | None = None
    state: Literal["queued", "running", "done", "failed"]
    progress: float = Field(ge=0, le=1)
    result: Any = None
    error: str | None = Field(None, description="A failed job's error, one line; without "
                              "the token (`Authorization: Bearer TOKEN`) only that it "
                              "failed, as the error may name the server's files.")


def _jobs():
    try:
        from skyroute.jobs import runner
    except ImportError:
        raise Problem(503, "jobs are not available in this installation (skyroute.jobs is "
                      "missing)", kind="jobs-unavailable") from None
    return runner


EXECUTOR_RETRY_SECONDS = 30  # an unreachable Dask scheduler's Retry-After


def _executor(res: Resources):
    """The jobs' executor, or a 503 when it cannot be opened (``serve --dask`` naming a
    scheduler that has gone, or never answered): the server's condition, not the
    request's. It was a 422 "invalid input" with ``field: address``, a field no request
    has, naming the scheduler's address to the caller; the reason goes to the log."""
    try:
        return res.executor()
    except SkyrouteError as exc:
        log.warning("jobs: the executor cannot be opened: %s", str(exc).splitlines()[0])
        raise Problem(503, "jobs cannot start: the server cannot reach its Dask cluster; "
                      "the server's log says why; try again later",
                      kind="executor-unavailable",
                      headers={"Retry-After": str(EXECUTOR_RETRY_SECONDS)}) from None


def _submit(res: Resources, request: Request, kind: str, params: dict, *,
            once: bool = False) -> FiniteJSONResponse:
    """Queue the job: 202 ``{"id"}``. With ``once``, a job of ``kind`` with the same
    parameters already queued or running (this server's or another's on the store) is
    answered instead: 200 with its id, nothing queued, even when the queue is full."""
    runner = _jobs()
    eng = res.engine()
    with _SUBMIT:
        active = 0
        for i in list(res.job_ids):
            job = runner.get(eng, i)
            if job is None or job["state"] in ("done", "failed"):
                res.job_ids.remove(i)
            else:
                active += 1
        try:
            if active >= res.settings.job_queue:
                job_id = runner.live_twin(eng, kind, params) if once else None
                if job_id is None:
                    raise Problem(429, f"{active} jobs are queued or running, this "
                                  "server's limit; try again later",
                                  headers={"Retry-After": "10"})
                new = False
            elif once:
                job_id, new = runner.submit_once(eng, kind, params, executor=_executor(res))
            else:
                job_id, new = runner.submit(eng, kind, params, executor=_executor(res)), True
        except (StoreBusyError, StoreSchemaError):
            # the server's condition, not the request's: a 503 naming no URL
            # (problems._busy, _schema); the 422 of str(exc) named the store's file
            raise
        except SkyrouteError as exc:
            raise Problem(422, str(exc), field=exc.param if isinstance(exc.param, str)
                          else None) from None
        if new:
            res.job_ids.append(job_id)
    return FiniteJSONResponse({"id": job_id}, status_code=202 if new else 200,
                              headers={"Location": url_path(request, f"/jobs/{job_id}")})


@router.post("/jobs/deliver", status_code=202, response_model=JobId,
             dependencies=[Depends(require_token)],
             responses={200: {"model": JobId, "description": "The same job (the same "
                              "days, method and replace) is already queued or running: "
                              "its id; nothing new is queued"},
                        **responses(401, 403, 404, 413, 422, 429, 503)},
             summary="Fly a day or a range of days as a job")
def post_deliver(body: DeliverJob, res: ResourcesDep, request: Request):
    """202 and the new job's id; 200 and the id of the job already doing it when the
    same days are queued or running with the same method and replace (a retried or
    double-clicked submission flies them once: follow that job)."""
    res.site()  # 404 without a site: the job would fail on every day
    s = res.settings
    first, last = (body.date, body.date) if body.date else (body.from_, body.to)
    params = {"from": first.isoformat(), "to": last.isoformat(), "method": body.method,
              "replace": body.replace,
              **({"data": str(s.data_dir)} if s.data_dir is not None else
                 {"source": s.source_url})}
    return _submit(res, request, "deliver", params, once=True)


@router.post("/jobs/fleet", status_code=202, response_model=JobId,
             dependencies=[Depends(require_token)],
             responses=responses(401, 403, 413, 422, 429, 503),
             summary="Run a fleet simulation as a job")
def post_fleet(body: FleetJob, res: ResourcesDep, request: Request):
    from skyroute.fleet.airborne import check_flights
    from skyroute.fleet.scenario import Scenario, preset

    if body.scenario is not None:
        scenario: Scenario = body.scenario  # read and checked as the request was read
        try:
            check_flights(scenario, "scenario")
        except SkyrouteError as exc:
            text = str(exc).removeprefix("scenario: ")
            # "drone.rollout: ..." names its field; a message naming none is the
            # scenario's (a key that is no text: the whole message was the field)
            head, named, _ = text.partition(": ")
            raise Problem(422, f"scenario.{text}" if named else f"scenario: {text}",
                          field=f"scenario.{head}" if named else "scenario") from None
    else:
        scenario = preset(body.preset)
    _check_work(scenario, body)
    params = {**({"preset": body.preset} if body.preset else
                 {"scenario": scenario.model_dump(mode="json")}),
              "hours": body.hours, "seed": body.seed, "scheduler": body.scheduler,
              **({"airspace": body.airspace} if body.airspace else {}),
              **({"rate_per_hour": body.rate} if body.rate is not None else {})}
    return _submit(res, request, "fleet", params)


def _check_work(scenario, body: FleetJob) -> None:
    """The packages the run would spawn (rate x hours) and the track rows it would store
    (drones x seconds, one a second) within :mod:`skyroute.fleet.limits`: a 422 naming
    ``rate`` or ``hours`` (the runner checks the same, in its parameters' names)."""
    rate = scenario.packages.rate_per_hour if body.rate is None else body.rate
    n = expected_packages(rate, body.hours)
    if n > MAX_PACKAGES:
        field = "rate" if body.rate is not None else "hours"
        where = "rate" if body.rate is not None else "the scenario's packages.rate_per_hour"
        raise Problem(422, f"{field}: {rate:g} packages/h ({where}) for {body.hours:g} h "
                      f"would spawn about {n:.2g} packages (limit {MAX_PACKAGES:,g}); lower "
                      "rate or hours", field=field)
    rows = track_rows(scenario.drones, body.hours, 1.0)
    if rows > MAX_TRACK_ROWS:
        raise Problem(422, f"hours: {scenario.drones} drones for {body.hours:g} h would store "
                      f"up to {rows:.2g} track rows, one a second (limit "
                      f"{MAX_TRACK_ROWS:,.0f}); lower hours or drones", field="hours")


@router.get("/jobs/{job_id}", response_model=JobState, responses=responses(404, 503),
            summary="A job's state, progress and result")
def get_job(job_id: Annotated[str, Path(max_length=100)],
            res: ResourcesDep, request: Request) -> dict:
    """Open to all; a failed job's ``error`` in full only with the token (it may name
    the server's data folder or store), else a line saying it failed."""
    runner = _jobs()
    job = runner.get(res.engine(), job_id)
    if job is None:
        raise Problem(404, f"no job {job_id!r}", kind="unknown-job")
    if job.get("kind") == "deliver" and job["state"] == "done":
        _forget_days(res, job.get("result") or {})
    error = job.get("error")
    if error is not None and not has_token(request):
        error = HIDDEN_ERROR
    return {"id": job_id, "kind": job.get("kind"), "state": job["state"],
            "progress": float(job.get("progress") or 0.0), "result": job.get("result"),
            "error": error}


def _forget_days(res, result: dict) -> None:
    """Drop this process's copies of the flight files of the days a finished deliver job
    stored: a file is served from memory for ``fresh_seconds``, and the viewer, loading
    a day the moment its job is seen done, was shown the flight the job had replaced."""
    import datetime as dt

    try:
        first = dt.date.fromisoformat(result["from"])
        last = dt.date.fromisoformat(result["to"])
    except (KeyError, TypeError, ValueError):
        return
    for k in range((last - first).days + 1):
        res.cache.pop(f"flightpath:{first + dt.timedelta(days=k)}", None)
