"""``POST /plan``: the same answer as :func:`skyroute.plan` on the same query (bundled
maps, uploaded map text, the shipped city world, GeoJSON zones), the server's budget,
and every bad input as a 422 naming its field."""

from __future__ import annotations

import json
import threading

import numpy as np
import pytest

import skyroute
from skyroute.world.load import bundled_maps
from skyroute.world.movingai import read_scen
from tests.conftest import ROOT
from tests.service.conftest import AUTH, make_client
from tests.service.test_app import assert_problem

CITY = ROOT / "examples" / "city.csv"
CITY_LONLAT = ((-3.1890, 55.9456), (-3.1850, 55.9432))
DEN = {"map": "den312d", "start": [50, 76], "goal": [60, 13]}


def same(answer: dict, r: skyroute.PlanResult) -> None:
    """The service's answer is the planner's result (all but the timing)."""
    want = r.to_dict()
    for key in ("status", "cost", "path", "expanded", "max_frontier", "los_checks",
                "algorithm"):
        assert answer[key] == want[key], key
    if "path_lonlat" in want:
        assert answer["path_lonlat"] == want["path_lonlat"]


@pytest.mark.parametrize("options", [
    {}, {"algorithm": "dijkstra"}, {"algorithm": "bfs"}, {"algorithm": "jps"},
    {"algorithm": "theta"}, {"algorithm": "lazy_theta", "prune": "los"},
    {"algorithm": "astar", "weight": 1.5, "corner_cutting": True},
    {"algorithm": "astar", "connectivity": 4, "heuristic": "manhattan"},
])
def test_bundled_map_equals_plan(client, options):
    r = client.post("/plan", json={**DEN, **options}, headers=AUTH)
    assert r.status_code == 200, r.text
    a = r.json()
    same(a, skyroute.plan(skyroute.load_map("den312d"), (50, 76), (60, 13), **options))
    assert a["max_expansions"] == 2_000_000 and a["seconds"] > 0
    feature = a["geojson"]["features"][0]
    assert feature["geometry"]["coordinates"][0] == [50.5, 76.5]  # cell centre, metres
    assert "wait;dur=" in r.headers["server-timing"] and "plan;dur=" in r.headers[
        "server-timing"]


def test_512_map_scenario_lines_equal_plan_and_the_optimum(client):
    grid = skyroute.load_map("Paris_1_512")
    scen = read_scen(str(bundled_maps()["Paris_1_512"]) + ".scen")
    for i in (0, 950, len(scen) - 1):
        s, g = scen.starts[i].tolist(), scen.goals[i].tolist()
        r = client.post("/plan", json={"map": "Paris_1_512", "start": s, "goal": g,
                                       "geojson": False}, headers=AUTH)
        a = r.json()
        same(a, skyroute.plan(grid, tuple(s), tuple(g)))
        assert scen.matches(i, a["cost"]) and a["geojson"] is None


def test_map_text_equals_the_file(client):
    text = bundled_maps()["den312d"].read_text()
    r = client.post("/plan", json={"map_text": text, "start": [50, 76], "goal": [60, 13]},
                    headers=AUTH)
    same(r.json(), skyroute.plan(skyroute.load_map("den312d"), (50, 76), (60, 13)))


@pytest.mark.parametrize("frame, options", [
    ("lonlat", {}),
    ("ned", {}),
    ("lonlat", {"algorithm": "astar", "resolution": 2.0}),
    ("enu", {"algorithm": "prm", "samples": 300, "seed": 3}),
])
def test_city_world_equals_plan(client, frame, options):
    world = skyroute.load_world(CITY, altitude=10, safety=2, frame="lonlat")
    a, b = CITY_LONLAT
    if frame != "lonlat":  # the same two places, given in the frame
        w = world.in_frame(frame)
        a, b = (w.from_plane(world.to_plane([p], "p"))[0].tolist() for p in (a, b))
    body = {"world_text": CITY.read_text(), "world_format": "colliders", "frame": frame,
            "altitude": 10, "safety": 2, "start": list(a), "goal": list(b), **options}
    r = client.post("/plan", json=body, headers=AUTH)
    assert r.status_code == 200, r.text
    ans = r.json()
    w = skyroute.load_world(CITY, altitude=10, safety=2, frame=frame)
    want = skyroute.plan(w, tuple(a), tuple(b), **options)
    same(ans, want)
    assert ans["frame"] == frame and want.found
    assert len(ans["waypoints"]) == len(ans["path"]) and ans["waypoints"][0][2] == 10.0
    coords = ans["geojson"]["features"][0]["geometry"]["coordinates"]
    assert np.allclose(coords, ans["path_lonlat"])


