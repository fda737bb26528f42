"""The ILP step drone: every move legal under an independent re-check; fewest moves."""

import functools
import json
import math
from collections import deque

import numpy as np
import pytest
import shapely
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

import skyroute
from skyroute.motion.step_drone import HOVER, STEP, Flight, follow, plan_moves
from skyroute.search import interrupt
from tests.conftest import SHARED

ILP = SHARED / "ilp2021"
pytestmark = pytest.mark.shared_data
AT = (-3.186874, 55.944494)
AREA = (-3.192473, 55.942617, -3.184319, 55.946233)


@pytest.fixture(scope="module")
def world():
    return skyroute.load_world(ILP / "website/buildings/no-fly-zones.geojson", frame="degrees",
                               boundary=ILP / "testing/confinement-zone.geojson")


@pytest.fixture(scope="module")
def places():
    d = json.loads((ILP / "testing/all.geojson").read_text())
    return {f["properties"]["name"]: tuple(f["geometry"]["coordinates"])
            for f in d["features"] if f["geometry"]["type"] == "Point"}


def zones():
    d = json.loads((ILP / "website/buildings/no-fly-zones.geojson").read_text())
    return [shapely.geometry.shape(f["geometry"]) for f in d["features"]]


def assert_legal(flight: Flight, start):
    """SPEC 4.2-4.3, checked from the raw rows with shapely and nothing of skyroute's."""
    polys = zones()
    prev = np.asarray(start, dtype=float)
    for f_lon, f_lat, angle, t_lon, t_lat in flight.rows():
        assert (f_lon, f_lat) == tuple(prev), "moves must chain"
        if angle == HOVER:
            assert (t_lon, t_lat) == (f_lon, f_lat)
        else:
            assert angle % 10 == 0 and 0 <= angle <= 350
            assert math.hypot(t_lon - f_lon, t_lat - f_lat) == pytest.approx(STEP, abs=1e-12)
            expect = (f_lon + STEP * math.cos(math.radians(angle)),
                      f_lat + STEP * math.sin(math.radians(angle)))
            assert (t_lon, t_lat) == pytest.approx(expect, abs=1e-15)
        assert AREA[0] < t_lon < AREA[2] and AREA[1] < t_lat < AREA[3]
        line = shapely.LineString([(f_lon, f_lat), (t_lon, t_lat)]) if angle != HOVER \
            else shapely.Point(t_lon, t_lat)
        assert not any(p.intersects(line) for p in polys)
        prev = np.array([t_lon, t_lat])


@pytest.mark.parametrize("name", ["Soderberg Cafe", "Bing Tea", "The Nile Valley",
                                  "Beirut Restaurant"])
def test_plan_moves_from_appleton_tower_is_legal_and_arrives(world, places, name):
    flight = plan_moves(world, AT, places[name])
    assert flight.status is skyroute.Status.FOUND
    assert_legal(flight.hover(), AT)
    assert math.dist(flight.end, places[name]) < STEP
    theta = skyroute.plan(world, AT, places[name], algorithm="theta")
    flown = follow(world, theta.path)
    assert flown.status is skyroute.Status.FOUND
    assert_legal(flown, AT)
    assert flight.moves <= flown.moves


@pytest.mark.parametrize("scale", [1 / 20, 1 / 10, 1 / 4, 3])
def test_follow_flies_a_path_with_any_step(world, places, scale):
    # follow's loop test kept spots a third of the ILP step wide whatever the step, so
    # with step < STEP / 3 every move landed on a spot already flown: no_path after 1
    step = STEP * scale
    goal = places["Soderberg Cafe"]
    path = skyroute.plan(world, AT, goal, algorithm="theta").path
    flown = follow(world, path, step=step)
    assert flown.status is skyroute.Status.FOUND
    assert math.dist(flown.end, goal) < step
    hops = np.hypot(*(flown.to - flown.frm).T)
    assert np.allclose(hops, step, rtol=0, atol=1e-12) and np.all(flown.angle % 10 == 0)
    segs = shapely.linestrings(np.stack([flown.frm, flown.to], axis=1))
    assert not shapely.intersects(segs, shapely.union_all(zones())).any()


