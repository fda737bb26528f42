"""Every error as ``application/problem+json`` (RFC 9457): ``type``, ``title``,
``status``, ``detail``, and for a bad input the ``field`` at fault (``errors`` lists them
all). Nothing from inside the server leaks: an unexpected exception is logged and
answered by a generic 500.
"""

from __future__ import annotations

import html
import logging

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import HTMLResponse, Response
from pydantic import BaseModel, Field
from sqlalchemy.exc import OperationalError
from starlette.exceptions import HTTPException as StarletteHTTPException

from skyroute.delivery.store import is_busy
from skyroute.errors import InputFormatError, SkyrouteError, StoreBusyError, StoreSchemaError
from skyroute.service import viewer
from skyroute.service.json_response import FiniteJSONResponse
from skyroute.service.paths import root_path, route_path

MEDIA_TYPE = "application/problem+json"
TYPE_BASE = "urn:skyroute:problem:"
log = logging.getLogger("skyroute.service")

TITLES = {400: "bad request", 401: "not authenticated", 403: "forbidden",
          404: "not found", 405: "method not allowed", 409: "conflict",
          413: "request body too large", 415: "unsupported media type",
          422: "invalid input", 429: "too many jobs", 500: "internal error",
          503: "service unavailable"}


class FieldError(BaseModel):
    field: str = Field(description="The input at fault, e.g. `start[0]`, `date`.")
    message: str


class ProblemDoc(BaseModel):
    """The body of every error response (media type application/problem+json)."""

    type: str = Field(description="A URI naming the kind of problem.")
    title: str
    status: int
    detail: str
    field: str | None = Field(None, description="The input at fault (422).")
    errors: list[FieldError] | None = Field(None, description="Every input at fault (422).")


class Problem(Exception):  # noqa: N818  (an answer, not a failure of the server)
    """Raised by a router to answer with a problem document."""

    def __init__(self, status: int, detail: str, *, field: str | None = None,
                 kind: str | None = None, headers: dict[str, str] | None = None) -> None:
        super().__init__(detail)
        self.status, self.detail, self.field = status, detail, field
        self.kind = kind or TITLES.get(status, "error").replace(" ", "-")
        self.headers = headers


def problem_response(status: int, detail: str, *, field: str | None = None,
                     kind: str | None = None, errors: list[dict] | None = None,
                     headers: dict[str, str] | None = None) -> FiniteJSONResponse:
    title = TITLES.get(status, "error")
    doc = {"type": TYPE_BASE + (kind or title.replace(" ", "-")), "title": title,
           "status": status, "detail": detail}
    if field is not None:
        doc["field"] = field
        # as a validation error reads: the message without the "field: " the detail has
        doc["errors"] = errors or [{"field": field,
                                    "message": detail.removeprefix(f"{field}: ")}]
    return FiniteJSONResponse(doc, status_code=status, media_type=MEDIA_TYPE, headers=headers)


def from_skyrouteerror(exc: SkyrouteError, *, field: str | None = None) -> Problem:
    """A library error on a caller's input as a 422 naming the field (``param`` when the
    library names one; a file error is reported against ``field``, with its line)."""
    if isinstance(exc, InputFormatError):
        where = f"line {exc.line}: " if exc.line is not None else ""
        return Problem(422, f"{field or 'input'}: {where}{exc.reason}", field=field,
                       kind="bad-file")
    param = exc.param if isinstance(exc.param, str) else \
        (exc.param[0] if exc.param else None)
    return Problem(422, str(exc), field=param or field)


def field_name(loc: tuple) -> str:
    """``("body", "start", 0)`` -> ``start[0]``; the request part is left out."""
    parts = list(loc)
    if len(parts) > 1 and parts[0] in ("body", "query", "path", "header"):
        parts = parts[1:]
    out = ""
    for p in parts:
        if isinstance(p, int):
            out += f"[{p}]"
        elif str(p).startswith(("function-", "tagged-union[")):
            continue  # pydantic's label of a validator, not a field
        else:
            out += ("." if out else "") + str(p)
    return out or "body"


def _message(err: dict) -> str:
    msg = err.get("msg", "invalid")
    return msg.removeprefix("Value error, ")