def test_prm_on_a_world_with_nothing_in_the_way(client):
    """An altitude above every building and no boundary: PRM answers the straight
    segment, as skyroute.plan does (it was a 422 naming no field)."""
    a, b = CITY_LONLAT
    body = {**CITY_BODY, "world_text": CITY.read_text(), "altitude": 1000,
            "algorithm": "prm", "samples": 300, "seed": 3}
    r = client.post("/plan", json=body, headers=AUTH)
    assert r.status_code == 200, r.text
    w = skyroute.load_world(CITY, altitude=1000, safety=2, frame="lonlat")
    want = skyroute.plan(w, a, b, algorithm="prm", samples=300, seed=3)
    same(r.json(), want)
    assert r.json()["status"] == "found" and r.json()["path"] == [list(a), list(b)]


def test_geojson_zones_world(client):
    zones = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {"name": "block"},
         "geometry": {"type": "Polygon", "coordinates": [[[0.001, -0.001], [0.002, -0.001],
                                                          [0.002, 0.001], [0.001, 0.001],
                                                          [0.001, -0.001]]]}}]}
    body = {"world_text": json.dumps(zones), "world_format": "geojson",
            "boundary": [-0.01, -0.01, 0.01, 0.01], "start": [0.0, 0.0], "goal": [0.003, 0.0]}
    ans = client.post("/plan", json=body, headers=AUTH).json()
    path = ROOT / "zones.geojson"
    try:
        path.write_text(json.dumps(zones))
        w = skyroute.load_world(path, boundary="-0.01,-0.01,0.01,0.01")
    finally:
        path.unlink()
    same(ans, skyroute.plan(w, (0.0, 0.0), (0.003, 0.0)))
    assert ans["status"] == "found" and ans["cost"] > 300  # metres round the block


def test_geojson_zones_with_heights_in_degrees(client):
    # [lon, lat, alt] vertices: the degrees frame's visibility graph failed on them (500)
    ring = [[0.001, -0.001], [0.002, -0.001], [0.002, 0.001], [0.001, 0.001], [0.001, -0.001]]
    def body(coords):
        zones = {"type": "FeatureCollection", "features": [
            {"type": "Feature", "properties": {"name": "block"},
             "geometry": {"type": "Polygon", "coordinates": [coords]}}]}
        return {"world_text": json.dumps(zones), "world_format": "geojson",
                "frame": "degrees", "boundary": [-0.01, -0.01, 0.01, 0.01],
                "start": [0.0, 0.0], "goal": [0.003, 0.0]}
    flat = client.post("/plan", json=body(ring), headers=AUTH).json()
    high = client.post("/plan", json=body([[*p, 30.0] for p in ring]), headers=AUTH)
    assert high.status_code == 200, high.text
    assert high.json()["status"] == "found" and high.json()["cost"] == flat["cost"]


def test_the_servers_budget_caps_each_request(tmp_path):
    with make_client(max_expansions=50) as c:
        a = c.post("/plan", json=DEN, headers=AUTH).json()
        assert a["status"] == "budget_exhausted" and a["max_expansions"] == 50
        assert a["cost"] is None and a["path"] == [] and a["expanded"] == 50
        a = c.post("/plan", json={**DEN, "max_expansions": 10**9}, headers=AUTH).json()
        assert a["max_expansions"] == 50  # asked for more: still the cap
        a = c.post("/plan", json={**DEN, "max_expansions": 7}, headers=AUTH).json()
        assert a["max_expansions"] == 7 and a["expanded"] == 7  # a lower one is kept


def test_no_path_is_a_status(client):
    text = "type octile\nheight 3\nwidth 5\nmap\n..@..\n..@..\n..@..\n"
    a = client.post("/plan", json={"map_text": text, "start": [0, 0], "goal": [4, 2]},
                    headers=AUTH).json()
    assert a["status"] == "no_path" and a["cost"] is None and a["path"] == []


CITY_BODY = {"world_format": "colliders", "altitude": 10, "safety": 2,
             "start": list(CITY_LONLAT[0]), "goal": list(CITY_LONLAT[1])}


