"""``POST /jobs/fleet``'s ``scenario`` in ``/openapi.json`` is the fleet's own scenario
model, and it declares the bounds the server holds a scenario to.

It was a free-form object: a client or an SDK made from the schema learnt the fields,
their types and their limits from 422s. Its fields are now those of a scenario file
(what ``skyroute fleet scenario`` writes and ``skyroute fleet simulate`` reads), and the
limits the scenario's validators check with their own messages (airports and zones
counted, positions from home, drones, rate, shared levels, two gates) are declared too:
each is read from the schema, a value at it is valid in the schema and not refused for
its field, one step past it is invalid in the schema and a 422 naming the field.
"""

from __future__ import annotations

import copy
import math

import jsonschema_rs
import pytest
import yaml

from skyroute.fleet.flightplan import gate_position
from skyroute.fleet.scenario import generate, parse_scenario, preset, to_yaml
from skyroute.service.app import create_app
from skyroute.service.settings import Settings
from tests.service.conftest import AUTH, TOKEN
from tests.service.test_app import assert_problem
from tests.service.test_jobs_fleet import SEED3, site_client  # noqa: F401  (a fixture)

SPEC = create_app(Settings(token=TOKEN, warm=False, db_url="sqlite://")).openapi()
SCHEMAS = SPEC["components"]["schemas"]
KEYWORDS = ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum", "minItems",
            "maxItems")
# the bounds that were nowhere in the schema: (path, keyword); "*" is any list item
DECLARED = {
    (("airports",), "maxItems"),
    *((("airports", "*", k), b) for k in ("north", "east") for b in ("minimum", "maximum")),
    (("airports", "*", "gates"), "minItems"), (("airports", "*", "gates"), "maxItems"),
    (("drones",), "maximum"), (("packages", "rate_per_hour"), "maximum"),
    (("airspace", "shared_levels"), "maximum"), (("no_fly_zones",), "maxItems"),
    *((("no_fly_zones", "*", "points", "*", i), b) for i in (0, 1)
      for b in ("minimum", "maximum")),
}


def _node(node: dict) -> dict:
    """``node`` with a ``$ref`` followed and a nullable ``anyOf`` reduced to its
    non-null branch."""
    if "$ref" in node:
        return SCHEMAS[node["$ref"].rsplit("/", 1)[1]]
    branches = [b for b in node.get("anyOf", ()) if b.get("type") != "null"]
    return _node(branches[0]) if len(branches) == 1 else node


def bounds() -> dict[tuple[tuple, str], object]:
    """{(path, keyword): bound} of every bound in the schema of a posted scenario."""
    out = {}

    def walk(path: tuple, node: dict) -> None:
        node = _node(node)
        for key in KEYWORDS:
            if key in node:
                out[path, key] = node[key]
        for name, sub in node.get("properties", {}).items():
            walk((*path, name), sub)
        if "items" in node:
            walk((*path, "*"), node["items"])
        for i, sub in enumerate(node.get("prefixItems", ())):
            walk((*path, i), sub)

    walk((), SCHEMAS["FleetJob"]["properties"]["scenario"])
    return out


BOUNDS = bounds()
VALIDATOR = jsonschema_rs.Draft202012Validator(
    {"$ref": "#/components/schemas/FleetJob", "components": SPEC["components"]})


def test_the_scenario_is_the_fleets_model_in_the_schema():
    """Every field a scenario file has (``to_yaml`` writes each, defaults included) is
    a property of the posted scenario, with its description where the model has one;
    a preset's scenario is valid in the schema."""
    def keys(doc, node, path=""):
        node = _node(node)
        assert set(doc) == set(node["properties"]), path
        for k, v in doc.items():
            if isinstance(v, dict):
                keys(v, node["properties"][k], f"{path}.{k}")
            elif isinstance(v, list) and v and isinstance(v[0], dict):
                keys(v[0], _node(node["properties"][k])["items"], f"{path}.{k}[0]")

    doc = yaml.safe_load(to_yaml(preset("seed-3x3")))
    doc["no_fly_zones"] = [{"name": "z", "points": [[0, 0], [0, 9], [9, 0]]}]
    keys(doc, SCHEMAS["FleetJob"]["properties"]["scenario"])
    assert SCHEMAS["PostedScenario"]["properties"]["drones"]["description"]
    assert SCHEMAS["Airport"]["properties"]["north"]["description"] == "metres north of home"
    assert VALIDATOR.is_valid({"scenario": SEED3})
    # packages name no file on the server: csv is null or absent
    assert not VALIDATOR.is_valid({"scenario": {**SEED3, "packages": {"csv": "p.csv"}}})


