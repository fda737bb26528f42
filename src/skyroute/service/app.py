"""The app factory: ``create_app(settings)`` -> a FastAPI app with every router, the
error handlers, the body limit, the timing header, the API reference at ``/docs`` and
``/redoc`` (served from local files) and the static viewer at ``/``.

Making the app opens nothing; the store, the site and the job executor open on first use
(:mod:`skyroute.service.resources`) and close when the app shuts down. Starting it (the
lifespan, before the server accepts a connection) warms the planners
(:mod:`skyroute.service.warm`) unless ``Settings.warm`` is off, then marks the process
ready for the bench that started it (:mod:`skyroute.bench.ready`, only when asked).
"""

from __future__ import annotations

import asyncio
import contextlib
from contextlib import asynccontextmanager
from pathlib import Path

from fastapi import APIRouter, Depends, FastAPI, Request
from fastapi_offline import FastAPIOffline

import skyroute
from skyroute.bench import ready
from skyroute.service import cut, problems, query
from skyroute.service.json_response import FiniteJSONResponse
from skyroute.service.middleware import BodyLimit, HeadAsGet, ServerTiming, TrustedHosts
from skyroute.service.resources import Resources
from skyroute.service.routers import (
    days,
    fleet,
    fleet_packages,
    health,
    jobs,
    maps,
    orders,
    plan,
    site,
)
from skyroute.service.settings import Settings
from skyroute.service.viewer import ViewerFiles

STATIC = Path(__file__).parent / "static"
POST_ONLY = ("/plan", "/jobs/deliver", "/jobs/fleet")

DESCRIPTION = """Plan paths on grids and worlds, read stored delivery days, run delivery
and fleet jobs. Reads are open; writes (`POST`, `DELETE`) need `Authorization: Bearer TOKEN`.
Every error is `application/problem+json` naming the field at fault."""


def create_app(settings: Settings | None = None) -> FastAPI:
    """A new app for ``settings`` (default: ``Settings()``, a random token)."""
    settings = settings or Settings()

    @asynccontextmanager
    async def lifespan(app: FastAPI):
        cut.install()  # the server has set up its logging by now
        if settings.warm:  # before the first connection: no caller pays for it
            from skyroute.service.warm import warm

            app.state.warmed = warm(app.state.resources)
        ready.mark_ready()  # one file a process: the bench waits for all of them
        # a second Ctrl-C (uvicorn's forced exit) sends no shutdown: the lifespan is
        # cancelled as the loop ends, which starlette logged as a failed shutdown (a
        # KeyboardInterrupt and CancelledError traceback); the jobs' workers ran on,
        # the exit waited for their tasks, and the running job failed with "cannot
        # schedule new futures after shutdown", not as an orphan
        with contextlib.suppress(asyncio.CancelledError):
            yield
        app.state.resources.close()

    # /docs and /redoc from files in the fastapi-offline package, not a CDN: a server
    # in the field (no internet) still shows its API reference
    app = FastAPIOffline(title="skyroute", version=skyroute.__version__,
                         description=DESCRIPTION, lifespan=lifespan,
                         # an infinity or a NaN is null, never a 500 (json_response)
                         default_response_class=FiniteJSONResponse,
                         # every route: a repeated single-valued query parameter is a 422
                         dependencies=[Depends(query.one_value_each)])
    app.state.settings = settings
    app.state.resources = Resources(settings)
    problems.install(app)
    problems.document(app)
    _declare_limits(app, settings)
    app.include_router(_post_only(POST_ONLY))  # first: /jobs/fleet is not /jobs/{job_id}
    modules = (health, maps, days, orders, site, plan, jobs, fleet, fleet_packages)
    for module in modules:
        app.include_router(module.router)
    app.add_middleware(ServerTiming)  # inside the body limit: the body is in hand
    app.add_middleware(BodyLimit, limit=settings.max_body_bytes)
    if "*" not in settings.allowed_hosts:  # before the body is read; HEAD as GET, too
        app.add_middleware(TrustedHosts, allowed_hosts=settings.allowed_hosts)
    app.add_middleware(HeadAsGet)
    app.mount("/", ViewerFiles(directory=STATIC, html=True), name="static")
    # the API's first path segments: a browser asking for any other missing path gets
    # an HTML page, not the problem document (the routers' own routes are listed, as
    # the app keeps included routers unexpanded)
    routes = [*app.routes, *(r for m in modules for r in m.router.routes)]
    app.state.api_heads = problems.api_heads(routes)
    app.state.api_methods = problems.api_methods(routes)  # a 405's Allow
    return app


def _declare_limits(app: FastAPI, settings: Settings) -> None:
    """``app``'s OpenAPI with this server's own limits where its settings lower the
    library's (:func:`plan.declare_limits`): the document is made once, then kept."""
    made = app.openapi

    def openapi() -> dict:
        if not app.openapi_schema:
            plan.declare_limits(made(), settings)
        return app.openapi_schema

    app.openapi = openapi


def _post_only(paths: tuple[str, ...]) -> APIRouter:
    """Any other method on these POST-only paths: a 405 with ``Allow: POST`` (without it
    the viewer mounted at ``/`` answers for them, 405 ``Allow: GET, HEAD`` or 404)."""
    router = APIRouter(include_in_schema=False)

    async def not_allowed(request: Request) -> None:
        raise problems.Problem(405, f"{request.method} is not allowed on "
                               f"{request.url.path}; use POST", headers={"Allow": "POST"})

    for path in paths:  # (HEAD arrives as GET: HeadAsGet)
        router.add_api_route(path, not_allowed, methods=["GET", "PUT", "PATCH", "DELETE",
                                                         "OPTIONS"])
    return router


SETTINGS_ENV = "SKYROUTE_SERVICE_SETTINGS"


def app_from_env() -> FastAPI:
    """The app for the settings in ``$SKYROUTE_SERVICE_SETTINGS`` (JSON): how each of
    ``skyroute serve --workers N``'s processes makes its own app."""
    import os

    return create_app(Settings.model_validate_json(os.environ[SETTINGS_ENV]))