@pytest.mark.parametrize("body, field, words", [
    ({"start": [50, 76], "goal": [60, 13]}, "body", "exactly one of map, map_text and "
                                                    "world_text"),
    ({**DEN, "map_text": "x"}, "body", "got map, map_text"),
    ({**DEN, "map": "atlantis"}, "map", "Input should be 'Berlin_1_256'"),
    ({**DEN, "start": [0, 0]}, "start", "on a blocked cell"),
    ({**DEN, "goal": [600, 13]}, "goal", "outside the 65x81 grid"),
    ({**DEN, "goal": [13, 60]}, "goal", "blocked cell; (60, 13) is free: cells are (x, y)"),
    ({**DEN, "start": [50.5, 76]}, "start", "two integers"),
    ({**DEN, "start": [50]}, "start[1]", "Field required"),
    ({**DEN, "start": [50, "north"]}, "start[1]", "valid number"),
    ({**DEN, "algorithm": "magic"}, "algorithm", "'astar'"),
    ({**DEN, "algorithm": "visibility"}, "algorithm", "choose one of"),
    ({**DEN, "weight": 0.5}, "weight", "greater than or equal to 1"),
    ({**DEN, "connectivity": 6}, "connectivity", "4 or 8"),
    ({**DEN, "algorithm": "dijkstra", "weight": 2}, "weight", "takes no weight"),
    ({**DEN, "algorithm": "bfs", "heuristic": "octile"}, "heuristic", "takes no heuristic"),
    ({**DEN, "algorithm": "bfs", "connectivity": 8}, "connectivity", "is 4-connected"),
    ({**DEN, "algorithm": "jps", "weight": 2}, "weight", "takes no weight"),
    ({**DEN, "algorithm": "jps", "heuristic": "manhattan"}, "heuristic", "no heuristic"),
    ({**DEN, "algorithm": "jps", "corner_cutting": True}, "corner_cutting",
     "needs connectivity=8 and no corner cutting"),
    ({**CITY_BODY, "algorithm": "dijkstra", "weight": 2, "resolution": 2}, "weight",
     "takes no weight"),
    ({**DEN, "max_expansions": 0}, "max_expansions", "greater than or equal to 1"),
    ({**DEN, "corner_cuting": True}, "corner_cuting", "Extra inputs are not permitted"),
    ({"map_text": "type octile\nheight 1\nwidth 2\nmap\n.Q\n", "start": [0, 0],
      "goal": [1, 0]}, "map_text", "line 5: unknown terrain 'Q'"),
    ({"map_text": "", "start": [0, 0], "goal": [1, 0]}, "map_text", "empty"),
    # a header claiming 3 x 10**12 cells: numpy's MemoryError before, a 500
    ({"map_text": "type octile\nheight 3\nwidth 1000000000000\nmap\n..\n..\n..\n",
      "start": [0, 0], "goal": [1, 0]}, "map_text",
     "line 3: the header's map is 1,000,000,000,000 x 3 cells"),
    ({**CITY_BODY, "world_format": None, "world_text": "x"}, "body", "world_format"),
    ({**CITY_BODY, "world_text": "lat0 x\n"}, "world_text", "line 1: expected 'lat0"),
    ({**CITY_BODY, "world_text": "lat0 37.79, lon0 -122.39\nposX,posY,posZ,halfSizeX,"
      "halfSizeY,halfSizeZ\n4182912,553400,5,2,2,5\n"}, "world_text",
     "line 3: the box reaches 4,219.4 km from home, over the 50 km limit"),
    ({**CITY_BODY, "world_text": "{}", "world_format": "geojson"}, "world_text", ""),
    ({**CITY_BODY, "frame": "polar"}, "frame", "'lonlat'"),
    ({**CITY_BODY, "frame": "degrees"}, "frame", "in metres"),
    ({**CITY_BODY, "safety": -1}, "safety", "greater than or equal to 0"),
    # below the ground: it kept no building and planned straight through them
    ({**CITY_BODY, "altitude": -5}, "altitude", "greater than or equal to 0"),
    ({**CITY_BODY, "boundary": "/etc/passwd"}, "boundary", "valid"),
    ({**CITY_BODY, "boundary": [0, 0, -1, -1]}, "boundary", "min must be below max"),
    ({**CITY_BODY, "start": [-3.1890, 95.0]}, "start", ""),
    # typed (lat, lon) in a city with no boundary: it planned 7,800 km and said "found"
    ({**CITY_BODY, "start": CITY_LONLAT[0][::-1]}, "start", "is within it: points are"),
    ({**CITY_BODY, "goal": [-3.7038, 40.4168]}, "goal", "a world with no boundary reaches"),
    ({**CITY_BODY, "algorithm": "astar", "resolution": 0.001}, "resolution",
     "this server's limit"),
    ({**CITY_BODY, "algorithm": "prm", "samples": 10**6}, "samples", "limit of 20,000"),
    # a cell past the whole local plane: the schema's bound; a raster reaching past it:
    # the planner's (both answered "path (...) lies more than 1e+07 m from home", or a
    # path through far-off lon/lat, without naming resolution)
    ({**CITY_BODY, "algorithm": "astar", "resolution": 1e9}, "resolution",
     "less than or equal to 10000000"),
    ({**CITY_BODY, "algorithm": "theta", "resolution": 2e6}, "resolution",
     "makes a raster reaching 1.6e+07 m from home"),
])
def test_bad_input_is_422_naming_the_field(client, body, field, words):
    if "world_format" in body and "world_text" not in body:
        body = {**body, "world_text": CITY.read_text()}
    body = {k: v for k, v in body.items() if v is not None}
    assert_problem(client.post("/plan", json=body, headers=AUTH), 422, field, words)