NOT_JSON = "the request body cannot be read as JSON text (UTF-8)"


def _not_json_media(request: Request) -> str | None:
    """Why FastAPI left the body unread (its rule: ``application/json`` or
    ``application/*+json``), or None for a JSON media type."""
    ctype = request.headers.get("content-type")
    if not ctype:
        return "the request has a body but no Content-Type"
    media = ctype.split(";")[0].strip().lower()
    main, _, sub = media.partition("/")
    if main == "application" and (sub == "json" or sub.endswith("+json")):
        return None
    return f"Content-Type {media} is not JSON"


async def _validation(request: Request, exc: RequestValidationError) -> FiniteJSONResponse:
    bad = next((e for e in exc.errors() if e.get("type") == "json_invalid"), None)
    if bad is not None:  # its loc is a byte offset, not a field: a 400, as for non-UTF-8
        where = bad.get("loc", ())[-1:]
        reason = (bad.get("ctx") or {}).get("error", "")
        at = f" at byte {where[0]}" if where and isinstance(where[0], int) else ""
        return problem_response(400, f"{NOT_JSON}: {reason or 'invalid JSON'}{at}")
    if any(tuple(e.get("loc", ())) == ("body",) and e.get("type") != "missing"
           for e in exc.errors()):  # a body that was there but never read as JSON
        why = _not_json_media(request)
        if why is not None:
            return problem_response(415, f"{why}; send the body as application/json")
    errors = [{"field": field_name(tuple(e.get("loc", ()))), "message": _message(e)}
              for e in exc.errors()]
    first = errors[0] if errors else {"field": "body", "message": "invalid input"}
    detail = f"{first['field']}: {first['message']}"
    if len(errors) > 1:
        detail += f" (and {len(errors) - 1} more)"
    return problem_response(422, detail, field=first["field"], errors=errors)


async def _problem(request: Request, exc: Problem) -> FiniteJSONResponse:
    return problem_response(exc.status, exc.detail, field=exc.field, kind=exc.kind,
                            headers=exc.headers)


def _quality(accept: str, media: str) -> float:
    """The q an Accept header gives ``media``: its most specific matching range's (RFC
    9110: exact, then type/*, then */*), 0 when none matches."""
    main = media.split("/")[0]
    best, q = -1, 0.0
    for part in accept.split(","):
        rng, *params = (x.strip() for x in part.split(";"))
        rng = rng.lower()
        rank = 2 if rng == media else 1 if rng == f"{main}/*" else 0 if rng == "*/*" else -1
        if rank > best:
            value = next((p[2:] for p in params if p.lower().startswith("q=")), "1")
            try:
                best, q = rank, float(value)
            except ValueError:
                best, q = rank, 0.0
    return q


def prefers_html(request: Request) -> bool:
    """Whether the client would rather have an HTML page than JSON: a browser navigating
    (``text/html`` over ``application/json``); no Accept header, or ``*/*``, is no."""
    accept = request.headers.get("accept", "")
    html = max(_quality(accept, m) for m in ("text/html", "application/xhtml+xml"))
    json = max(_quality(accept, m) for m in ("application/json", MEDIA_TYPE))
    return html > json


def api_heads(routes) -> frozenset[str]:
    """The first path segments of ``routes`` (plan, days, fleet, docs, openapi.json, ...;
    not the viewer's mount at /): the app factory keeps them as ``state.api_heads``."""
    paths = (getattr(r, "path", "") for r in routes)
    return frozenset(p.split("/")[1] for p in paths if p.startswith("/") and len(p) > 1)


def api_methods(routes) -> tuple:
    """(path pattern, methods) of each of ``routes`` that names its methods: the app
    factory keeps them as ``state.api_methods`` for the ``Allow`` of a 405."""
    return tuple((r.path_regex, frozenset(r.methods)) for r in routes
                 if getattr(r, "methods", None) and getattr(r, "path_regex", None))


