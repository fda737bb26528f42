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
from skyroute.world.points import MAX_METRES
from tests.service.conftest import AUTH, TOKEN, make_client
from tests.service.test_app import assert_problem
from tests.service.test_plan import CITY, CITY_LONLAT

FRAMES = ("lonlat", "degrees", "ned", "local", "enu")
# the fields whose bounds the schema came to declare (each of its bounds is checked)
FIELDS = ("altitude", "safety", "samples", "boundary", "map")
# what it must declare of them (field, keyword, the frame it holds in)
DECLARED = {("altitude", "minimum", None), ("safety", "minimum", None),
            ("safety", "maximum", None), ("safety", "maximum", "degrees"),
            ("samples", "minimum", None), ("samples", "maximum", None),
            ("map", "enum", None),
            *((f"boundary[{i}]", k, None) for i in range(4) for k in ("minimum", "maximum")),
            # start and goal: cells on a map, points in the frame on a world
            *((f"{p}[{i}]", k, case) for p in ("start", "goal") for i in (0, 1)
              for case in ("map", *FRAMES) for k in ("minimum", "maximum")
              if (case, k) != ("map", "maximum"))}
# a server whose own limit on samples is past the planner's: the schema declares the
# planner's (test_samples_are_declared_up_to_this_servers_limit: a lower one)
SPEC = create_app(Settings(token=TOKEN, warm=False, db_url="sqlite://",
                           max_samples=10**9)).openapi()


def bounds(spec: dict) -> list[tuple[str, str, object, str, str | None]]:
    """(field as a 422 names it, keyword, bound, JSON type, case) of every bound the
    PlanRequest schema puts on :data:`FIELDS`, and of its ``if ... then`` ones (the case:
    the frame they hold in, or "map")."""
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
    for rule in plan.get("allOf", ()):
        for case in cases(rule["if"]):
            for name, sub in rule["then"]["properties"].items():
                walk(name, sub, plan["properties"][name].get("type"), case)
    return out


def cases(rule: dict) -> list[str]:
    """The frames an ``if`` holds for, or ["map"] (no world_text)."""
    frame = rule.get("properties", {}).get("frame")
    if frame is None:
        assert rule["properties"]["world_text"] == {"type": "null"}, rule
        return ["map"]
    return [frame["const"]] if "const" in frame else list(frame["enum"])


BOUNDS = bounds(SPEC)


def test_the_schema_declares_every_bound_the_server_holds():
    assert {(f, k, frame) for f, k, _, _, frame in BOUNDS} >= DECLARED


def _step(bound, kind: str, down: bool):
    if kind == "integer":
        return int(bound) - 1 if down else int(bound) + 1
    return math.nextafter(float(bound), -math.inf if down else math.inf)


def at_and_past(key: str, bound, kind: str, *, edge: bool = False) -> tuple[list, list]:
    """The values at the bound (accepted) and one step past it (refused). ``edge``: a
    point of a world at the bound lies on the world's edge, which is outside it, and a
    lon/lat's way through the local plane moves its last bits: the accepted value is
    1e-9 of the bound inside it."""
    if key == "enum":
        return list(bound), [bound[0] + ".map"]
    exact = int(bound) if kind == "integer" else float(bound)
    if edge:
        return [exact * (1 - 1e-9)], [_step(bound, kind, down=key == "minimum")]
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


MAP_TEXT = "type octile\nheight 3\nwidth 4\nmap\n....\n....\n....\n"  # all free


def _point(field: str, value, frame: str) -> dict:
    """A request whose ``start[i]`` or ``goal[i]`` is ``value``: a cell of a free map, or
    a point of a world in ``frame``: round a small zone near it (lon/lat), or metres from
    the home of a one-building city."""
    name, i = field[:-3], int(field[-2])
    if frame == "map":
        b = {"map_text": MAP_TEXT, "start": [0, 0], "goal": [3, 2]}
    else:
        top, size = ((180.0, 90.0)[i], 0.01) if frame in ("lonlat", "degrees") \
            else (MAX_METRES, 100.0)
        edge = math.copysign(top, value)  # a box inside that edge
        box = [0.0, 0.0, size, size]
        box[i], box[i + 2] = sorted((edge, edge - math.copysign(size, value)))
        b = zones(box) if top != MAX_METRES else colliders(box, frame)
        if frame != "lonlat":  # lonlat: the default, not given
            b["frame"] = frame
    b[name][i] = value
    return b


