"""The bounds ``/openapi.json`` declares on ``POST /plan``'s fields are the server's own.

Each bound is read from the schema (not written here): a value at it is valid in the
schema and not refused for its field, a value one step past it (the next float, the
next integer, a name not in the enum) is invalid in the schema and a 422 problem naming
the field. The schema declared none of altitude's, safety's maximum, the boundary's
degrees or the bundled maps, and samples from 1 (the planner's is 2): a client or a form
made from it sent values the server refused.
"""

from __future__ import annotations

import json
import math

import jsonschema_rs
import pytest

from skyroute.roadmap import world_plan
from skyroute.roadmap.prm import prm_options
from skyroute.service.app import create_app
from skyroute.service.settings import Settings
from tests.service.conftest import AUTH, TOKEN, make_client
from tests.service.test_app import assert_problem
from tests.service.test_plan import CITY, CITY_LONLAT

# the fields whose bounds the schema came to declare (each of its bounds is checked)
FIELDS = ("altitude", "safety", "samples", "boundary", "map")
# what it must declare of them (field, keyword, the frame it holds in)
DECLARED = {("altitude", "minimum", None), ("safety", "minimum", None),
            ("safety", "maximum", None), ("safety", "maximum", "degrees"),
            ("samples", "minimum", None), ("samples", "maximum", None),
            ("map", "enum", None),
            *((f"boundary[{i}]", k, None) for i in range(4) for k in ("minimum", "maximum"))}
SPEC = create_app(Settings(token=TOKEN, warm=False, db_url="sqlite://")).openapi()


def bounds(spec: dict) -> list[tuple[str, str, object, str, str | None]]:
    """(field as a 422 names it, keyword, bound, JSON type, frame) of every bound the
    PlanRequest schema puts on :data:`FIELDS`, its ``if frame ... then`` ones too."""
    plan = spec["components"]["schemas"]["PlanRequest"]
    out = []

    def walk(name: str, node: dict, kind: str | None, frame: str | None) -> None:
        for alt in node.get("anyOf", [node]):
            for i, item in enumerate(alt.get("prefixItems", ())):
                walk(f"{name}[{i}]", item, None, frame)
            for key in ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum",
                        "enum"):
                if key in alt:
                    out.append((name, key, alt[key], alt.get("type") or kind, frame))

    for name in FIELDS:
        walk(name, plan["properties"][name], None, None)
    if "if" in plan:
        frame = plan["if"]["properties"]["frame"]["const"]
        for name, sub in plan["then"]["properties"].items():
            walk(name, sub, plan["properties"][name].get("type"), frame)
    return out


BOUNDS = bounds(SPEC)


def test_the_schema_declares_every_bound_the_server_holds():
    assert {(f, k, frame) for f, k, _, _, frame in BOUNDS} >= DECLARED


def _step(bound, kind: str, down: bool):
    if kind == "integer":
        return int(bound) - 1 if down else int(bound) + 1
    return math.nextafter(float(bound), -math.inf if down else math.inf)


def at_and_past(key: str, bound, kind: str) -> tuple[list, list]:
    """The values at the bound (accepted) and one step past it (refused)."""
    if key == "enum":
        return list(bound), [bound[0] + ".map"]
    exact = int(bound) if kind == "integer" else float(bound)
    if key == "minimum":
        return [exact], [_step(bound, kind, down=True)]
    if key == "maximum":
        return [exact], [_step(bound, kind, down=False)]
    if key == "exclusiveMinimum":
        return [_step(bound, kind, down=False)], [exact]
    return [_step(bound, kind, down=True)], [exact]  # exclusiveMaximum


CITY_BODY = {"world_format": "colliders", "world_text": CITY.read_text(),
             "start": list(CITY_LONLAT[0]), "goal": list(CITY_LONLAT[1])}


def zones(box: list[float]) -> dict:
    """A GeoJSON world of one small zone in the middle of ``box`` (lon/lat), start and
    goal either side of it."""
    x0, y0, x1, y1 = box
    cx, cy, w, h = (x0 + x1) / 2, (y0 + y1) / 2, (x1 - x0) / 10, (y1 - y0) / 10
    ring = [[cx - w, cy - h], [cx + w, cy - h], [cx + w, cy + h], [cx - w, cy + h],
            [cx - w, cy - h]]
    doc = {"type": "FeatureCollection", "features": [{
        "type": "Feature", "properties": {"name": "z"},
        "geometry": {"type": "Polygon", "coordinates": [ring]}}]}
    return {"world_format": "geojson", "world_text": json.dumps(doc), "boundary": box,
            "start": [x0 + 0.1 * (x1 - x0), y0 + 0.1 * (y1 - y0)],
            "goal": [x0 + 0.9 * (x1 - x0), y0 + 0.9 * (y1 - y0)]}


def body(field: str, value, frame: str | None) -> dict:
    """A request valid but for ``field`` = ``value``, where that field is read."""
    if field == "map":
        return {"map": value, "start": [1, 1], "goal": [2, 2]}
    if field.startswith("boundary["):
        i = int(field[-2])
        box = [0.0, 0.0, 0.01, 0.01]
        top = 180.0 if i % 2 == 0 else 90.0  # the box goes inwards from the value
        partner = value + 0.01 if i < 2 else value - 0.01
        box[i], box[(i + 2) % 4] = value, max(-top, min(top, partner))
        return zones(box)
    if frame is not None:
        return {**zones([0.0, 0.0, 0.01, 0.01]), "frame": frame, field: value}
    if field == "samples":
        return {**CITY_BODY, "algorithm": "prm", field: value}
    return {**CITY_BODY, field: value}


@pytest.fixture(scope="module")
def client():
    # samples up to the planner's own limit (the server's default is lower)
    with make_client(db_url="sqlite://", max_samples=10**9) as c:
        yield c


@pytest.fixture(autouse=True)
def small_roadmaps(monkeypatch):
    """PRM's check of the samples asked for (the planner's own), then a roadmap of a few
    (ten million would take minutes)."""
    real = world_plan.prm_roadmap

    def roadmap(world, *, samples=1000, neighbours=10, prm_star=False, seed=0):
        prm_options(samples, neighbours, prm_star, seed)
        return real(world, samples=min(samples, 50), neighbours=neighbours,
                    prm_star=prm_star, seed=seed)

    monkeypatch.setattr(world_plan, "prm_roadmap", roadmap)


VALIDATOR = jsonschema_rs.Draft202012Validator(
    {"$ref": "#/components/schemas/PlanRequest", "components": SPEC["components"]})


@pytest.mark.parametrize("field, key, bound, kind, frame", BOUNDS,
                         ids=[f"{f}-{k}" + (f"-{fr}" if fr else "")
                              for f, k, _, _, fr in BOUNDS])
def test_a_declared_bound_is_where_the_server_refuses(client, field, key, bound, kind,
                                                      frame):
    ok, bad = at_and_past(key, bound, kind)
    for value in ok:
        b = body(field, value, frame)
        assert VALIDATOR.is_valid(b), (field, value)
        r = client.post("/plan", json=b, headers=AUTH)
        named = {e["field"] for e in r.json().get("errors", ())} \
            if r.status_code == 422 else set()
        assert r.status_code in (200, 422) and field not in named, (value, r.text)
    for value in bad:
        b = body(field, value, frame)
        assert not VALIDATOR.is_valid(b), (field, value)
        doc = assert_problem(client.post("/plan", json=b, headers=AUTH), 422)
        assert field in {e["field"] for e in doc["errors"]}, (value, doc)
