"""Turn-aware planning on a (cell, heading) lattice."""

import math

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import skyroute
from skyroute.motion.turn_lattice import plan_turns, travel_time
from tests.search.checks import assert_any_angle_path_legal, two_indices

SETTINGS = settings(max_examples=60, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow])


@st.composite
def grid_query(draw):
    h, w = draw(st.integers(2, 12)), draw(st.integers(2, 12))
    # every cell drawn (fill=nothing; with a fill most grids were all blocked or all
    # free), a quarter of them blocked (at a half most queries were no_path)
    blocked = draw(arrays(np.bool_, (h, w), elements=st.integers(0, 3).map(lambda v: v == 3),
                          fill=st.nothing()))
    free = np.argwhere(~blocked)
    if len(free) < 2:
        blocked[:] = False
        free = np.argwhere(~blocked)
    i, j = two_indices(draw, len(free))  # start != goal
    return blocked, (int(free[i][1]), int(free[i][0])), (int(free[j][1]), int(free[j][0]))


@SETTINGS
@given(grid_query(), st.floats(0.2, 5.0), st.sampled_from([8, 16]))
def test_never_slower_than_the_distance_optimal_path(q, rate, headings):
    blocked, s, t = q
    grid = skyroute.Grid(blocked)
    a = skyroute.plan(grid, s, t)
    r = plan_turns(grid, s, t, headings=headings, turn_rate=rate)
    assert r.found == a.found
    if a.found:
        assert r.time <= travel_time(a.path, turn_rate=rate) + 1e-9
        assert r.distance >= math.dist(s, t) - 1e-9
        assert_any_angle_path_legal(blocked, r.cells)


@SETTINGS
@given(grid_query())
def test_free_turning_gives_the_octile_optimum_and_16_never_loses(q):
    blocked, s, t = q
    grid = skyroute.Grid(blocked)
    a = skyroute.plan(grid, s, t)
    r8 = plan_turns(grid, s, t, headings=8, turn_rate=1e9)
    if a.found:
        assert abs(r8.time - a.cost) < 1e-6
        r8slow = plan_turns(grid, s, t, headings=8, turn_rate=0.7)
        r16slow = plan_turns(grid, s, t, headings=16, turn_rate=0.7)
        assert r16slow.time <= r8slow.time + 1e-9



def lattice_optimum(blocked, s, t, headings, speed, rate, first) -> float:
    """networkx's Dijkstra over (x, y, heading) states built here from the module's
    contract: forward one cell along the heading (8: no corner cutting; 16: knight moves
    by the exact segment test of tests/search/checks.py), a turn to either neighbouring
    heading costs its angle / rate; ``first`` fixes the start heading (index) or not."""
    import networkx as nx

    from skyroute.motion.turn_lattice import _DIRS
    from tests.search.checks import segment_legal

    dirs = _DIRS[headings]
    ang = [math.atan2(dy, dx) for dx, dy in dirs]
    h, w = blocked.shape
    g = nx.DiGraph()
    for y, x in np.argwhere(~blocked):
        x, y = int(x), int(y)
        for k, (dx, dy) in enumerate(dirs):
            for j in ((k + 1) % headings, (k - 1) % headings):
                g.add_edge((x, y, k), (x, y, j),
                           weight=abs(math.remainder(ang[j] - ang[k], 2 * math.pi)) / rate)
            u, v = x + dx, y + dy
            if not (0 <= u < w and 0 <= v < h) or blocked[v, u]:
                continue
            if abs(dx) == abs(dy) == 1 and (blocked[y, u] or blocked[v, x]):
                continue
            if abs(dx) + abs(dy) == 3 and not segment_legal(blocked, (x, y), (u, v)):
                continue
            g.add_edge((x, y, k), (u, v, k), weight=math.hypot(dx, dy) / speed)
    g.add_edges_from((("S", (*s, k)) for k in range(headings) if first in (None, k)),
                     weight=0.0)
    g.add_edges_from((((*t, k), "T") for k in range(headings)), weight=0.0)
    try:
        return nx.dijkstra_path_length(g, "S", "T")
    except (nx.NetworkXNoPath, nx.NodeNotFound):
        return math.inf


