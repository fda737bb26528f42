"""The service's JSON response: infinities and NaNs as ``null``.

Starlette's JSONResponse refuses them (``allow_nan=False``): a document carrying one
was a 500. Pydantic writes them as null in the routes with a response model; this
class does the same for the others (``POST /plan``, jobs, problems) with the one
encoder the CLI's ``--json`` uses (:func:`skyroute.io.json_text.to_json`).
"""

from __future__ import annotations

from fastapi.responses import JSONResponse

from skyroute.io.json_text import to_json


class FiniteJSONResponse(JSONResponse):
    """A JSONResponse that writes non-finite numbers as ``null``."""

    def render(self, content) -> bytes:
        return to_json(content, ensure_ascii=False, separators=(",", ":")).encode("utf-8")
