"""The write endpoints' bearer token: missing is 401 (with ``WWW-Authenticate``), wrong
is 403; compared in constant time (:func:`secrets.compare_digest`). A check the whole
app runs before the route's own dependencies (:mod:`skyroute.service.query`) calls
:func:`authenticate` first on a route that needs the token, so a caller without it
learns nothing of the route's parameters."""

from __future__ import annotations

import secrets
from typing import Annotated

from fastapi import Depends, Request
from fastapi.security import HTTPAuthorizationCredentials, HTTPBearer
from fastapi.security.utils import get_authorization_scheme_param

from skyroute.service.problems import Problem

_bearer = HTTPBearer(auto_error=False, description="The server's token: SKYROUTE_TOKEN, "
                     "--token-file, or the one `skyroute serve` printed at start.")


async def require_token(
        request: Request,
        cred: Annotated[HTTPAuthorizationCredentials | None, Depends(_bearer)]) -> None:
    """A FastAPI dependency: passes with ``Authorization: Bearer <the token>``."""
    if cred is None:
        raise Problem(401, "this endpoint needs 'Authorization: Bearer TOKEN'",
                      headers={"WWW-Authenticate": "Bearer"})
    expected = request.app.state.settings.token.encode()
    if not secrets.compare_digest(cred.credentials.encode(), expected):
        raise Problem(403, "the bearer token is not this server's")


def needs_token(route) -> bool:
    """Whether ``route`` (a FastAPI route) depends on :func:`require_token`, directly or
    through its dependencies."""
    todo = [route.dependant]
    while todo:
        dependant = todo.pop()
        if dependant.call is require_token:
            return True
        todo += dependant.dependencies
    return False


async def authenticate(request: Request) -> None:
    """:func:`require_token` for ``request``, called outside FastAPI's dependencies: by
    an app-wide check that would otherwise answer before the route's token is read."""
    await require_token(request, await _bearer(request))


def has_token(request: Request) -> bool:
    """Whether ``request`` carries ``Authorization: Bearer <the token>``; never an error:
    for an open read that shows its holder more (a failed job's full error)."""
    scheme, given = get_authorization_scheme_param(request.headers.get("Authorization"))
    expected = request.app.state.settings.token.encode()
    return scheme.lower() == "bearer" and secrets.compare_digest(given.encode(), expected)