@SETTINGS
@given(grid_query(), st.sampled_from([8, 16]), st.sampled_from([0.4, 1.0, 3.0]),
       st.sampled_from([0.3, math.pi / 2, 6.0]), st.one_of(st.none(), st.integers(0, 15)))
@example((np.array([[1, 1, 1], [1, 0, 0]], bool), (1, 1), (2, 1)), 16, 1.0, math.pi / 2, 1)
def test_the_time_is_the_optimum_of_an_independent_lattice_and_counts_every_turn(
        q, headings, speed, rate, first):
    # no test compared the lattice's time with an optimum that prices turns, nor the
    # time it reports with its own route's (travel_time: the turns counted)
    from skyroute.motion.turn_lattice import _DIRS

    blocked, s, t = q
    first = None if first is None else first % headings
    start_heading = None if first is None else math.atan2(*_DIRS[headings][first][::-1])
    r = plan_turns(skyroute.Grid(blocked), s, t, headings=headings, speed=speed,
                   turn_rate=rate, start_heading=start_heading)
    optimum = lattice_optimum(blocked, s, t, headings, speed, rate, first)
    assert r.found == math.isfinite(optimum)
    if r.found:
        assert r.time == pytest.approx(optimum, rel=1e-12)
        assert tuple(r.cells[0]) == s and tuple(r.cells[-1]) == t
        assert r.time == pytest.approx(travel_time(r.cells, speed=speed, turn_rate=rate,
                                                   start_heading=start_heading), rel=1e-12)

def test_turns_cost_time_on_a_real_map():
    grid = skyroute.load_map("den312d")
    a = skyroute.plan(grid, (50, 76), (60, 13))
    r = plan_turns(grid, (50, 76), (60, 13), turn_rate=math.pi / 4)
    assert r.time < travel_time(a.path, turn_rate=math.pi / 4)
    assert r.distance >= a.cost - 1e-9  # the fastest route is never shorter than the shortest


def test_repr_summarises_the_route():
    r = plan_turns(skyroute.load_map("den312d"), (50, 76), (60, 13), turn_rate=math.pi / 4)
    text = repr(r)
    assert text.startswith(f"<LatticeResult found, {r.time:.6g} s over {r.distance:.6g}, "
                           f"{len(r.cells)} cells, {r.expanded} expanded")
    assert "array" not in text


def test_lattice_options_are_checked():
    # "2" was a TypeError, inf a speed, -1 and "5" budgets, NaN a heading
    import pytest

    from skyroute.motion.turn_lattice import plan_turns_world

    grid = skyroute.load_map("den312d")
    for kw in ({"speed": "2"}, {"speed": math.inf}, {"turn_rate": None},
               {"max_expansions": -1}, {"max_expansions": "5"},
               {"start_heading": math.nan}, {"start_heading": "x"}):
        (name, _), = kw.items()
        with pytest.raises(skyroute.OptionError, match=f"{name}="):
            plan_turns(grid, (50, 76), (60, 13), **kw)
    with pytest.raises(skyroute.OptionError, match="speed="):
        travel_time([(0, 0), (1, 0)], speed=0)
    with pytest.raises(skyroute.QueryError):
        travel_time([(0, 0, 0), (1, 0, 0)])
    import shapely

    tower = skyroute.World([shapely.box(1, 1, 3, 3)], [0], [50], ("tower",))
    with pytest.raises(skyroute.OptionError, match="speed="):
        plan_turns_world(tower, (0, 2), (4, 2), speed="1")
    r = plan_turns(grid, (50, 76), (60, 13), speed=np.float32(2), start_heading=np.array(1.0),
                   max_expansions=np.int64(10**6))
    assert r.found


_box = st.tuples(st.floats(5, 80), st.floats(5, 80), st.floats(2, 20), st.floats(2, 20))
_pt = st.tuples(st.floats(1, 99), st.floats(1, 99))


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(_box, max_size=5), _pt, _pt, st.sampled_from(["enu", "ned"]),
       st.sampled_from([8, 16]), st.floats(-360, 360), st.sampled_from([2.0, 5.0]))
