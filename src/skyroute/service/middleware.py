"""Four plain ASGI middlewares: the request body limit (413 past it, before any handler
reads a byte too many), the server-side timing header every response carries
(``Server-Timing: app;dur=MS``, which the load benchmark reads), HEAD answered as GET
without its body, and the check of the ``Host`` header against the server's names.

The body limit runs first and hands the app the whole body, so ``app;dur`` is the time
from the complete request to the response headers: the server's work on the request,
not the wait for a client's bytes to arrive."""

from __future__ import annotations

import time

from starlette.datastructures import Headers
from starlette.middleware.trustedhost import TrustedHostMiddleware

from skyroute.service.problems import problem_response


class BodyLimit:
    """Refuse a body over ``limit`` bytes with a 413 problem: a declared Content-Length
    is checked first, then the bytes as they stream in. The body is read whole before
    the app sees the request (so the timing inside starts with the request in hand)."""

    def __init__(self, app, limit: int) -> None:
        self.app, self.limit = app, limit

    async def __call__(self, scope, receive, send) -> None:
        if scope["type"] != "http" or scope["method"] not in ("POST", "PUT", "PATCH"):
            await self.app(scope, receive, send)
            return
        declared = dict(scope["headers"]).get(b"content-length")
        if declared is not None:
            try:
                size = int(declared)
            except ValueError:
                size = -1
            if size < 0:
                await self._refuse(scope, receive, send, 400, "Content-Length is not a number")
                return
            if size > self.limit:
                await self._refuse(scope, receive, send, 413, self._too_large(size))
                return
        chunks, size = [], 0
        while True:
            message = await receive()
            if message["type"] != "http.request":
                await self.app(scope, _replay([message]), send)
                return
            chunks.append(message.get("body", b""))
            size += len(chunks[-1])
            if size > self.limit:
                await self._refuse(scope, receive, send, 413, self._too_large(size, at_least=True))
                return
            if not message.get("more_body", False):
                break
        await self.app(scope, _replay([{"type": "http.request", "body": b"".join(chunks),
                                         "more_body": False}]), send)

    def _too_large(self, size: int, *, at_least: bool = False) -> str:
        return (f"the request body is {'over ' if at_least else ''}{size:,} bytes; the "
                f"limit is {self.limit:,}")

    async def _refuse(self, scope, receive, send, status: int, detail: str) -> None:
        response = problem_response(status, detail, headers={"Connection": "close"})
        await response(scope, receive, send)


def _replay(messages: list[dict]):
    queue = list(messages)

    async def receive() -> dict:
        if queue:
            return queue.pop(0)
        return {"type": "http.disconnect"}

    return receive


class ServerTiming:
    """Adds ``Server-Timing: app;dur=<milliseconds>`` (from the request, body included,
    reaching the app to its response headers), after any metric a handler set itself."""

    def __init__(self, app) -> None:
        self.app = app

    async def __call__(self, scope, receive, send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        t0 = time.perf_counter()

        async def timed_send(message) -> None:
            if message["type"] == "http.response.start":
                ms = (time.perf_counter() - t0) * 1e3
                headers = list(message.get("headers", []))
                mine = f"app;dur={ms:.3f}".encode()
                for i, (k, v) in enumerate(headers):
                    if k.lower() == b"server-timing":
                        headers[i] = (k, v + b", " + mine)
                        break
                else:
                    headers.append((b"server-timing", mine))
                message = {**message, "headers": headers}
            await send(message)

        await self.app(scope, receive, timed_send)


HEAD_KEY = "skyroute.head"  # in the scope of a HEAD request that HeadAsGet passes on as GET


def is_head(scope) -> bool:
    """Whether the request came as ``HEAD`` (and reaches the app as GET): a response
    whose headers are known before its body (a stored file's length) sends only those."""
    return bool(scope.get(HEAD_KEY))


class HeadAsGet:
    """Answer ``HEAD`` as ``GET`` with the body left out (RFC 9110: the same status and
    headers). FastAPI's routes take GET alone, so without this the viewer's static mount
    answered HEAD on every API path with a 404. The scope passed on says it was HEAD
    (:func:`is_head`), so a response can skip making a body that would be dropped."""

    def __init__(self, app) -> None:
        self.app = app

    async def __call__(self, scope, receive, send) -> None:
        if scope["type"] != "http" or scope["method"] != "HEAD":
            await self.app(scope, receive, send)
            return

        async def no_body(message) -> None:
            if message["type"] == "http.response.body":
                message = {**message, "body": b""}
            await send(message)

        await self.app({**scope, "method": "GET", HEAD_KEY: True}, receive, no_body)


class TrustedHosts:
    """Starlette's :class:`~starlette.middleware.trustedhost.TrustedHostMiddleware` over
    ``allowed_hosts`` (names, addresses, ``*.example.com``), its refusal a 400 problem
    document like the app's other errors (Starlette's is the text "Invalid host
    header"). Without it a page of another site reaches a server on 127.0.0.1 through a
    DNS name of its own that it points there (DNS rebinding), and reads what the server
    serves: the browser sends that name as the ``Host``."""

    def __init__(self, app, allowed_hosts) -> None:
        self.app = app
        self.check = TrustedHostMiddleware(self._through, allowed_hosts=list(allowed_hosts),
                                           www_redirect=False)

    async def _through(self, scope, receive, refusal: _Refusal) -> None:
        await self.app(scope, receive, refusal.send)  # a trusted host: the real send

    async def __call__(self, scope, receive, send) -> None:
        refusal = _Refusal(send)
        await self.check(scope, receive, refusal)
        if refusal.refused:
            host = Headers(scope=scope).get("host")
            said = "no Host header" if host is None else f"the Host {host[:100]!r}"
            response = problem_response(
                400, f"{said} is not one of this server's names (skyroute serve "
                "--allowed-hosts)", kind="untrusted-host")
            await response(scope, receive, send)


class _Refusal:
    """The ``send`` handed to Starlette's check: its own refusal is dropped (a problem
    is sent instead); a request it lets through is sent on with ``send`` itself."""

    def __init__(self, send) -> None:
        self.send, self.refused = send, False

    async def __call__(self, message) -> None:
        self.refused = True
