"""What a service instance is configured with (``skyroute serve`` fills it from flags).

Every limit that protects the server lives here, with its default: the request body
size, the search budget per ``POST /plan``, the raster and roadmap sizes a caller may
ask for, and the job queue length.
"""

from __future__ import annotations

import ipaddress
import secrets
from pathlib import Path

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from skyroute.delivery.store import DEFAULT_DB
from skyroute.roadmap.limits import MIN_SAMPLES

MB = 1024 * 1024
# a token's fewest characters: the write endpoints answer anyone who can reach the
# server, so a short token is guessed by trying (the generated one has 43)
MIN_TOKEN = 16


class Settings(BaseModel):
    """A service's configuration; immutable once the app is made."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    db_url: str = Field(DEFAULT_DB, description="SQLAlchemy URL of the delivery store.")
    data_dir: Path | None = Field(None, description="The delivery site: a data folder in the "
                                  "ILP layout (as `deliver --data`).")
    source_url: str | None = Field(None, description="The delivery site over HTTP "
                                   "(as `deliver --source`).")
    token: str = Field(default_factory=lambda: secrets.token_urlsafe(32),
                       description="Bearer token the write endpoints require (at least "
                       f"{MIN_TOKEN} printable ASCII characters).")
    max_body_bytes: int = Field(10 * MB, gt=0, description="Largest request body (413 past it).")
    max_expansions: int = Field(2_000_000, gt=0, description="Search budget per POST /plan: "
                                "a larger or missing max_expansions is capped to it.")
    max_raster_cells: int = Field(4_000_000, gt=0, description="Largest raster a grid "
                                  "algorithm on a world may build: its resolution (given "
                                  "or default) over the world, start and goal.")
    max_samples: int = Field(20_000, ge=MIN_SAMPLES, description="Largest PRM roadmap per "
                             "request (POST /plan's samples; /openapi.json declares it, or "
                             "the planner's own where that is lower, as their maximum).")
    fresh_seconds: float = Field(1.0, ge=0, description="How long a file made from a "
                                 "stored day is served before the store is asked again "
                                 "whether the day changed.")
    job_queue: int = Field(8, ge=1, description="Jobs queued or running at once (429 past it).")
    dask_address: str | None = Field(None, description="Run jobs on this Dask scheduler "
                                     "(tcp://HOST:8786) instead of local processes.")
    job_workers: int | None = Field(None, ge=1, description="Local worker processes for jobs.")
    allowed_hosts: tuple[str, ...] = Field(("*",), description="The names a request's "
                                           "Host header may give (a 400 for any other): "
                                           "host names, addresses, *.example.com; '*' "
                                           "takes any (the app factory's default; `serve` "
                                           "on a loopback address names its own).")
    warm: bool = Field(True, description="Load the planners' compiled kernels and "
                       "libraries when the app starts, before it takes a request "
                       "(skyroute.service.warm), not in its first POST /plan.")

    @field_validator("token")
    @classmethod
    def _sendable(cls, token: str) -> str:
        # the token travels in a header: a client sends a non-ASCII one as UTF-8 (curl,
        # httpx) or Latin-1 (browsers), and no request matched it (every write a 403);
        # the message names the character's place, not the character (a secret's part)
        bad = next((i for i, ch in enumerate(token) if not " " <= ch <= "~"), None)
        if bad is not None:
            raise ValueError(f"the token's character {bad + 1} is not printable ASCII; "
                             "it goes in an HTTP header, which carries only that")
        if len(token) < MIN_TOKEN:  # (the limit said, not the token's own length)
            raise ValueError(f"the token is shorter than {MIN_TOKEN} characters, short "
                             "enough to guess; choose a longer one (python -c 'import "
                             "secrets; print(secrets.token_urlsafe(32))' makes one)")
        return token

    @field_validator("allowed_hosts")
    @classmethod
    def _hosts(cls, hosts: tuple[str, ...]) -> tuple[str, ...]:
        if not hosts:
            raise ValueError("give at least one host (or * for any)")
        return tuple(dict.fromkeys(host_pattern(h) for h in hosts))

    @model_validator(mode="after")
    def _one_site(self) -> Settings:
        if self.data_dir is not None and self.source_url is not None:
            raise ValueError("give at most one of data_dir and source_url")
        return self

    @property
    def has_site(self) -> bool:
        return self.data_dir is not None or self.source_url is not None


def host_pattern(text: str) -> str:
    """``text`` as a Host header names it, for the Host check (Starlette's
    ``TrustedHostMiddleware``): lower case, an IPv6 address in brackets (``::1`` ->
    ``[::1]``); ``*`` (any host), or ``*.`` and a domain (its subdomains). A ValueError
    naming it for a port, an empty name or a ``*`` elsewhere."""
    host = text.strip().lower()
    bare = host.removeprefix("[").removesuffix("]")
    try:
        if ipaddress.ip_address(bare).version == 6:
            return f"[{bare}]"
    except ValueError:
        pass
    if not host or host == "*." or "*" in host[1:] or (host[0] == "*" and host != "*"
                                                      and not host.startswith("*.")):
        raise ValueError(f"host {text!r}: give a name, an address, *.domain or *")
    if ":" in host or "/" in host:
        raise ValueError(f"host {text!r}: give the name or address alone (no port, "
                         "scheme or path)")
    return host