@pytest.mark.parametrize("body, field, words", [
    ({**DEN, "start": ["50", "76"]}, "start[0]", "valid number"),
    ({**DEN, "goal": [60, True]}, "goal[1]", "valid number"),
    ({**DEN, "weight": "2"}, "weight", "valid number"),
    ({**DEN, "weight": True}, "weight", "valid number"),
    ({**DEN, "safety": "1"}, "safety", "valid number"),
    ({**DEN, "max_expansions": "100"}, "max_expansions", "valid integer"),
    ({**DEN, "max_expansions": 100.0}, "max_expansions", "valid integer"),
    ({**DEN, "max_expansions": True}, "max_expansions", "valid integer"),
    ({**DEN, "corner_cutting": "yes"}, "corner_cutting", "valid boolean"),
    ({**DEN, "corner_cutting": 1}, "corner_cutting", "valid boolean"),
    ({**DEN, "geojson": 0}, "geojson", "valid boolean"),
    ({**CITY_BODY, "altitude": "10"}, "altitude", "valid number"),
    ({**CITY_BODY, "boundary": ["-3.2", 55.9, -3.1, 56.0]}, "boundary[0]", "valid number"),
    ({**CITY_BODY, "algorithm": "prm", "samples": 100.0}, "samples", "valid integer"),
    ({**CITY_BODY, "algorithm": "prm", "seed": "3"}, "seed", "valid integer"),
    ({**CITY_BODY, "algorithm": "prm", "prm_star": "false"}, "prm_star", "valid boolean"),
])
def test_a_value_of_another_type_is_422_as_skyroute_plan_refuses_it(client, body, field,
                                                                     words):
    """A numeric string, a boolean as a number, a number as a boolean, 100.0 as a count:
    skyroute.plan refuses each (an OptionError naming it), so the service does too,
    rather than planning with what it guessed."""
    if "world_format" in body:
        body = {**body, "world_text": CITY.read_text()}
    assert_problem(client.post("/plan", json=body, headers=AUTH), 422, field, words)


def test_integers_for_numbers_and_whole_floats_for_cells_are_accepted(client):
    """JSON has one number type: 2 is a weight of 2.0, and 50.0 names cell 50 (as a
    JavaScript client may send it)."""
    want = client.post("/plan", json={**DEN, "weight": 2.0, "safety": 0.0},
                       headers=AUTH).json()
    got = client.post("/plan", json={**DEN, "start": [50.0, 76.0], "weight": 2,
                                     "safety": 0}, headers=AUTH)
    assert got.status_code == 200, got.text
    assert (got.json()["cost"], got.json()["path"]) == (want["cost"], want["path"])


def test_a_body_that_is_not_text_is_400(client):
    r = client.post("/plan", content=b'{"map": "\xff\xfe"}', headers={
        **AUTH, "Content-Type": "application/json"})
    assert_problem(r, 400, words="cannot be read as JSON text")


