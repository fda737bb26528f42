"""The write endpoints' bearer token: missing is 401 (with ``WWW-Authenticate``), wrong
is 403; compared in constant time (:func:`secrets.compare_digest`)."""

from __future__ import annotations

import secrets
from typing import Annotated

from fastapi import Depends, Request
from fastapi.security import HTTPAuthorizationCredentials, HTTPBearer

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
