"""Stored fleet runs: ``GET /fleet/runs`` (newest first, ``?offset&limit``, a ``Link``
to the next page), ``GET /fleet/runs/{id}`` (report, scenario
and a page of events: ``?offset&limit``, read from the parts of events.jsonl it lies in)
and the run's files ``events.jsonl``, ``tracks.csv`` and ``fleet.geojson``, streamed
from the store part by part (:func:`skyroute.jobs.store.open_fleet_file`) with their
length up front; a HEAD of a file is its headers from the size alone, no part read.

Runs are written by fleet jobs (:mod:`skyroute.jobs.store`, imported on first use;
without it these endpoints answer 503).
"""

from __future__ import annotations

import json
import logging
from typing import Annotated, Any

from fastapi import APIRouter, Path, Query, Request, Response
from fastapi.responses import StreamingResponse
from pydantic import BaseModel, Field

from skyroute.io.json_text import to_json
from skyroute.service import cut
from skyroute.service.middleware import is_head
from skyroute.service.paths import url_path
from skyroute.service.problems import Problem, responses
from skyroute.service.resources import Resources, ResourcesDep

router = APIRouter(tags=["fleet"])
log = logging.getLogger("skyroute.service")
RunId = Annotated[str, Path(max_length=100)]


class RunSummary(BaseModel):
    id: str
    scenario: str | None = Field(None, description="The scenario's name.")
    params: dict[str, Any] | None = None
    report: dict[str, Any] | None = None
    created: str | None = Field(None, description="When the run was stored (ISO 8601, "
                                "UTC): runs of the same scenario, hours and seed differ "
                                "by it.")


class Run(BaseModel):
    id: str
    report: dict[str, Any]
    scenario: dict[str, Any]
    params: dict[str, Any] | None = None
    events: list[dict[str, Any]] = Field(description="Events offset .. offset + limit.")
    offset: int
    limit: int
    events_total: int
    files: dict[str, str] = Field(description="Each of the run's files by name: "
                                  "events.jsonl, tracks.csv, fleet.geojson, and "
                                  "packages.csv where the run has it.")


def _store():
    try:
        from skyroute.jobs import store
    except ImportError:
        raise Problem(503, "fleet runs are not available in this installation "
                      "(skyroute.jobs is missing)", kind="jobs-unavailable") from None
    return store


def _run(res: Resources, run_id: str, *files: str) -> dict:
    """The run's summary and only the ``files`` named (the store's column names): a
    route reads what it answers, never the tracks (about 150 MB for a big run) to page
    its events."""
    run = _store().get_fleet_run(res.engine(), run_id, files=files)
    if run is None:
        raise Problem(404, f"no fleet run {run_id!r}; GET /fleet/runs lists them",
                      kind="unknown-run")
    return run


def _as_dict(value) -> dict:
    if isinstance(value, str):
        return json.loads(value)
    return dict(value or {})


def _text(run: dict, *keys: str) -> str:
    """A stored file's text under the first of ``keys`` the store uses."""
    for k in keys:
        v = run.get(k)
        if v is not None:
            return v.decode() if isinstance(v, bytes | bytearray | memoryview) \
                else str(v)
    return ""


def _scenario(run: dict) -> dict:
    """The run's scenario as an object: stored whole, in its parameters, or a preset's
    name."""
    sc = run.get("scenario")
    if isinstance(sc, dict):
        return sc
    params = _as_dict(run.get("params"))
    if isinstance(params.get("scenario"), dict):
        return params["scenario"]
    name = params.get("preset") or sc
    if isinstance(name, str):
        from skyroute.fleet.scenario import PRESETS, preset

        if name in PRESETS:
            return preset(name).model_dump(mode="json")
        try:
            return json.loads(name)
        except ValueError:
            pass
    return {}


RUNS_PAGE = 100  # runs in a page of GET /fleet/runs unless limit says otherwise
MAX_RUNS_PAGE = 1000
NEXT = {"Link": {"description": 'The next page, when there is one: `</fleet/runs?offset='
                 'N&limit=M>; rel="next"` (the path behind the server\'s root path, when it '
                 'has one: `</prefix/fleet/runs?...>`).', "schema": {"type": "string"}}}


@router.get("/fleet/runs", response_model=list[RunSummary],
            responses={200: {"headers": NEXT}, **responses(422, 503)},
            summary="Stored fleet runs, newest first, a page at a time")
def list_runs(res: ResourcesDep, request: Request, response: Response,
              offset: Annotated[int, Query(ge=0, le=2**62, description="Runs to skip, "
                                           "newest first.")] = 0,
              limit: Annotated[int, Query(ge=1, le=MAX_RUNS_PAGE, description="Runs in "
                                          "the page.")] = RUNS_PAGE) -> list[dict]:
    # one run more than the page: whether a next page exists, without a count
    rows = _store().list_fleet_runs(res.engine(), offset=offset, limit=limit + 1)
    if len(rows) > limit:
        del rows[limit:]
        nxt = url_path(request, f"/fleet/runs?offset={offset + limit}&limit={limit}")
        response.headers["Link"] = f'<{nxt}>; rel="next"'
    out = []
    for r in rows:
        sc = r.get("scenario")
        name = sc.get("name") if isinstance(sc, dict) else sc
        out.append({"id": str(r["id"]), "scenario": name,
                    "params": _as_dict(r.get("params")),
                    "report": _as_dict(r.get("report")), "created": r.get("created")})
    return out


@router.get("/fleet/runs/{run_id}", response_model=Run,
            responses=responses(404, 409, 422, 503),
            summary="A fleet run: report, scenario, a page of events")
