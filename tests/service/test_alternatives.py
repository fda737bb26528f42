"""The "exactly one of" rules of the request bodies are in /openapi.json as ``oneOf``,
and the schema accepts exactly the bodies the models' validators accept: every field of
a rule absent, null or given, the rest of the body valid."""

from __future__ import annotations

import itertools

import jsonschema_rs
import pytest
from pydantic import ValidationError

from skyroute.fleet.scenario import preset
from skyroute.service import alternatives
from skyroute.service.routers.jobs import DeliverJob, FleetJob
from skyroute.service.routers.plan import PlanRequest

# model, its path, the fields each oneOf branch requires, a valid value of each field,
# the rest of a valid body
RULES = {
    "PlanRequest": (PlanRequest, "/plan",
                    [["map"], ["map_text"], ["world_text", "world_format"]],
                    {"map": "den312d", "map_text": "type octile\nheight 1\nwidth 1\nmap\n.",
                     "world_text": "lat0 0, lon0 0", "world_format": "colliders"},
                    {"start": [0, 0], "goal": [0, 0]}),
    "DeliverJob": (DeliverJob, "/jobs/deliver", [["date"], ["from", "to"]],
                   {"date": "2024-01-03", "from": "2024-01-01", "to": "2024-01-02"}, {}),
    "FleetJob": (FleetJob, "/jobs/fleet", [["preset"], ["scenario"]],
                 # a scenario is the fleet's model now, in the schema as in the validator
                 {"preset": "seed-3x3", "scenario": preset("seed-3x3").model_dump(
                     mode="json")}, {"hours": 0.5}),
}
ABSENT = object()


@pytest.fixture(scope="module")
def spec():
    from tests.service.conftest import make_client

    with make_client(db_url="sqlite:///:memory:") as c:  # the schema opens no store
        return c.get("/openapi.json").json()


def body_schema(spec: dict, path: str) -> dict:
    return spec["paths"][path]["post"]["requestBody"]["content"]["application/json"][
        "schema"]


@pytest.mark.parametrize("name", RULES)
def test_openapi_states_the_rule_as_one_of(spec, name):
    _, path, required, _, _ = RULES[name]
    assert body_schema(spec, path) == {"$ref": f"#/components/schemas/{name}"}
    schema = spec["components"]["schemas"][name]
    assert [b["required"] for b in schema["oneOf"]] == required
    for branch in schema["oneOf"]:
        assert set(branch["properties"]) <= set(schema["properties"])
        for field in branch["required"]:
            assert branch["properties"][field] == {"not": {"type": "null"}}
    for field in (f for r in required for f in r):  # the description says it in words
        assert f"``{field}``" in schema["description"], (field, schema["description"])
    assert "oneOf" in schema["description"]


@pytest.mark.parametrize("name", RULES)
def test_schema_and_validator_accept_the_same_bodies(spec, name):
    model, path, required, values, rest = RULES[name]
    validator = jsonschema_rs.Draft202012Validator(
        {**body_schema(spec, path), "components": spec["components"]})
    fields = list(values)
    accepted = []
    for choice in itertools.product((ABSENT, None, "value"), repeat=len(fields)):
        body = dict(rest)
        for field, c in zip(fields, choice, strict=True):
            if c is not ABSENT:
                body[field] = values[field] if c == "value" else None
        try:
            model.model_validate(body)
            runtime = True
        except ValidationError:
            runtime = False
        assert validator.is_valid(body) == runtime, (body, runtime)
        if runtime:
            accepted.append(sorted(k for k in fields if body.get(k) is not None))
    assert {tuple(a) for a in accepted} >= {tuple(sorted(r)) for r in required}


def test_exactly_one_misuse():
    with pytest.raises(ValueError, match="two or more alternatives"):
        alternatives.exactly_one("map")
