"""The scenario a fleet job posts (``POST /jobs/fleet``'s ``scenario``): the fleet's own
model (:class:`skyroute.fleet.scenario.Scenario`, what ``skyroute fleet simulate`` reads
from a file), so its fields, bounds and descriptions are in ``/openapi.json`` and no
second copy of them can drift. Two differences, both stated in the schema: ``packages``
is a mapping and names no file (``packages.csv`` would be read on the server).

Errors are the scenario reader's (:func:`~skyroute.fleet.scenario.first_error`): one,
naming its field under ``scenario`` (``scenario.airports[1].takeoff.length``).
"""

from __future__ import annotations

from pydantic import Field, ValidationError, field_validator
from pydantic_core import InitErrorDetails, PydanticCustomError

from skyroute.fleet.scenario import Packages, Scenario, first_error


class PostedPackages(Packages):
    """Packages of a posted scenario: a seeded stream (``csv`` only null)."""

    csv: None = Field(None, description="Not in a posted scenario: it would name a file "
                      "on the server; give rate_per_hour.")

    @field_validator("csv", mode="before")
    @classmethod
    def _no_file(cls, v):
        if v is not None:
            raise ValueError("a posted scenario cannot name a file on the server; give "
                             "packages.rate_per_hour")
        return v


class PostedScenario(Scenario):
    """A fleet scenario as ``POST /jobs/fleet`` takes it: the fields of ``skyroute fleet
    scenario``'s YAML, with packages drawn at ``packages.rate_per_hour``."""

    packages: PostedPackages = PostedPackages()

    @field_validator("packages", mode="before")
    @classmethod
    def _mapping(cls, v):
        # pydantic's own message named the Python class ("instance of PostedPackages")
        if not isinstance(v, dict | Packages):
            raise ValueError("expected a mapping of package fields (rate_per_hour)")
        return v


def validate(value, handler) -> PostedScenario | None:
    """``value`` through ``handler`` (a wrap validator's: the field's own validation),
    its first error alone, as the scenario reader reports it (one line, the field named
    below the request's ``scenario``)."""
    try:
        return handler(value)
    except ValidationError as exc:
        loc, msg = first_error(exc, PostedScenario)
        raise ValidationError.from_exception_data("scenario", [InitErrorDetails(
            type=PydanticCustomError("scenario", "{reason}", {"reason": msg}),
            loc=loc, input=value)]) from None