def get_run(run_id: RunId, res: ResourcesDep, request: Request,
            offset: Annotated[int, Query(ge=0)] = 0,
            limit: Annotated[int, Query(ge=1, le=10_000)] = 1000) -> dict:
    store = _store()
    for _ in range(3):  # a run replaced while it was read: read the new one
        events = _stored(res, run_id, "events_jsonl")
        try:  # the parts the page lies in, not the whole file (hundreds of MB at most)
            lines, total = events.lines(offset, limit)
        except store.RunChangedError:
            continue
        run = _run(res, run_id)
        packages = _stored(res, run_id, "packages_csv")
        if run.get("created") == events.created == packages.created:
            break
    else:
        raise Problem(409, f"fleet run {run_id!r} was replaced again and again while it "
                      "was read; ask again", kind="run-changed")
    base = url_path(request, f"/fleet/runs/{run_id}")
    names = ["events.jsonl", "tracks.csv", "fleet.geojson"]
    if packages.size:  # a run stored without it: a 404 there
        names.append("packages.csv")
    return {"id": str(run["id"]), "report": _as_dict(run.get("report")),
            "scenario": _scenario(run), "params": _as_dict(run.get("params")),
            "events": [json.loads(x) for x in lines], "offset": offset, "limit": limit,
            "events_total": total, "files": {k: f"{base}/{k}" for k in names}}


def _file(content: str | bytes, media_type: str, name: str) -> Response:
    return Response(content, media_type=media_type,
                    headers={"Content-Disposition": f'attachment; filename="{name}"'})


def _stored(res: Resources, run_id: str, key: str):
    """The run's stored file ``key`` (the store's name) to stream, its size known; 404
    for an unknown run."""
    f = _store().open_fleet_file(res.engine(), run_id, key)
    if f is None:
        raise Problem(404, f"no fleet run {run_id!r}; GET /fleet/runs lists them",
                      kind="unknown-run")
    return f


class _StoredResponse(StreamingResponse):
    """A stored file's response: to a HEAD request only its headers (the length is known
    up front), no part read from the store; to a GET its parts as the store reads them.

    A run replaced by other bytes or deleted while its file is sent (the store's
    RunChangedError; the same bytes stored again are followed by the store) cuts the
    response short: one warning in the log, and the connection closed before the body
    reaches its Content-Length, so no client takes the part it got for the whole file
    (:mod:`skyroute.service.cut`). Asking again gets the run as it is now."""

    def __init__(self, f, media_type: str, headers: dict[str, str], changed: type) -> None:
        super().__init__(iter(f), media_type=media_type, headers=headers)
        self.file, self.changed = f, changed

    async def __call__(self, scope, receive, send) -> None:
        if not is_head(scope):
            self.path = scope.get("path", "")
            cut.begin()
            await super().__call__(scope, receive, send)
            return
        await send({"type": "http.response.start", "status": self.status_code,
                    "headers": self.raw_headers})
        await send({"type": "http.response.body", "body": b"", "more_body": False})

    async def stream_response(self, send) -> None:
        await send({"type": "http.response.start", "status": self.status_code,
                    "headers": self.raw_headers})
        sent = 0
        try:
            async for chunk in self.body_iterator:
                await send({"type": "http.response.body", "body": chunk, "more_body": True})
                sent += len(chunk)
        except self.changed as exc:
            log.warning("GET %s cut short after %s of its %s bytes: %s (the client sees "
                        "the connection closed before the end of the body)", self.path,
                        f"{sent:,}", f"{self.file.size:,}", exc)
            cut.mark()
            return  # without the last message: the server closes the connection
        await send({"type": "http.response.body", "body": b"", "more_body": False})


def _stream(f, media_type: str, name: str) -> StreamingResponse:
    """The stored file ``f`` sent as the store reads it, part by part (at most
    ``PART_BYTES`` held at a time, not the whole file: a big run's tracks are about
    150 MB), with its length up front; to a HEAD request the same headers alone."""
    return _StoredResponse(f, media_type, {
        "Content-Length": str(f.size),
        "Content-Disposition": f'attachment; filename="{name}"'},
        changed=_store().RunChangedError)


@router.get("/fleet/runs/{run_id}/events.jsonl", response_class=Response,
            responses={200: {"content": {"application/x-ndjson": {}}}, **responses(404, 503)},
            summary="A fleet run's events, one JSON object a line")
def get_events(run_id: RunId, res: ResourcesDep) -> Response:
    return _stream(_stored(res, run_id, "events_jsonl"), "application/x-ndjson",
                   "events.jsonl")


@router.get("/fleet/runs/{run_id}/tracks.csv", response_class=Response,
            responses={200: {"content": {"text/csv": {}}}, **responses(404, 503)},
            summary="A fleet run's tracks (one row per drone and time step)")
def get_tracks(run_id: RunId, res: ResourcesDep) -> Response:
    return _stream(_stored(res, run_id, "tracks_csv"), "text/csv", "tracks.csv")


@router.get("/fleet/runs/{run_id}/fleet.geojson", response_class=Response,
            responses={200: {"content": {"application/geo+json": {}}},
                       **responses(404, 503)},
            summary="A fleet run's airports, runways and tracks in lon/lat")
def get_geojson(run_id: RunId, res: ResourcesDep) -> Response:
    stored = _stored(res, run_id, "fleet_geojson")
    if stored.size:
        return _stream(stored, "application/geo+json", "fleet.geojson")
    # a run stored without it: rebuilt from its tracks, read only then
    from skyroute.fleet.scenario import parse_scenario
    from skyroute.io.fleet_out import fleet_geojson_from_tracks

    run = _run(res, run_id, "tracks_csv")
    scenario = parse_scenario(_scenario(run), "scenario")
    text = to_json(fleet_geojson_from_tracks(scenario, _text(run, "tracks", "tracks_csv")))
    return _file(text, "application/geo+json", "fleet.geojson")
