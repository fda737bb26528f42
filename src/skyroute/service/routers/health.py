"""``GET /health``: the process answers (it opens nothing, so it stays cheap)."""

from __future__ import annotations

from fastapi import APIRouter
from pydantic import BaseModel

import skyroute

router = APIRouter(tags=["health"])


class Health(BaseModel):
    status: str
    version: str


@router.get("/health", response_model=Health, summary="The server is up")
def health() -> Health:
    return Health(status="ok", version=skyroute.__version__)
