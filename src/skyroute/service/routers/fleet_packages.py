"""``GET /fleet/runs/{id}/packages.csv``: a fleet run's packages (one row each: spawn,
origin and destination airports and gates, times, drone, state at the end), as
:mod:`skyroute.io.fleet_out` writes it. The viewer's package table reads each package's
destination here, which the events name only once the package flies.

Read-only, beside :mod:`skyroute.service.routers.fleet` (same run lookup, same 404 and 503).
"""

from __future__ import annotations

from fastapi import APIRouter, Response

from skyroute.service.problems import Problem, responses
from skyroute.service.resources import ResourcesDep
from skyroute.service.routers.fleet import RunId, _stored, _stream

router = APIRouter(tags=["fleet"])


@router.get("/fleet/runs/{run_id}/packages.csv", response_class=Response,
            responses={200: {"content": {"text/csv": {}}}, **responses(404, 503)},
            summary="A fleet run's packages (one row per package)")
def get_packages(run_id: RunId, res: ResourcesDep) -> Response:
    stored = _stored(res, run_id, "packages_csv")
    if not stored.size:
        raise Problem(404, f"fleet run {run_id!r} has no packages.csv", kind="no-packages")
    return _stream(stored, "text/csv", "packages.csv")
