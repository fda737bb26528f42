"""``POST /plan``: one query of :func:`skyroute.plan` over HTTP, on a bundled map (by
name), an uploaded map text, or an uploaded world (colliders CSV or GeoJSON zones).

The answer is the planner's own result (``PlanResult.to_dict``: the same status, cost,
path and expansions as the same call in Python) plus the path as GeoJSON. A request may
lower, never raise, the server's search budget (``max_expansions``); PRM samples and
raster sizes are capped too. Bad input is a 422 naming the field.
"""

from __future__ import annotations

import math
import threading
import time
from typing import Annotated, Literal

from fastapi import APIRouter, Depends
from fastapi.concurrency import run_in_threadpool
from pydantic import BaseModel, ConfigDict, Field, StrictBool, model_validator

from skyroute.errors import SEED_MAX, InputFormatError, QueryError, SkyrouteError
from skyroute.roadmap.limits import MAX_SAMPLES, MIN_SAMPLES
from skyroute.service.alternatives import exactly_one
from skyroute.service.auth import require_token
from skyroute.service.json_response import FiniteJSONResponse
from skyroute.service.problems import Problem, from_skyrouteerror, responses
from skyroute.service.resources import Resources, ResourcesDep
from skyroute.world.load import MAX_SAFETY_DEGREES, MIN_ALTITUDE, bundled_maps
from skyroute.world.points import MAX_LAT, MAX_LON, MAX_METRES

router = APIRouter(tags=["plan"])

Algorithm = Literal["astar", "dijkstra", "bfs", "jps", "theta", "lazy_theta", "visibility",
                    "prm"]
# Numbers, counts and switches are strict, as skyroute.plan reads them: a JSON number
# (an integer counts), a JSON integer, true or false; never a numeric string ("3"), a
# boolean as a number or a number as a boolean, or 100.0 as a count (a 422 naming it).
# `connectivity` is a choice, not a count: 8.0 is taken as 8, as skyroute.plan takes it.
Number = Annotated[float, Field(strict=True, allow_inf_nan=False)]
Point = tuple[Number, Number]
# The schema states every bound the server holds a value to (a client or a form made
# from /openapi.json refuses what the server would), from the library's own constants.
Lon = Annotated[Number, Field(ge=-MAX_LON, le=MAX_LON)]
Lat = Annotated[Number, Field(ge=-MAX_LAT, le=MAX_LAT)]
MapName = Literal[tuple(bundled_maps())]  # the bundled maps, as GET /maps lists them
# Bounds that depend on another field, stated as JSON Schema's if/then (each a 422
# naming its field): a margin in the degrees frame is at most MAX_SAFETY_DEGREES
# (load_world refuses more); start and goal on a map are cells, two integers from 0
# (_cell, the grid's bounds); on a world they are points in the frame: lon/lat in
# lonlat (the default) and degrees (check_places), metres within MAX_METRES of home in
# ned, local and enu (check_metres).
WORLD = {"required": ["world_text"], "properties": {"world_text": {"type": "string"}}}


def _when(rule: dict, then: dict) -> dict:
    return {"if": rule, "then": {"properties": then}}


def _points(*item: dict) -> dict:
    return {k: {"prefixItems": list(item)} for k in ("start", "goal")}


def _within(limit: float) -> dict:
    return {"minimum": -limit, "maximum": limit}


CONDITIONS = [
    _when({"properties": {"frame": {"const": "degrees"}}, "required": ["frame"]},
          {"safety": {"maximum": MAX_SAFETY_DEGREES}}),
    _when({"properties": {"world_text": {"type": "null"}}},  # absent or null: a map
          _points(*[{"type": "integer", "minimum": 0}] * 2)),
    _when({**WORLD, "properties": {**WORLD["properties"],
                                   "frame": {"enum": ["lonlat", "degrees"]}}},
          _points(_within(MAX_LON), _within(MAX_LAT))),
    _when({"required": [*WORLD["required"], "frame"],
           "properties": {**WORLD["properties"], "frame": {"enum": ["ned", "local", "enu"]}}},
          _points(*[_within(MAX_METRES)] * 2)),
]
Pair = Annotated[list[float], Field(min_length=2, max_length=2)]
SOURCES = ("map", "map_text", "world_text")  # exactly one of them
DEFAULT_SAMPLES = 1000  # skyroute.plan's, unless this server's limit is lower