def test_the_schema_declares_the_validators_bounds():
    assert set(BOUNDS) >= DECLARED


def _past(bound, key: str, integer: bool):
    """One step past ``bound``: the next integer or float outside it."""
    up = key in ("maximum", "maxItems")
    if integer or key in ("minItems", "maxItems"):
        return int(bound) + (1 if up else -1)
    return math.nextafter(float(bound), math.inf if up else -math.inf)


def _gates(airport: dict) -> list[list[float]]:
    """An airport's two gates where the model puts them by default."""
    a = parse_scenario(SEED3).airports[0]
    assert a.id == airport["id"]
    return [list(map(float, gate_position(a, k))) for k in (0, 1)]


def _zone(n: int, corner: tuple[float, float] = (90_000.0, 90_000.0)) -> dict:
    """A small triangle, far from the airports, with ``corner`` as its first corner."""
    x, y = corner
    dx, dy = (-10.0 if x > 0 else 10.0), (-10.0 if y > 0 else 10.0)
    return {"name": f"z{n}", "points": [[x, y], [x + dx, y], [x, y + dy]]}


def scenario(path: tuple, key: str, value) -> dict:
    """SEED3 but for the field at ``path`` set to ``value`` (a count for an item
    bound: that many items)."""
    s = copy.deepcopy(SEED3)
    if path == ("airports",):
        if value > len(SEED3["airports"]):  # a layout that fits that many
            s["airports"] = generate(min(value, 100), 3, area_km=30).model_dump(
                mode="json")["airports"]
            s["airports"] += s["airports"][:value - len(s["airports"])]
        return s
    if path == ("no_fly_zones",):
        s["no_fly_zones"] = [_zone(k, (90_000.0 - 20 * k, 90_000.0)) for k in range(value)]
        return s
    if path == ("airports", "*", "gates"):
        gates = _gates(s["airports"][0])
        s["airports"][0]["gates"] = (gates + [[g + 40 for g in gates[1]]] * 5)[:value]
        return s
    if path[0] == "no_fly_zones":
        corner = [90_000.0, 90_000.0]
        corner[path[-1]] = value
        s["no_fly_zones"] = [_zone(0, tuple(corner))]
        return s
    node = s
    for p in path[:-1]:
        node = node[0 if p == "*" else p]
    node[path[-1]] = value
    return s


def field(path: tuple) -> str:
    """The field a 422 names: ``scenario.airports[0].north``."""
    out = "scenario"
    for p in path:
        out += "[0]" if p == "*" else f"[{p}]" if isinstance(p, int) else f".{p}"
    return out


@pytest.mark.parametrize("path, key", sorted(DECLARED, key=str),
                         ids=[f"{field(p)}-{k}" for p, k in sorted(DECLARED, key=str)])
def test_a_declared_bound_is_where_the_server_refuses(site_client, fake, path, key):  # noqa: F811
    bound = BOUNDS[path, key]
    integer = key in ("minItems", "maxItems") or path[-1] in ("drones", "shared_levels")
    name = field(path)
    ok = scenario(path, key, int(bound) if integer else float(bound))
    assert VALIDATOR.is_valid({"scenario": ok}), (path, key)
    r = site_client.post("/jobs/fleet", json={"scenario": ok}, headers=AUTH)
    named = {e["field"] for e in r.json().get("errors", ())} if r.status_code == 422 \
        else set()
    assert r.status_code == 202 and not named, r.text
    bad = scenario(path, key, _past(bound, key, integer))
    assert not VALIDATOR.is_valid({"scenario": bad}), (path, key)
    doc = assert_problem(site_client.post("/jobs/fleet", json={"scenario": bad},
                                          headers=AUTH), 422)
    assert doc["field"] == name and len(doc["detail"].splitlines()) == 1, doc


@pytest.fixture
def fake(monkeypatch):
    from tests.service.test_jobs_fleet import FakeJobs

    return FakeJobs().install(monkeypatch)