def bfs_moves(world, start, target, limit):
    """Fewest moves by breadth-first search in move space (no heuristic)."""
    angles = np.radians(np.arange(0, 360, 10))
    deltas = STEP * np.c_[np.cos(angles), np.sin(angles)]
    start = np.asarray(start, dtype=float)
    seen = {(round(start[0] / 1e-9), round(start[1] / 1e-9))}
    frontier = deque([(start, 0)])
    while frontier:
        p, d = frontier.popleft()
        if math.dist(p, target) < STEP:
            return d
        if d >= limit:
            continue
        nxt = p + deltas
        ok = world.segments_clear(np.broadcast_to(p, nxt.shape), nxt)
        for q in nxt[ok]:
            key = (round(q[0] / 1e-9), round(q[1] / 1e-9))
            if key not in seen:
                seen.add(key)
                frontier.append((q, d + 1))
    return None


def test_plan_moves_is_fewest_moves(world):
    target = (AT[0] - 2.6 * STEP, AT[1] + 1.3 * STEP)
    flight = plan_moves(world, AT, target)
    assert flight.moves == bfs_moves(world, AT, target, 4) == 2


@pytest.mark.parametrize("leg", [("Soderberg Cafe", "Appleton Tower"), ("Bing Tea", "Rudis"),
                                 ("Rudis", "The Nile Valley")])
def test_default_merge_loses_no_move_against_exact_search(world, places, leg):
    """On these legs a 1e-5 lattice flies one move more; the default must not."""
    exact = plan_moves(world, places[leg[0]], places[leg[1]], merge=1e-9)
    assert exact.status is skyroute.Status.FOUND
    assert plan_moves(world, places[leg[0]], places[leg[1]]).moves == exact.moves


def _sees(polys, p, q) -> bool:
    line = shapely.LineString([p, q])
    return not any(line.relate_pattern(z, "T********") for z in polys)


@functools.cache
def _corner_graph():
    """The zone vertices and the networkx graph of those that see each other (built once:
    the zones never change, only the two end points do)."""
    import networkx as nx

    polys = zones()
    corners = [c for p in polys for c in p.exterior.coords[:-1]]
    g = nx.Graph()
    g.add_nodes_from(range(len(corners)))
    for i, p in enumerate(corners):
        for j in range(i + 1, len(corners)):
            if _sees(polys, p, corners[j]):
                g.add_edge(i, j, weight=math.dist(p, corners[j]))
    return polys, corners, g


def shortest_distance(a, b):
    """Obstacle-avoiding distance by networkx over a shapely visibility graph of every
    zone vertex and the two points (lines may touch zones, not enter them)."""
    import networkx as nx

    polys, corners, g = _corner_graph()
    g = g.copy()
    ends = {"a": tuple(a), "b": tuple(b)}
    for name, p in ends.items():
        for j, c in enumerate(corners):
            if _sees(polys, p, c):
                g.add_edge(name, j, weight=math.dist(p, c))
    if _sees(polys, ends["a"], ends["b"]):
        g.add_edge("a", "b", weight=math.dist(ends["a"], ends["b"]))
    return nx.dijkstra_path_length(g, "a", "b")


@settings(max_examples=25, deadline=None)
@given(st.floats(0.02, 0.98), st.floats(0.02, 0.98), st.sampled_from(range(14)))
def test_heuristic_never_exceeds_the_moves_left(world, places, u, v, k):
    """A*'s bound stays at or below ceil(D / step - 1), D the true shortest distance."""
    from skyroute.motion import move_search
    from skyroute.motion.step_drone import DistanceBound, _zones

    q = np.array([AREA[0] + u * (AREA[2] - AREA[0]), AREA[1] + v * (AREA[3] - AREA[1])])
    assume(world.blocking([q])[0] < 0)
    t = np.array(list(places.values())[k])
    table = DistanceBound(world, t)
    sees = bool(world.segments_free([q], [t])[0])
    z = _zones(world)
    h = move_search.bound(q[0], q[1], sees, t[0], t[1], table.cols, table.dist,
                          z[0], *z[4:], STEP)
    d = shortest_distance(q, t)
    assert h <= max(0, math.ceil(d / STEP - 1 + 1e-9))


def _area_point(u, v):
    return (AREA[0] + u * (AREA[2] - AREA[0]), AREA[1] + v * (AREA[3] - AREA[1]))


@settings(max_examples=20, deadline=None)
@given(st.floats(0.02, 0.98), st.floats(0.02, 0.98), st.floats(0.02, 0.98),
       st.floats(0.02, 0.98), st.sampled_from([None, 0, 1, 2, 3, 4]))