def allowed(request: Request) -> str | None:
    """The ``Allow`` of a 405 on an API path: every method of the API's routes for that
    path (HEAD with GET, as HEAD is answered as GET), or None off the API's routes. The
    405 comes from the viewer's mount at ``/``, which matches every path and allows GET
    and HEAD; it said "GET, HEAD" also for ``/days/{date}``, which a DELETE serves."""
    found: set[str] = set()
    for pattern, methods in getattr(request.app.state, "api_methods", ()):
        if pattern.match(route_path(request)):
            found |= methods
    if "GET" in found:
        found.add("HEAD")
    return ", ".join(sorted(found)) or None


def api_path(request: Request) -> bool:
    """Whether the request's path lies under the API (see :func:`api_heads`), not among
    the viewer's pages."""
    heads = getattr(request.app.state, "api_heads", None)
    if heads is None:
        heads = api_heads(request.app.routes)
    return route_path(request).split("/")[1] in heads


NOT_FOUND_PAGE = """<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>Page not found - skyroute</title>
<link rel="icon" href="{root}/favicon.svg" type="image/svg+xml">
<link rel="stylesheet" href="{root}/viewer.css">
</head>
<body>
<main id="main">
<h1>Page not found</h1>
<p>The page <code>{path}</code> does not exist.</p>
<p><a href="{root}/">Go to the skyroute start page</a></p>
</main>
</body>
</html>
"""


async def _http(request: Request, exc: StarletteHTTPException) -> Response:
    detail = exc.detail if isinstance(exc.detail, str) else TITLES.get(exc.status_code,
                                                                        "error")
    if exc.status_code == 404 and detail == "Not Found" and not api_path(request):
        # a page of the viewer that is not there: a browser gets a page, API clients
        # the problem document; either may be cached only by the Accept it was asked with
        if prefers_html(request):
            page = NOT_FOUND_PAGE.format(path=html.escape(request.url.path),
                                         root=html.escape(root_path(request)))
            # a page of the viewer's: its policy too (it shows the path asked for)
            return HTMLResponse(page, status_code=404,
                                headers={"Vary": "Accept", **viewer.HEADERS})
        return problem_response(404, f"no such resource: {request.url.path}",
                                headers={"Vary": "Accept"})
    if exc.status_code == 404 and detail == "Not Found":
        detail = f"no such resource: {request.url.path}"
    elif exc.status_code == 400 and detail == "There was an error parsing the body":
        detail = NOT_JSON
    headers = getattr(exc, "headers", None)
    if exc.status_code == 405:
        detail = f"{request.method} is not allowed on {request.url.path}"
        allow = allowed(request)
        if allow:
            headers = {**(headers or {}), "Allow": allow}
    return problem_response(exc.status_code, detail, headers=headers)


async def _library(request: Request, exc: SkyrouteError) -> FiniteJSONResponse:
    return await _problem(request, from_skyrouteerror(exc))


BUSY_RETRY_SECONDS = 5  # a busy store's Retry-After: its writer has held it past the timeout


async def _busy(request: Request, exc: StoreBusyError) -> FiniteJSONResponse:
    """The store locked by another process past its busy timeout: the server's condition,
    and a passing one, not a fault of the request (a write was answered 422, a read
    500); the store's URL in the library's message stays in the log."""
    log.warning("%s %s: %s", request.method, request.url.path,
                str(exc).splitlines()[0])
    return problem_response(503, "the store is busy: another process has kept it locked "
                            "past the busy timeout; nothing was changed; try again later",
                            kind="store-busy",
                            headers={"Retry-After": str(BUSY_RETRY_SECONDS)})


async def _schema(request: Request, exc: StoreSchemaError) -> FiniteJSONResponse:
    """The store without skyroute's tables (dropped, or its file replaced, under the
    running server, which made them when it opened the store): the server's condition,
    answered as a store that cannot be opened is (``Resources.engine``). The library's
    message names the store's URL or file: it was the body of a 422, to anyone; it now
    stays in the log."""
    log.warning("%s %s: the store cannot be read: %s", request.method, request.url.path,
                str(exc).splitlines()[0])
    return problem_response(503, "the store cannot be read: its tables are missing; the "
                            "server's log says why", kind="store-unavailable")


UNREACHABLE_RETRY_SECONDS = 10  # a lost server's Retry-After: a restart takes seconds