@pytest.mark.parametrize("text", [b"{not json", b'{"map":"den312d",}', b"[1, 2"])
def test_a_body_that_is_not_json_is_400(client, text):
    r = client.post("/plan", content=text, headers={**AUTH, "Content-Type":
                                                    "application/json"})
    doc = assert_problem(r, 400, words="the request body cannot be read as JSON text")
    assert "field" not in doc and "Expecting" in doc["detail"] and "at byte" in doc["detail"]


ZONE = {"type": "Feature", "properties": {"name": "block"}, "geometry": {
    "type": "Polygon", "coordinates": [[[0.001, -0.001], [0.002, -0.001], [0.002, 0.001],
                                        [0.001, -0.001]]]}}
ZONES_TEXT = json.dumps({"type": "FeatureCollection", "features": [ZONE]})


@pytest.mark.parametrize("extra, field, words", [
    # the escape in the request's own JSON: a str holding U+D800
    ({"map_text": "type octile\nheight 2\nwidth 2\nmap\n.\ud800\n..\n"}, "map_text",
     "map_text: line 5: not an ASCII text file"),
    ({"world_text": ZONES_TEXT.replace("block", "\ud800"), "world_format": "geojson"},
     "world_text", "world_text: feature 0: its name holds U+D800, half of a UTF-16"),
    # the escape inside the uploaded file's JSON, read by the GeoJSON reader
    ({"world_text": ZONES_TEXT.replace("block", "\\ud800"), "world_format": "geojson"},
     "world_text", "world_text: feature 0: its name holds U+D800"),
])
def test_a_lone_surrogate_in_an_upload_is_422(client, extra, field, words):
    """A lone surrogate (``"\\ud800"``, no character) in a map or a zone's name was a
    500: the map's text could not be encoded, the visibility graph's cache key neither
    (found probing a running server beside schemathesis, which sends no surrogates)."""
    body = {"start": [0, 0], "goal": [1, 1], **extra}
    if "world_text" in extra:
        body.update(start=[0.0, 0.0], goal=[0.003, 0.0])
    r = client.post("/plan", content=json.dumps(body).encode(),  # ASCII: the escape kept
                    headers={**AUTH, "Content-Type": "application/json"})
    assert_problem(r, 422, field, words)


def test_not_finite_is_422(client):
    r = client.post("/plan", content=b'{"map": "den312d", "start": [NaN, 1], "goal": [1, 1]}',
                    headers={**AUTH, "Content-Type": "application/json"})
    assert_problem(r, 422, "start[0]")


class WatchedLock:
    """The search slot, telling when a request starts to wait for it."""

    def __init__(self):
        self.lock = threading.Lock()
        self.waiting = threading.Event()

    def acquire(self, blocking=True, timeout=-1):
        if blocking:
            self.waiting.set()
        return self.lock.acquire(blocking, timeout)

    def release(self):
        self.lock.release()

    def __enter__(self):
        self.acquire()

    def __exit__(self, *exc):
        self.release()


def test_a_bundled_map_waits_for_the_search_slot_off_the_event_loop(client, monkeypatch):
    """While another search holds the slot, a bundled-map query waits on a pool thread
    and the loop goes on answering; when the slot is free it runs without a thread."""
    from skyroute.service.routers import plan as plan_router

    slot = WatchedLock()
    hops = []
    pool = plan_router.run_in_threadpool

    async def counted(*args):
        hops.append(args[0].__name__)
        return await pool(*args)

    monkeypatch.setattr(plan_router, "_SEARCH", slot)
    monkeypatch.setattr(plan_router, "run_in_threadpool", counted)
    want = client.post("/plan", json=DEN, headers=AUTH).json()
    assert want["status"] == "found" and hops == []  # idle: the fast path

    answers = {}
    slot.lock.acquire()  # another search holds the slot
    try:
        planner = threading.Thread(target=lambda: answers.update(
            plan=client.post("/plan", json=DEN, headers=AUTH)))
        planner.start()
        assert slot.waiting.wait(60), "the query never asked for the slot"
        health = threading.Thread(target=lambda: answers.update(
            health=client.get("/health")))
        health.start()
        health.join(60)  # a guard against a hung test, not a measure
        assert answers.get("health") is not None and answers["health"].status_code == 200
        assert "plan" not in answers  # still waiting for the slot
    finally:
        slot.lock.release()
    planner.join(60)
    r = answers["plan"]
    assert r.status_code == 200 and hops == ["_timed"]
    assert r.json()["path"] == want["path"] and "wait;dur=" in r.headers["server-timing"]