# a start just outside a zone, near its centroid: the goal mirrored through the centroid
# is 0.76 steps away across the zone (close: 0 moves) and 5.06 steps round it
@example(u0=0.390625, v0=0.5625, u1=0.5, v1=0.5, behind=2)
def test_every_move_between_random_points_is_legal(world, u0, v0, u1, v1, behind):
    """Every flown move legal (assert_legal: shapely on the raw rows) from and to random
    free points of the area, not only the four legs from Appleton Tower; the flight
    ends within a step of the goal and is never fewer moves than the obstacle-avoiding
    distance (networkx) allows: its moves are a free path to its end, so they cover at
    least the way round the zones to the goal less the way from the end to the goal.
    (The end is within a step of the goal in a straight line, which may cross a zone:
    the bound "the way to the goal less one step" failed on such a pair.)"""
    start, goal = _area_point(u0, v0), _area_point(u1, v1)
    polys = zones()
    if behind is not None:  # the goal mirrored through a zone's centre: the straight
        # line is blocked (random goals: 17 of 20 flights saw their goal from the start)
        c = polys[behind].centroid
        goal = (2 * c.x - start[0], 2 * c.y - start[1])
        assume(AREA[0] < goal[0] < AREA[2] and AREA[1] < goal[1] < AREA[3])
    assume(not any(z.intersects(shapely.Point(p)) for z in polys for p in (start, goal)))
    flight = plan_moves(world, start, goal)
    assert flight.status is skyroute.Status.FOUND  # the zones enclose no free pocket
    assert_legal(flight.hover(), start)
    assert math.dist(flight.end, goal) < STEP
    assert flight.moves * STEP > shortest_distance(start, goal) - \
        shortest_distance(flight.end, goal) - 1e-12


HARD = (_area_point(0.75, 0.75), _area_point(0.1875, 0.5))


def test_a_pair_past_200000_expansions_is_found_within_the_default_budget(world):
    # The way west between the buildings is 31.35 steps long but no flight of steps
    # passes it; the fewest moves go round (36), and A* must expand every state with
    # f < 36 first: 215,220 expansions. The default budget was 200,000
    # (budget_exhausted); it is now every state of the area's merge lattice.
    start, goal = HARD
    flight = plan_moves(world, start, goal)
    assert flight.status is skyroute.Status.FOUND
    assert flight.expanded > 200_000
    assert_legal(flight.hover(), start)
    assert math.dist(flight.end, goal) < STEP
    assert flight.moves * STEP > shortest_distance(start, goal) - STEP - 1e-12


def test_default_budget_is_every_state_of_a_bounded_world(world):
    from skyroute.motion.step_drone import MERGE, UNBOUNDED_BUDGET, default_budget

    assert default_budget(world) >= (AREA[2] - AREA[0]) / MERGE * (AREA[3] - AREA[1]) / MERGE
    assert default_budget(_grid_city(2)) == UNBOUNDED_BUDGET  # no boundary: no such count
    tiny = plan_moves(world, AT, (-3.1913, 55.9455), max_expansions=None)
    assert tiny.found


def test_a_budget_beyond_an_int64_is_no_budget():
    # as errors.budget reads it for every planner; plan_moves passed it to its compiled
    # search as given, which raised numba's OverflowError ("int too big to convert")
    w = _degrees_square()
    s, t = (-3.19, 55.943), (-3.186, 55.9448)
    ref = plan_moves(w, s, t)
    assert ref.found and ref.moves > 20
    for huge in (2**63, 10**30):
        f = plan_moves(w, s, t, max_expansions=huge)
        assert f.found and f.expanded == ref.expanded and f.rows() == ref.rows()


def _interrupted(world, monkeypatch, handler):
    """plan_moves on the HARD pair with ``handler`` as SIGINT's and a SIGINT as its
    search starts (tests/search/sigint.py)."""
    from skyroute.motion import move_search
    from tests.search.sigint import interrupted

    plan_moves(world, AT, (-3.1913, 55.9455))  # compiled and the corner table built
    return interrupted(monkeypatch, move_search, lambda: plan_moves(world, *HARD), handler)