def test_property_a_world_route_is_free_and_drives_along_its_headings(
        boxes, start, goal, frame, headings, start_heading, resolution):
    """On a World (a 100 m square, random boxes, read in enu or ned): every leg of the
    route meets no obstacle's interior and stays inside the boundary (shapely), a move
    drives along the heading it has (in the frame's convention), a turn in place is to a
    neighbouring lattice heading, and the distance is the legs' length."""
    from skyroute.motion.turn_lattice import _DIRS, plan_turns_world
    from skyroute.world.world import World

    obs = np.array([shapely.box(x, y, x + w, y + h) for x, y, w, h in boxes], dtype=object)
    world = World(obs, np.full(len(obs), -np.inf), np.full(len(obs), np.inf), (),
                  boundary=shapely.box(0, 0, 100, 100), frame=frame)
    assume(world.is_free([start, goal]).all())  # plane points
    flip = (lambda p: p[::-1]) if frame == "ned" else (lambda p: p)
    s, g = flip(start), flip(goal)  # as the frame reads them
    try:
        res = plan_turns_world(world, s, g, headings=headings, resolution=resolution,
                               start_heading=math.radians(start_heading))
    except skyroute.QueryError as exc:  # no free cell in sight of a point (a narrow gap)
        assert "is too close to an obstacle" in str(exc)
        return
    if not res.found:
        assert res.status is skyroute.Status.NO_PATH
        return
    plane = world.to_plane(res.path)
    line = shapely.LineString(plane) if len(plane) > 1 else shapely.Point(plane[0])
    union = shapely.unary_union(obs)
    assert not union.relate_pattern(line, "T********")  # no interior point shared
    assert shapely.box(0, 0, 100, 100).contains(line)
    th = np.asarray(world.heading_to_plane(res.headings))
    d = np.diff(plane, axis=0)
    moves = np.hypot(*d.T) > 1e-9
    along = np.arctan2(d[:, 1], d[:, 0])
    gap = lambda a, b: np.abs((a - b + math.pi) % (2 * math.pi) - math.pi)  # noqa: E731
    assert (gap(along, th[1:])[moves] < 1e-9).all()  # drives the heading it has
    assert (gap(th[1:], th[:-1])[moves] < 1e-9).all()  # and turns only in place
    turns = gap(th[1:], th[:-1])[~moves]  # to a neighbouring lattice heading
    ang = np.arctan2(*np.array(_DIRS[headings])[:, ::-1].T)
    steps = gap(np.roll(ang, -1), ang)
    assert all(np.isclose(steps, t, rtol=0, atol=1e-9).any() for t in turns)
    assert res.distance == pytest.approx(float(np.hypot(*d.T).sum()), abs=1e-9)


def _boxed_goal_grid():
    """A 200 x 200 grid whose goal cell (196, 197) is walled in (12 wall cells round 3):
    the search expands the other 39,985 cells' 8 states each, then ends in no_path."""
    from skyroute.world.grid import Grid

    b = np.zeros((200, 200), bool)
    b[195, 195:198] = b[199, 195:198] = True
    b[195:200, 195] = b[195:200, 197] = True
    return Grid(b), (0, 0), (196, 197)


@pytest.mark.parametrize("raises", [True, False])
def test_ctrl_c_stops_the_compiled_search_and_frees_it(monkeypatch, raises):
    """The lattice's search is one compiled call (a fine raster's: seconds and more); it
    polls every 4,096 expansions (skyroute.search.interrupt): a SIGINT handler that raises
    does so after the search has returned, so nothing of it stays allocated, and one that
    does not lets it run again to the end."""
    from skyroute.motion import turn_lattice
    from skyroute.result import NO_PATH
    from skyroute.search.interrupt import INTERRUPTED
    from tests.search.sigint import interrupted

    class SigintError(Exception):
        pass

    def handler(signum, frame):
        if raises:
            raise SigintError

    grid, s, t = _boxed_goal_grid()
    alone = plan_turns(grid, s, t)
    assert alone.status is skyroute.Status.NO_PATH and alone.expanded == 8 * (200 * 200 - 15)
    out, statuses, (allocs, frees) = interrupted(
        monkeypatch, turn_lattice, lambda: plan_turns(grid, s, t), handler,
        kernel="_lattice_kernel")
    if raises:
        assert isinstance(out, SigintError) and statuses == [INTERRUPTED]
        assert allocs > 0 and frees == allocs
    else:
        assert statuses == [INTERRUPTED, NO_PATH] and out.expanded == alone.expanded