FAR_WEST = [-3.2216, 55.9430]  # free, about 2 km west of the city's obstacles


@pytest.mark.parametrize("extra, words", [
    # the obstacles alone make ~117k cells at 1 m; reaching start makes ~800k
    ({"resolution": 1, "start": FAR_WEST}, "resolution=1 makes a raster of"),
    # no resolution: the default one (~0.34 m here) makes ~1M cells
    ({}, "(the default for this world) makes a raster of"),
])
def test_the_raster_limit_counts_the_raster_that_would_be_built(extra, words):
    body = {**CITY_BODY, "world_text": CITY.read_text(), "algorithm": "astar", **extra}
    with make_client(max_raster_cells=200_000) as c:
        assert_problem(c.post("/plan", json=body, headers=AUTH), 422, "resolution", words)
        ok = {**CITY_BODY, "world_text": CITY.read_text(), "algorithm": "astar",
              "resolution": 1}
        assert c.post("/plan", json=ok, headers=AUTH).json()["status"] == "found"


def test_default_resolution_spans_the_points():
    from skyroute.roadmap.raster import default_resolution

    w = skyroute.load_world(CITY, altitude=10, safety=2)
    x0, y0, x1, y1 = w.bounds
    assert default_resolution(w) == max(x1 - x0, y1 - y0) / 1000
    far = w.to_plane([FAR_WEST])[0]
    inside = w.to_plane([CITY_LONLAT[0]])[0]
    assert default_resolution(w, [far, inside]) == (x1 - far[0]) / 1000


def test_a_world_too_large_for_the_visibility_graph_is_422(client, monkeypatch, tmp_path):
    from skyroute.roadmap import visibility

    monkeypatch.setenv("SKYROUTE_CACHE", str(tmp_path))  # not a graph an earlier test kept
    monkeypatch.setattr(visibility, "MAX_CORNERS", 20)
    body = {**CITY_BODY, "world_text": CITY.read_text()}
    assert_problem(client.post("/plan", json=body, headers=AUTH), 422, "algorithm",
                   "obstacle corners, over the limit of 20 for the visibility graph")
    many = "lat0 55.944494, lon0 -3.186874\nposX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n"
    body = {**body, "world_text": many + "1,1,1,1,1,1\n" * 50_001, "algorithm": "prm"}
    assert_problem(client.post("/plan", json=body, headers=AUTH), 422, "world_text",
                   "50,001 boxes, over the limit of 50,000 in a colliders file")


@pytest.mark.parametrize("options, field, words", [
    ({"resolution": 2}, "resolution", "applies to planning on a World"),
    ({"samples": 50}, "samples", "applies to planning on a World"),
    ({"seed": 3}, "seed", "applies to planning on a World"),
    ({"prm_star": True}, "prm_star", "applies to planning on a World"),
    ({"frame": "enu"}, "frame", "applies to a world (world_text)"),
    ({"altitude": 10}, "altitude", "applies to a world (world_text)"),
    ({"boundary": [0, 0, 10, 10]}, "boundary", "applies to a world (world_text)"),
])
def test_a_world_option_on_a_map_is_422(client, options, field, words):
    """As skyroute.plan refuses them on a Grid: an option the search would not read is an
    error naming it, not silently dropped."""
    assert_problem(client.post("/plan", json={**DEN, **options}, headers=AUTH), 422, field,
                   words)


@pytest.mark.parametrize("options, field", [
    ({"samples": 300}, "samples"),  # visibility, the default on a world
    ({"algorithm": "astar", "seed": 3}, "seed"),
    ({"algorithm": "prm", "resolution": 2}, "resolution"),
    ({"algorithm": "prm", "heuristic": "octile"}, "heuristic"),
    ({"weight": 1.5}, "weight"),
])
def test_an_option_the_world_algorithm_does_not_read_is_422(client, options, field):
    body = {**CITY_BODY, "world_text": CITY.read_text(), **options}
    assert_problem(client.post("/plan", json=body, headers=AUTH), 422, field,
                   "does not apply to algorithm=")


def test_null_options_count_as_not_given(client):
    body = {**DEN, "resolution": None, "altitude": None, "boundary": None,
            "geojson": False}
    assert client.post("/plan", json=body, headers=AUTH).status_code == 200
