"""The service's own URLs under the path a reverse proxy serves it at.

Behind a proxy that forwards ``https://host/skyroute/...`` to the server as ``/...``,
the server runs with ``skyroute serve --root-path /skyroute`` (uvicorn's ``root_path``:
each request's ``scope["root_path"]``). A URL the service hands out (the ``Link`` of
a page of runs, a job's ``Location``, a run's ``files``, the links of the 404 page)
is then that prefix and the app's path; without one, the app's path alone. Requests
are routed, and told apart as API or viewer paths, by the path under the prefix
(:func:`route_path`).
"""

from __future__ import annotations

from starlette.requests import Request


def root_path(request: Request) -> str:
    """The prefix the server is served under ("" for none), without a trailing ``/``."""
    return request.scope.get("root_path", "").rstrip("/")


def url_path(request: Request, path: str) -> str:
    """The path a client asks for to reach the app's ``path`` (``/fleet/runs``)."""
    return root_path(request) + path


def route_path(request: Request) -> str:
    """The request's path under the prefix, as the app's routes see it: uvicorn gives
    ``path`` with the prefix in front, a client may leave it out (as Starlette's routing
    reads it)."""
    path, root = request.scope["path"], root_path(request)
    if root and (path == root or path.startswith(root + "/")):
        return path[len(root):] or "/"
    return path