class PlanRequest(BaseModel):
    """One planning query. Give exactly one of ``map``, ``map_text`` and ``world_text``
    (null counts as not given), and ``world_format`` with ``world_text``; the schema
    states it as ``oneOf``.

    On a map, ``start`` and ``goal`` are (x, y) cells (column, row) and the options are
    those of :func:`skyroute.plan` on a Grid. On a world they are points in ``frame``
    and ``algorithm`` defaults to ``visibility``."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, json_schema_extra={
        "examples": [{"map": "den312d", "start": [50, 76], "goal": [60, 13],
                      "algorithm": "astar"}],
        **exactly_one("map", "map_text", ("world_text", "world_format"),
                      among=SOURCES), "allOf": CONDITIONS})

    map: MapName | None = Field(None, description="A bundled map's name (GET /maps). "
                                "Exactly one of map, map_text and world_text.")
    map_text: str | None = Field(None, description="A MovingAI .map file's text. Exactly "
                                 "one of map, map_text and world_text.")
    world_text: str | None = Field(None, description="A world file's text, read as "
                                   "world_format. Exactly one of map, map_text and "
                                   "world_text.")
    world_format: Literal["colliders", "geojson"] | None = Field(
        None, description="How to read world_text: colliders (FCND colliders.csv) or "
        "geojson (zones). Required with world_text.")
    frame: Literal["lonlat", "ned", "local", "enu", "degrees"] = Field(
        "lonlat", description="Worlds: the frame of start, goal and the path.")
    altitude: Number | None = Field(None, ge=MIN_ALTITUDE, description="Worlds: keep "
                                    "obstacles that count at this altitude (metres above "
                                    "the ground).")
    safety: Number = Field(0.0, ge=0, le=MAX_METRES, description="Grow obstacles by this "
                           "margin: metres, or degrees in the degrees frame (there at "
                           f"most {MAX_SAFETY_DEGREES:g}).")
    boundary: tuple[Lon, Lat, Lon, Lat] | None = Field(
        None, description="Worlds: [min_lon, min_lat, max_lon, max_lat], each min below "
        "its max.")
    start: Point
    goal: Point
    algorithm: Algorithm | None = Field(None, description="Default astar on maps, "
                                        "visibility on worlds.")
    connectivity: Literal[4, 8] | None = None
    corner_cutting: StrictBool = False
    heuristic: Literal["octile", "euclidean", "manhattan", "zero"] | None = None
    weight: Number = Field(1.0, ge=1.0, le=1e6)
    prune: Literal["none", "collinear", "los"] | None = None
    max_expansions: int | None = Field(None, strict=True, ge=1, le=2**62,
                                       description="Stop after this many expansions; "
                                       "null: enough to finish the search; capped by the "
                                       "server's budget.")
    resolution: Number | None = Field(None, gt=0, le=MAX_METRES, description="Worlds, "
                                      "grid algorithms: cell size in world units (at most "
                                      "a local plane's 1e7 m; the raster, 8 cells round "
                                      "the obstacles and points, must lie within it).")
    samples: int = Field(DEFAULT_SAMPLES, strict=True, ge=MIN_SAMPLES, le=MAX_SAMPLES,
                         description="PRM samples, at most this server's limit (the "
                         "schema's maximum; the default is held to it too).")
    neighbours: int = Field(10, strict=True, ge=1, le=1000, description="PRM neighbours.")
    prm_star: StrictBool = False
    seed: int = Field(0, strict=True, ge=0, le=SEED_MAX, description="PRM seed.")
    geojson: StrictBool = Field(True, description="Add the path as GeoJSON.")

    @model_validator(mode="after")
    def _one_source(self) -> PlanRequest:
        given = [k for k in SOURCES if getattr(self, k) is not None]
        if len(given) != 1:
            raise ValueError("give exactly one of map, map_text and world_text"
                             + (f" (got {', '.join(given)})" if given else ""))
        if self.world_text is not None and self.world_format is None:
            raise ValueError("world_format (colliders or geojson) is required with "
                             "world_text")
        return self


class PlanAnswer(BaseModel):
    status: Literal["found", "no_path", "budget_exhausted"]
    cost: float | None = Field(description="Path length (cells on a map, world units on a "
                               "world); null unless found.")
    path: list[Pair] = Field(description="Cells (x, y) on a map; points in "
                                            "the frame on a world.")
    expanded: int
    max_frontier: int
    los_checks: int
    seconds: float = Field(description="The search's own wall time.")
    algorithm: str
    max_expansions: int | None = Field(description="The budget the search ran with (null "
                                       "for PRM, bounded by its samples instead).")
    path_lonlat: list[Pair] | None = None
    frame: str | None = None
    waypoints: list[list[float]] | None = Field(
        None, description="Worlds: [north, east, altitude, heading] per point (FCND): metres "
        "from home, heading in radians clockwise from north along the track into the point.")
    geojson: dict | None = None


ANSWER_KEYS = tuple(PlanAnswer.model_fields)

# Planning is CPU work that holds the GIL: more than one search at a time per process
# only adds switching, so searches take turns (the wait shows in Server-Timing).
_SEARCH = threading.Lock()


@router.post("/plan", response_model=PlanAnswer, dependencies=[Depends(require_token)],
             responses=responses(401, 403, 413, 422), summary="Plan one path")
async def post_plan(body: PlanRequest, res: ResourcesDep) -> FiniteJSONResponse:
    # A bundled map is read once and its search is bounded by the budget: when no other
    # search holds the slot it runs right here on the event loop (a thread hop and the
    # GIL hand-overs cost more than the search on most queries). The loop never waits
    # for the slot: a busy slot sends the query to the thread pool, as uploads always go
    # (they are parsed first, at any size up to the body limit).
    t0 = time.perf_counter()
    if body.map is not None and _SEARCH.acquire(blocking=False):
        try:
            out, timing = _search(body, res, t0)
        finally:
            _SEARCH.release()
    else:
        out, timing = await run_in_threadpool(_timed, body, res, t0)
    return FiniteJSONResponse(out, headers={"Server-Timing": timing})


def _timed(body: PlanRequest, res: Resources, t0: float) -> tuple[dict, str]:
    """Wait for the search slot (on a pool thread), then search."""
    with _SEARCH:
        return _search(body, res, t0)


def _search(body: PlanRequest, res: Resources, t0: float) -> tuple[dict, str]:
    """The answer and its Server-Timing (the wait since ``t0``, the search); the caller
    holds the slot."""
    t1 = time.perf_counter()
    out = _plan(body, res)
    t2 = time.perf_counter()
    return out, f"wait;dur={(t1 - t0) * 1e3:.3f}, plan;dur={(t2 - t1) * 1e3:.3f}"


def _plan(body: PlanRequest, res: Resources) -> dict:
    try:
        return _plan_checked(body, res)
    except QueryError as exc:
        field = exc.param or next((w for w in ("start", "goal") if str(exc).startswith(w)),
                                  None)
        raise Problem(422, str(exc), field=field) from None
    except InputFormatError as exc:
        field = "map_text" if body.map_text is not None else "world_text"
        raise from_skyrouteerror(exc, field=field) from None
    except SkyrouteError as exc:
        raise from_skyrouteerror(exc) from None


def _plan_checked(body: PlanRequest, res: Resources) -> dict:
    from skyroute.planner import plan

    cap = res.settings.max_expansions
    budget = cap if body.max_expansions is None else min(body.max_expansions, cap)
    if body.world_text is None:
        grid = _grid(body, res)
        start, goal = _cell(body.start, "start"), _cell(body.goal, "goal")
        r = plan(grid, start, goal, algorithm=body.algorithm or "astar",
                 max_expansions=budget, **_options(body))
        out = r.to_dict()
        if body.geojson:
            from skyroute.io.geojson import grid_path_geojson

            out["geojson"] = grid_path_geojson(grid, r)
    else:
        world = _world(body)
        _check_world_limits(body, world, res)
        algorithm = body.algorithm or "visibility"
        options = _options(body)
        if algorithm == "prm":
            budget = None  # scipy's Dijkstra has no budget; samples bound the work
            options.setdefault("samples", _samples_default(res.settings))
        r = plan(world, tuple(body.start), tuple(body.goal), algorithm=algorithm,
                 max_expansions=budget, **options)
        out = r.to_dict()
        out["frame"] = world.frame
        if r.found:
            from skyroute.io.world_out import waypoints

            out["waypoints"] = waypoints(world, r.path, body.altitude or 0.0)
        if body.geojson:
            from skyroute.io.world_out import world_path_geojson

            out["geojson"] = world_path_geojson(world, r)
    out["max_expansions"] = budget
    for key in ANSWER_KEYS:  # the answer's shape whatever was planned on (JSON null)
        out.setdefault(key, None)
    return out


OPTIONS = ("connectivity", "corner_cutting", "heuristic", "weight", "prune", "resolution",
           "samples", "neighbours", "prm_star", "seed")
WORLD_ONLY = ("frame", "altitude", "boundary")  # how a world_text is read


def _options(body: PlanRequest) -> dict:
    """The planner options the request gave (null counts as not given), for
    :func:`skyroute.plan` to read or refuse as it does in Python: ``seed`` on a map or
    ``samples`` with "visibility" is a 422 naming it, not dropped."""
    given = body.model_fields_set
    return {k: getattr(body, k) for k in OPTIONS
            if k in given and getattr(body, k) is not None}


def _grid(body: PlanRequest, res: Resources):
    stray = next((k for k in WORLD_ONLY if k in body.model_fields_set
                  and getattr(body, k) is not None), None)
    if stray is not None:
        raise Problem(422, f"{stray}={getattr(body, stray)!r} applies to a world "
                      "(world_text); a map is searched as it is", field=stray)
    if body.map is not None:
        grid = res.grid(body.map)  # one of the bundled maps: the schema's enum (MapName)
    else:
        from skyroute.world.movingai import read_map

        grid = read_map("map_text", text=body.map_text)
    if body.safety:
        grid = grid.inflate(body.safety)
    return grid


def _cell(p, name: str) -> tuple[int, int]:
    if not all(float(v).is_integer() for v in p):
        raise Problem(422, f"{name} {list(p)}: a cell on a map is two integers (x, y)",
                      field=name)
    return int(p[0]), int(p[1])


def _world(body: PlanRequest):
    from skyroute.world.load import load_world

    name = "world_text.csv" if body.world_format == "colliders" else "world_text.geojson"
    # the boundary goes in as numbers only: load_world would read any other string as a
    # file name, and a request names no file on the server
    box = None if body.boundary is None else ",".join(repr(float(v)) for v in body.boundary)
    return load_world(name, text=body.world_text, altitude=body.altitude,
                      safety=body.safety, boundary=box, frame=body.frame)


def _check_world_limits(body: PlanRequest, world, res: Resources) -> None:
    s = res.settings
    algorithm = body.algorithm or "visibility"
    if algorithm == "prm" and "samples" in body.model_fields_set \
            and body.samples > s.max_samples:
        raise Problem(422, f"samples={body.samples} is over this server's limit of "
                      f"{s.max_samples:,}", field="samples")
    if algorithm not in ("prm", "visibility"):
        cells, r = _raster_cells(body, world)
        if cells > s.max_raster_cells:
            given = "" if body.resolution is not None else " (the default for this world)"
            raise Problem(422, f"resolution={r:g}{given} makes a raster of {cells:,} "
                          f"cells; this server's limit is {s.max_raster_cells:,}",
                          field="resolution")


def _raster_cells(body: PlanRequest, world) -> tuple[int, float]:
    """The cells and resolution of the raster a grid algorithm will build
    (:func:`skyroute.roadmap.raster.raster_box`, as ``world_raster`` builds it)."""
    from skyroute.roadmap.raster import default_resolution, raster_box

    s, t = world.check_point(body.start, "start"), world.check_point(body.goal, "goal")
    r = default_resolution(world, [s, t]) if body.resolution is None else body.resolution
    x0, y0, x1, y1 = raster_box(world, s, t, r)
    return max(1, math.ceil((x1 - x0) / r)) * max(1, math.ceil((y1 - y0) / r)), r


def _samples_default(settings) -> int:
    """PRM's samples when a request gives none: skyroute.plan's default, held to this
    server's limit (a request that gave none was refused when the limit was lower)."""
    return min(DEFAULT_SAMPLES, settings.max_samples)


def declare_limits(spec: dict, settings) -> None:
    """Put this server's own limits into ``spec`` (the app's OpenAPI document), where
    the request model holds the library's: ``samples`` at most ``max_samples``, and its
    default held to it. A client made from ``/openapi.json`` then refuses what this
    server would (a 422 naming ``samples``)."""
    samples = spec["components"]["schemas"]["PlanRequest"]["properties"]["samples"]
    samples["maximum"] = min(samples["maximum"], settings.max_samples)
    samples["default"] = _samples_default(settings)