async def _database(request: Request, exc: OperationalError) -> FiniteJSONResponse:
    """A database error the store let through: a read of a locked SQLite store is
    :func:`_busy`'s 503; the store's server lost (:func:`lost`) a 503
    ``store-unavailable`` with ``Retry-After``, the driver's reason in the log in one
    line; anything else the 500 of :func:`_internal`."""
    if is_busy(exc):
        return await _busy(request, exc)
    if lost(exc):
        log.warning("%s %s: the store cannot be reached: %s", request.method,
                    request.url.path, (str(exc.orig).strip().splitlines() or ["?"])[0])
        return problem_response(503, "the store cannot be reached; the server's log says "
                                "why; try again later", kind="store-unavailable",
                                headers={"Retry-After": str(UNREACHABLE_RETRY_SECONDS)})
    return await _internal(request, exc)


def lost(exc: OperationalError) -> bool:
    """Whether ``exc`` is a store that cannot be reached after the server opened it: no
    connection could be made (no statement: the database server down or restarting,
    the database dropped), or one was lost in a statement (SQLAlchemy marks it
    invalidated). The server's condition, and often a passing one; it was a 500 whose
    traceback filled the log at every request."""
    return exc.connection_invalidated or exc.statement is None


async def _internal(request: Request, exc: Exception) -> FiniteJSONResponse:
    log.exception("unhandled error on %s %s", request.method, request.url.path)
    return problem_response(500, "the server could not answer this request; the error "
                            "is in its log")


def install(app: FastAPI) -> None:
    """Register the handlers on ``app``."""
    app.add_exception_handler(RequestValidationError, _validation)
    app.add_exception_handler(Problem, _problem)
    app.add_exception_handler(StarletteHTTPException, _http)
    app.add_exception_handler(SkyrouteError, _library)
    app.add_exception_handler(StoreBusyError, _busy)  # (a child: its own handler wins)
    app.add_exception_handler(StoreSchemaError, _schema)  # (likewise)
    app.add_exception_handler(OperationalError, _database)
    app.add_exception_handler(Exception, _internal)


def responses(*codes: int) -> dict:
    """OpenAPI ``responses=`` entries for these error codes (their media type is set to
    problem+json by :func:`document`)."""
    return {c: {"model": ProblemDoc, "description": TITLES.get(c, "error")} for c in codes}


def document(app: FastAPI) -> None:
    """Make ``app``'s OpenAPI say what the handlers do: every error response is
    ``application/problem+json`` with :class:`ProblemDoc` (FastAPI documents its 422 as
    JSON of its own shape), an operation with inputs documents 422, one with a body 400
    and 415, and a write 413."""
    from fastapi.openapi.utils import get_openapi

    def openapi() -> dict:
        if app.openapi_schema:
            return app.openapi_schema
        spec = get_openapi(title=app.title, version=app.version,
                           description=app.description, routes=app.routes)
        schemas = spec.setdefault("components", {}).setdefault("schemas", {})
        schemas["ProblemDoc"] = ProblemDoc.model_json_schema(
            ref_template="#/components/schemas/{model}")
        for name, sub in schemas["ProblemDoc"].pop("$defs", {}).items():
            schemas[name] = sub
        for name in ("HTTPValidationError", "ValidationError"):
            schemas.pop(name, None)
        problem = {MEDIA_TYPE: {"schema": {"$ref": "#/components/schemas/ProblemDoc"}}}
        for ops in spec.get("paths", {}).values():
            for method, op in ops.items():
                codes = op.setdefault("responses", {})
                if op.get("parameters") or op.get("requestBody"):
                    codes.setdefault("422", {})
                if op.get("requestBody"):
                    codes.setdefault("400", {})  # a body that is not UTF-8 text
                    codes.setdefault("415", {})  # a body not sent as JSON
                if method in ("post", "put", "patch"):
                    codes.setdefault("413", {})
                for code, resp in codes.items():
                    if code[0] in "45":
                        resp["description"] = TITLES.get(int(code), "error")
                        resp["content"] = problem
        app.openapi_schema = spec
        return spec

    app.openapi = openapi