def colliders(box: list[float], frame: str) -> dict:
    """A colliders.csv world (metres, north and east of its home) of one building at home
    (a box lies within 50 km of it), start and goal at either end of ``box`` (in
    ``frame``: ned, local or enu)."""
    x0, y0, x1, y1 = box
    text = ("lat0 55.944494, lon0 -3.186874\nposX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n"
            "0,0,10,5,5,10\n")
    return {"world_format": "colliders", "world_text": text,
            "start": [x0 + 0.1 * (x1 - x0), y0 + 0.1 * (y1 - y0)],
            "goal": [x0 + 0.9 * (x1 - x0), y0 + 0.9 * (y1 - y0)]}


def body(field: str, value, frame: str | None) -> dict:
    """A request valid but for ``field`` = ``value``, where that field is read."""
    if field.startswith(("start", "goal")):
        return _point(field, value, frame)
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
    edge = field.startswith(("start", "goal")) and frame != "map"
    ok, bad = at_and_past(key, bound, kind, edge=edge)
    # a 422 names start or goal for either of its numbers
    names = {field, field[:-3]} if field.startswith(("start", "goal")) else {field}
    for value in ok:
        b = body(field, value, frame)
        assert VALIDATOR.is_valid(b), (field, value)
        r = client.post("/plan", json=b, headers=AUTH)
        named = {e["field"] for e in r.json().get("errors", ())} \
            if r.status_code == 422 else set()
        assert r.status_code in (200, 422) and not names & named, (value, r.text)
        if field.startswith(("start", "goal")):  # planned
            assert r.status_code == 200, (value, r.text)
    for value in bad:
        b = body(field, value, frame)
        assert not VALIDATOR.is_valid(b), (field, value)
        doc = assert_problem(client.post("/plan", json=b, headers=AUTH), 422)
        assert names & {e["field"] for e in doc["errors"]}, (value, doc)
        assert len(doc["detail"].splitlines()) == 1


def test_a_cell_on_a_map_is_declared_as_integers(client):
    """On a map start and goal are cells: the schema says integers (a whole float counts,
    in JSON Schema as on the server); on a world they are any numbers of the frame."""
    for name in ("start", "goal"):
        ok = {"map_text": MAP_TEXT, "start": [0, 0], "goal": [3, 2], name: [1.0, 2]}
        assert VALIDATOR.is_valid(ok)
        assert client.post("/plan", json=ok, headers=AUTH).status_code == 200
        bad = {**ok, name: [1.5, 2]}
        assert not VALIDATOR.is_valid(bad)
        assert_problem(client.post("/plan", json=bad, headers=AUTH), 422, name,
                       "a cell on a map is two integers")
    world = {**zones([0.0, 0.0, 0.01, 0.01]), "start": [0.0015, 0.0025]}
    assert VALIDATOR.is_valid(world)
    assert client.post("/plan", json=world, headers=AUTH).status_code == 200


def test_samples_are_declared_up_to_this_servers_limit(monkeypatch):
    """The schema's ``samples`` maximum was the planner's (1e7) on every server, whose
    own limit (``max_samples``, ``serve --max-samples``) is lower: 20,000 by default.
    It is the server's now, and so is the default when the limit is below the
    planner's 1000 (a PRM request without samples was refused for samples=1000)."""
    asked = []
    real = world_plan.prm_roadmap

    def roadmap(world, *, samples=1000, **kw):
        asked.append(samples)
        return real(world, samples=min(samples, 50), **kw)

    monkeypatch.setattr(world_plan, "prm_roadmap", roadmap)
    default = create_app(Settings(token=TOKEN, warm=False)).openapi()
    assert default["components"]["schemas"]["PlanRequest"]["properties"]["samples"][
        "maximum"] == Settings().max_samples == 20_000
    with make_client(db_url="sqlite://", max_samples=500) as c:
        spec = c.get("/openapi.json").json()
        samples = spec["components"]["schemas"]["PlanRequest"]["properties"]["samples"]
        assert (samples["maximum"], samples["default"]) == (500, 500)
        check = jsonschema_rs.Draft202012Validator(
            {"$ref": "#/components/schemas/PlanRequest", "components": spec["components"]})
        prm = {**CITY_BODY, "algorithm": "prm"}
        for n in (500, 499):
            assert check.is_valid({**prm, "samples": n})
            assert c.post("/plan", json={**prm, "samples": n}, headers=AUTH).status_code == 200
        assert not check.is_valid({**prm, "samples": 501})
        assert_problem(c.post("/plan", json={**prm, "samples": 501}, headers=AUTH), 422,
                       "samples", "samples=501 is over this server's limit of 500")
        assert check.is_valid(prm)
        assert c.post("/plan", json=prm, headers=AUTH).status_code == 200
    assert asked == [500, 499, 500]
