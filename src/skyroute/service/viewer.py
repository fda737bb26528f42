"""The viewer's files (``service/static``, mounted at ``/``) with the headers that keep
a page to what it came with: a Content-Security-Policy that runs only the viewer's own
scripts, talks only to this server and is shown in no other site's frame, and
``X-Content-Type-Options: nosniff``.

The pages build every element from data as text (``js/ui.js``'s ``h``), never as HTML;
the policy is the second wall: should a name from the store (a customer, a place, an
airport id) ever reach the page as HTML, its ``<script>`` or ``onerror=`` does not run.
Inline ``style`` attributes stay allowed (the legends' swatches and the drone colours
are set so); inline scripts, ``eval`` and other origins are not. ``/docs`` and
``/redoc`` (fastapi-offline's pages, whose scripts are inline) are not served from here
and keep their own headers.
"""

from __future__ import annotations

from starlette.staticfiles import StaticFiles

CSP = "; ".join((
    "default-src 'self'",
    "script-src 'self'",
    "style-src 'self' 'unsafe-inline'",
    "img-src 'self' data: blob:",
    "connect-src 'self'",
    "object-src 'none'",
    "base-uri 'none'",
    "form-action 'self'",
    "frame-ancestors 'none'",
))
HEADERS = {"Content-Security-Policy": CSP, "X-Content-Type-Options": "nosniff"}


class ViewerFiles(StaticFiles):
    """:class:`StaticFiles` whose every answer (a page, a script, a 304) carries
    :data:`HEADERS`."""

    async def get_response(self, path: str, scope):
        response = await super().get_response(path, scope)
        response.headers.update(HEADERS)
        return response