def test_ctrl_c_stops_a_long_search_inside_the_compiled_loop_and_frees_it(world,
                                                                          monkeypatch):
    """The compiled search polls every 4,096 expansions; SIGINT's handler runs once the
    search has returned (:data:`interrupt.INTERRUPTED`), so its exception is raised
    from Python, not through the compiled frames: raised there (the handler ran in the
    poll) it left the search's arrays allocated, about 25 MB a Ctrl-C a few seconds in."""
    class SigintError(Exception):
        pass

    def handler(signum, frame):
        raise SigintError

    out, statuses, (allocs, frees) = _interrupted(world, monkeypatch, handler)
    assert isinstance(out, SigintError)
    assert allocs > 0 and frees == allocs
    assert statuses == [interrupt.INTERRUPTED]  # stopped inside, not run to its end


def test_a_sigint_handler_that_does_not_raise_lets_the_search_end(world, monkeypatch):
    """A handler that returns (as the CLI's does for a second Ctrl-C while the first one
    unwinds) did not stop the search when it ran in the poll; the search cut short for it
    is run again, and the flight found."""
    calls = []
    out, statuses, _ = _interrupted(world, monkeypatch, lambda signum, frame: calls.append(1))
    assert calls == [1]
    assert statuses == [interrupt.INTERRUPTED, skyroute.result.FOUND]
    assert out.found and out.moves == 36


def test_statuses_and_bad_frame(world):
    inside_zone = (-3.188896, 55.944913)  # Teviot's centroid
    assert world.names[world.blocking([inside_zone])[0]] == "Teviot"
    with pytest.raises(skyroute.QueryError):
        plan_moves(world, inside_zone, AT)
    budget = plan_moves(world, AT, (-3.1913, 55.9455), max_expansions=3)
    assert budget.status is skyroute.Status.BUDGET_EXHAUSTED and budget.moves == 0
    metres = skyroute.load_world(ILP / "website/buildings/no-fly-zones.geojson")
    with pytest.raises(skyroute.OptionError, match="degrees"):
        plan_moves(metres, (0, 0), (1, 1))


def test_compiled_move_test_is_never_more_permissive_than_shapely(world):
    from skyroute.motion.step_drone import ANGLES, _zones
    from skyroute.motion.zone_kernels import expand

    rad = np.radians(ANGLES)
    deltas = STEP * np.c_[np.cos(rad), np.sin(rad)]
    rng = np.random.default_rng(9)
    points = []
    for poly in world.obstacles:  # near every zone, where the edge cases are
        ring = poly.buffer(STEP * 0.7).exterior
        for f in rng.uniform(0, 1, 60):
            q = np.array(ring.interpolate(f, normalized=True).coords[0]) + \
                rng.normal(0, STEP * 0.3, 2)
            if world.is_free([q])[0]:
                points.append(q)
    assert len(points) > 100
    for p in points:
        clear, _ = expand(p[0], p[1], deltas, AT[0], AT[1], *_zones(world), 1e-12)
        nxt = p + deltas
        ref = world.segments_clear(np.broadcast_to(p, nxt.shape), nxt)
        assert not np.any(clear & ~ref)
        assert np.array_equal(clear, ref)


def test_flight_repr_counts_moves_and_hovers():
    p = np.array([-3.19, 55.94])
    flight = Flight(p[None], np.array([HOVER]), p[None].copy()).hover()
    assert repr(flight) == "<Flight found, 2 moves (2 hovers), 0 expanded, 0 ms>"


def _degrees_square() -> skyroute.World:
    """One zone in a small confinement box, in the degrees frame (no shared data)."""
    return skyroute.World([shapely.box(-3.1885, 55.9440, -3.1875, 55.9445)], [0], [50],
                          ("zone",), shapely.box(-3.192, 55.942, -3.184, 55.946), "degrees")


@pytest.mark.parametrize("kw", [{"step": 0}, {"step": "x"}, {"step": math.nan},
                                {"step": -STEP}, {"max_expansions": "5"},
                                {"max_expansions": 5.5},
                                {"max_expansions": -1}, {"merge": "x"}])
def test_plan_moves_names_a_bad_option(kw):
    # step=0 was a ZeroDivisionError, "5" a numba TypingError, NaN and -STEP "no_path"
    (name, _), = kw.items()
    with pytest.raises(skyroute.OptionError, match=f"{name}="):
        plan_moves(_degrees_square(), (-3.1890, 55.9442), (-3.1870, 55.9442), **kw)


@pytest.mark.parametrize("kw", [{"step": 0}, {"step": "x"}, {"max_moves": "5"},
                                {"max_moves": -1}])
def test_follow_names_a_bad_option(kw):
    (name, _), = kw.items()
    with pytest.raises(skyroute.OptionError, match=f"{name}="):
        follow(_degrees_square(), [(-3.1890, 55.9442), (-3.1870, 55.9442)], **kw)


@pytest.mark.parametrize("path", [[], [(1, 2, 3)], [(-3.1890, 55.9442), (math.nan, 55.9)],
                                  "ab"])
def test_follow_refuses_a_path_that_is_not_lon_lat_points(path):
    # [] was an IndexError, (N, 3) a reshape error, NaN a silent "no_path"
    with pytest.raises(skyroute.QueryError, match="path"):
        follow(_degrees_square(), path)


def test_step_drone_takes_numpy_numbers():
    w = _degrees_square()
    s, t = (-3.1890, 55.9442), (-3.1870, 55.9442)
    a = plan_moves(w, np.array(s), t, step=np.float64(STEP), max_expansions=np.int64(10**5))
    b = plan_moves(w, s, t)
    assert a.found and a.moves == b.moves
    assert follow(w, np.array([s, t]), max_moves=np.int64(100)).found


@pytest.mark.parametrize("offset", [0.0, STEP / 2])
def test_a_goal_within_a_step_is_no_moves_ending_at_the_start(offset):
    # found with no moves, but the flight's end was (nan, nan): hover() then wrote a
    # hover row of NaNs (found by test_every_move_between_random_points_is_legal)
    w = _degrees_square()
    s = (-3.1890, 55.9442)
    for flight in (plan_moves(w, s, (s[0] + offset, s[1])),
                   follow(w, [s, (s[0], s[1] + offset)])):
        assert flight.found and flight.moves == 0
        assert flight.end.tolist() == list(s)
        assert flight.hover().rows() == [[*s, HOVER, *s]]
        assert flight.then(plan_moves(w, s, (-3.1870, 55.9442))).end.tolist() != list(s)
    with pytest.raises(skyroute.QueryError, match="at="):
        Flight(np.empty((0, 2)), np.empty(0, int), np.empty((0, 2))).hover()


def _grid_city(k: int) -> skyroute.World:
    """k x k boxes of 1e-4 degrees, 3e-4 apart: 4 k^2 corners, more pairs than the step
    drone tests one by one."""
    from skyroute.world.world import World

    boxes = [shapely.box(AT[0] + 3e-4 * a, AT[1] + 3e-4 * b, AT[0] + 3e-4 * a + 1e-4,
                         AT[1] + 3e-4 * b + 1e-4) for a in range(k) for b in range(k)]
    n = len(boxes)
    return World(np.array(boxes, dtype=object), np.full(n, -np.inf), np.full(n, np.inf),
                 tuple(f"box {i}" for i in range(n)), None, "degrees")


def test_a_city_of_corners_plans_from_the_visibility_graphs_table(monkeypatch):
    # The corner table tested every pair of corners with shapely: the FCND city's 3,534
    # corners (6.2 million pairs) ran 45 minutes and took 3 GB before the first move.
    import skyroute.motion.step_drone as sd
    from skyroute.world.world import World

    start, goal = (AT[0] - 2e-4, AT[1] - 2e-4), (AT[0] + 2.8e-3, AT[1] + 2.6e-3)
    tested = []
    real_free = World.segments_free

    def counting(self, a, b):
        tested.append(len(np.atleast_2d(a)))
        return real_free(self, a, b)

    monkeypatch.setattr(World, "segments_free", counting)
    city = _grid_city(9)
    corners, vertices = 4 * 81, 5 * 81
    assert vertices * (vertices - 1) // 2 > sd.MAX_PAIRS
    flight = plan_moves(city, start, goal)
    assert flight.status is skyroute.Status.FOUND
    assert sum(tested) < corners * (corners - 1) // 20  # no pair-by-pair table
    monkeypatch.setattr(sd, "MAX_PAIRS", 10**9)  # the pair-by-pair table, as before
    exact = plan_moves(_grid_city(9), start, goal)
    assert flight.moves == exact.moves
    lines = shapely.linestrings(np.stack([flight.frm, flight.to], axis=1))
    boxes = city.obstacles[None, :]
    assert (shapely.length(shapely.intersection(lines[:, None], boxes)) < 1e-12).all()
