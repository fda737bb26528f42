"""Potential fields: the plain field on easy and medium, the escape on the C shape."""

import math

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from skyroute import OptionError, World
from skyroute.motion.potential import course, run_field


@pytest.mark.parametrize("name", ["easy", "medium"])
def test_plain_field_reaches_easy_and_medium(name):
    world, start, goal = course(name)
    run = run_field(world, start, goal, escape=False)
    assert run.reached and run.escaped == 0
    assert world.segments_free(run.path[:-1], run.path[1:]).all()
    m = run.metrics()
    assert m["moves"] == run.moves and m["length"] >= math.dist(start, goal) - 0.5
    assert 0 <= m["smoothness"] < 0.2  # nearly straight


def test_c_shape_traps_the_plain_field_and_the_escape_gets_out():
    world, start, goal = course("hard")
    plain = run_field(world, start, goal, escape=False)
    assert not plain.reached  # stalls inside the C
    assert plain.path[-1][0] < 34  # it never got past the C's back wall
    out = run_field(world, start, goal, escape=True)
    assert out.reached and out.escaped > 0
    assert world.segments_free(out.path[:-1], out.path[1:]).all()


def test_sensor_parameters_matter_and_are_checked():
    world, start, goal = course("medium")
    near = run_field(world, start, goal, escape=False, sensor_range=1.0)
    far = run_field(world, start, goal, escape=False, sensor_range=6.0)
    assert near.reached and far.reached and near.path.shape != far.path.shape
    with pytest.raises(OptionError):
        run_field(world, start, goal, sensor_rays=2)
    with pytest.raises(OptionError):
        course("impossible")


@pytest.mark.parametrize("name", ["easy", "medium"])
def test_arc_mode_reaches_with_bounded_turns_and_fractional_steps(name):
    world, start, goal = course(name)
    run = run_field(world, start, goal, escape=False, mode="arc", max_turn=math.pi / 6)
    assert run.reached and run.escaped == 0
    assert world.segments_free(run.trace[:-1], run.trace[1:]).all()
    chords = np.diff(run.trace, axis=0)
    heading = np.arctan2(chords[:, 1], chords[:, 0])
    turns = np.abs((np.diff(heading) + math.pi) % (2 * math.pi) - math.pi)
    assert turns.max() <= math.pi / 6 + 1e-9  # never a sharper turn than allowed
    hops = np.hypot(*np.diff(run.path, axis=0).T)
    assert hops.max() <= 0.5 + 1e-9 and hops.min() >= 0.5 / 4 * 0.9  # fractional progress
    assert run.distance == pytest.approx(np.hypot(*chords.T).sum())


def test_arc_mode_escapes_the_c_shape_more_smoothly_than_steps():
    world, start, goal = course("hard")
    arc = run_field(world, start, goal, mode="arc")
    step = run_field(world, start, goal, mode="step")
    assert arc.reached and arc.escaped > 0 and step.reached
    assert world.segments_free(arc.trace[:-1], arc.trace[1:]).all()
    assert arc.smoothness < step.smoothness
    with pytest.raises(OptionError):
        run_field(world, start, goal, mode="glide")


@pytest.mark.parametrize("max_turn", [math.pi / 6, math.pi / 4, math.pi / 18])
def test_arc_mode_escape_moves_keep_the_turn_limit(max_turn):
    # escape moves jumped straight to the navigation function's next cell centre, so
    # the arc-mode trace out of the C turned 174 degrees in one move with max_turn 30
    world, start, goal = course("hard")
    run = run_field(world, start, goal, mode="arc", max_turn=max_turn)
    assert run.reached and run.escaped > 0
    assert world.segments_free(run.trace[:-1], run.trace[1:]).all()
    chords = np.diff(run.trace, axis=0)
    heading = np.arctan2(chords[:, 1], chords[:, 0])
    turns = np.abs((np.diff(heading) + math.pi) % (2 * math.pi) - math.pi)
    assert turns.max() <= max_turn + 1e-9



def _open_c(mirror: bool = False) -> World:
    """The hard course's C with no boundary (a colliders.csv city has none): the
    navigation function's raster then covered the obstacles' bounds alone."""
    boxes = [(30, 15, 34, 45), (18, 41, 34, 45), (18, 15, 34, 19)]
    if mirror:
        boxes = [(60 - x1, y0, 60 - x0, y1) for x0, y0, x1, y1 in boxes]
    return World(shapely.box(*np.array(boxes, float).T), np.full(3, -np.inf),
                 np.full(3, np.inf), (), None, "enu")


@pytest.mark.parametrize("mode", ["step", "arc"])
@pytest.mark.parametrize("world, start, goal", [
    (_open_c(), (5.0, 30.0), (52.0, 30.0)),     # goal east of the obstacles' bounds
    (_open_c(True), (55.0, 30.0), (8.0, 30.0)),  # west: the cell index was negative
    (_open_c(), (5.0, 30.0), (34.1, 30.0)),     # just behind the C, in the raster's bounds
    (course("hard")[0], (5.0, 30.0), (34.1, 30.0)),  # the goal's own cell blocked
], ids=["east", "west", "behind-the-c", "goal-cell-blocked"])
def test_the_escape_reaches_goals_beyond_the_obstacles_and_beside_a_wall(world, start,
                                                                        goal, mode):
    # the escape's raster spanned the obstacles' bounds only: a goal beyond them raised
    # IndexError (skyroute fly city.csv --vehicle field, a goal past the city) or, west
    # or south of them, wrapped to a cell on the far side; a goal within the clearance of
    # a wall sat in a blocked cell that the wavefront never left (stuck, 0 escape moves)
    run = run_field(world, start, goal, mode=mode)
    assert run.reached and run.escaped > 0
    flown = run.trace if mode == "arc" else run.path
    assert world.segments_free(flown[:-1], flown[1:]).all()
    assert math.dist(run.path[-1], goal) < 0.5

def test_repr_summarises_the_run():
    world, start, goal = course("easy")
    run = run_field(world, start, goal, escape=False)
    assert repr(run) == (f"<FieldRun found, {run.moves} moves, length {run.distance:.6g}, "
                         "0 escape moves>")


@pytest.mark.parametrize("kw", [{"step": "1"}, {"attract": math.nan}, {"repulse": math.inf},
                                {"attract": -1.0}, {"sensor_range": "6"},
                                {"tolerance": "0.5"}, {"max_turn": "1"},
                                {"sensor_rays": 12.5}, {"max_moves": -1},
                                {"max_moves": 12.5}, {"window": 0}, {"window": 2.5},
                                {"escape": "no"}, {"heading": "x"}])
def test_run_field_names_a_bad_option(kw):
    # TypeErrors, a GEOSException for attract=nan, an IndexError for window=-1; a
    # negative attraction and escape="no" were taken
    world, s, t = course("easy")
    (name, _), = kw.items()
    with pytest.raises(OptionError, match=f"{name}="):
        run_field(world, s, t, **kw)


def test_run_field_takes_numpy_numbers():
    world, s, t = course("easy")
    a = run_field(world, s, t, step=np.float32(0.5), sensor_rays=np.int64(36),
                  max_moves=np.int64(2000), window=np.array(40))
    b = run_field(world, s, t, step=0.5)
    assert a.status == b.status and a.moves == b.moves


def test_a_field_run_says_found_as_every_result_does():
    # FieldRun had only .reached, the step drone's Flight neither
    world, s, t = course("easy")
    r = run_field(world, s, t)
    assert r.found is r.reached is True
    assert run_field(world, s, t, max_moves=3).found is False


def test_escape_reaches_a_goal_beyond_the_obstacles_of_an_unbounded_world():
    """The navigation raster covered the obstacles' extent only: with no boundary, a
    robot trapped in the C (x < 34) and a goal past it (x = 80) had no cells there, and
    the escape ended in an IndexError (a traceback from ``skyroute fly --vehicle field``
    on a GeoJSON world whose goal lay beyond its zones)."""
    import shapely

    from skyroute.world.world import World

    hard, start, _ = course("hard")
    world = World(hard.obstacles, np.full(3, -np.inf), np.full(3, np.inf), (), None, "enu")
    goal = np.array([80.0, 30.0])
    assert shapely.box(*world.bounds).contains(shapely.Point(goal)) is False
    run = run_field(world, start, goal, escape=True)
    assert run.reached and run.escaped > 0
    assert world.segments_free(run.path[:-1], run.path[1:]).all()
    assert math.dist(run.path[-1], goal) < 0.5


def test_an_escape_raster_past_the_cell_limit_names_the_step():
    """A goal far beyond the obstacles of an unbounded world grows the escape's raster
    (cells a step wide) past MAX_CELLS: the error named ``resolution``, which run_field
    has not (and ``fly --vehicle field`` refuses: "does not use --resolution")."""
    with pytest.raises(OptionError) as err:
        run_field(_open_c(), (25.0, 30.0), (6000.0, 6000.0))
    assert err.value.param == "step"
    assert str(err.value).startswith("step=0.5 makes the escape's raster (cells a step wide "
                                     "over the obstacles, the start, the robot and the goal")
    assert str(err.value).endswith("; use a larger step, or turn the escape off")


# -- the escape is used whenever the field cannot move on --------------------------------

def _box_world(boxes, size=(60, 60)) -> World:
    n = len(boxes)
    return World(np.array([shapely.box(*b) for b in boxes], dtype=object),
                 np.full(n, -np.inf), np.full(n, np.inf), (), shapely.box(0, 0, *size),
                 "enu")


def _flown(run):
    return run.trace if run.trace is not None else run.path


def test_a_blocked_step_hands_over_to_the_escape():
    """A pebble on the line to the goal, between two of the sensor's 36 rays: the field
    does not see it, its step and half step are blocked, and the run ended stuck with 0
    escape moves although the escape was on."""
    a = math.radians(5)  # half-way between the rays at 0 and 10 degrees
    start = np.array([5.0, 30.0])
    ahead = np.array([math.cos(a), math.sin(a)])
    c = start + 0.2 * ahead
    world = _box_world([(c[0] - 0.01, c[1] - 0.01, c[0] + 0.01, c[1] + 0.01)])
    goal = start + 40 * ahead
    run = run_field(world, start, goal)
    assert run.reached and run.escaped > 0 and run.why == ""
    assert world.segments_free(run.path[:-1], run.path[1:]).all()
    off = run_field(world, start, goal, escape=False)
    assert off.status.value == "stuck" and off.moves == 0
    assert off.why == "the move along the field and its half are blocked and the escape is off"


def test_a_blocked_arc_hands_over_to_the_escape():
    """Nose to a wall 5 cm ahead: the arc turning away and its half both touch it, and
    the arc-mode run ended stuck with 0 escape moves although the escape was on."""
    world = _box_world([(10, 20, 12, 40)])
    run = run_field(world, (9.95, 30.0), (52.0, 30.0), mode="arc")
    assert run.reached and run.escaped > 0
    assert world.segments_free(run.trace[:-1], run.trace[1:]).all()
    chords = np.diff(run.trace, axis=0)
    heading = np.arctan2(chords[:, 1], chords[:, 0])
    turns = np.abs((np.diff(heading) + math.pi) % (2 * math.pi) - math.pi)
    assert turns.max() <= math.pi / 4 + 1e-9  # the escape keeps the turn limit
    off = run_field(world, (9.95, 30.0), (52.0, 30.0), mode="arc", escape=False)
    assert off.status.value == "stuck" and off.moves == 0
    assert off.why == "the arc along the field and its half are blocked and the escape is off"


@pytest.mark.parametrize("mode", ["step", "arc"])
def test_a_trap_the_field_falls_back_into_is_left_for_good(mode):
    """A C 40 m deep round the start, the goal beyond its back: each escape (24 m) got
    the robot out of the C's mouth, the field pulled it back in, and the run went round
    until its 2,000 moves were spent. Each escape now runs twice as long as the last."""
    world = _box_world([(100, 20, 104, 80), (60, 20, 104, 24), (60, 76, 104, 80)],
                       size=(200, 100))
    run = run_field(world, (80.0, 50.0), (150.0, 50.0), mode=mode)
    assert run.reached and run.escaped > 0
    assert world.segments_free(_flown(run)[:-1], _flown(run)[1:]).all()


@settings(max_examples=60, deadline=None, derandomize=True)
@given(heading=st.floats(-math.pi, math.pi), bearing=st.floats(-math.pi, math.pi),
       far=st.floats(0.05, 3.0), step=st.floats(0.2, 2.0), max_turn=st.floats(3, 180),
       tolerance=st.floats(0.25, 1.0), escape=st.booleans())
def test_arc_mode_arrives_near_the_goal_instead_of_circling_it(heading, bearing, far, step,
                                                                max_turn, tolerance,
                                                                escape):
    """A goal a few moves away and off to one side: the turn-limited robot went round
    it for good, as close as a move but never within the tolerance (stuck after 40 moves
    without the escape, out of moves with it). With a tolerance of at least a quarter
    move, it now always arrives."""
    world = _box_world([])
    start = np.array([30.0, 30.0])
    goal = start + far * step * np.array([math.cos(bearing), math.sin(bearing)])
    run = run_field(world, start, goal, mode="arc", heading=heading, step=step,
                    tolerance=tolerance * step, max_turn=math.radians(max_turn),
                    escape=escape)
    assert run.reached, run
    assert math.dist(run.path[-1], goal) < tolerance * step


def _free_parts(world: World, margin: float = 50.0):
    """The connected parts of the free plane (shapely, not the planner's raster)."""
    region = world.boundary if world.boundary is not None else \
        shapely.box(*np.add(world.bounds, (-margin, -margin, margin, margin)))
    free = shapely.difference(shapely.Polygon(region) if region.geom_type == "LinearRing"
                              else region, shapely.union_all(world.obstacles))
    return list(getattr(free, "geoms", [free]))


def _reachable(parts, a, b) -> bool:
    pa, pb = shapely.Point(a), shapely.Point(b)
    return any(part.covers(pa) and part.covers(pb) for part in parts)


def _zones_world(tmp_path) -> World:
    """A GeoJSON world: zones, a boundary and a courtyard (a zone with a hole: the free
    space inside it is cut off)."""
    import json

    from skyroute import load_world

    lon0, lat0 = -3.186874, 55.944494

    def ring(x0, y0, x1, y1):
        return [[x0, y0], [x1, y0], [x1, y1], [x0, y1], [x0, y0]]

    rng = np.random.default_rng(5)
    feats = []
    while len(feats) < 10:
        cx, cy = lon0 + rng.uniform(-0.003, 0.003), lat0 + rng.uniform(-0.0018, 0.0018)
        if abs(cx - lon0) < 0.0016 and abs(cy - lat0) < 0.001:
            continue  # clear of the courtyard
        i = len(feats)
        w, h = rng.uniform(0.0002, 0.0009), rng.uniform(0.0001, 0.0005)
        feats.append({"type": "Feature", "properties": {"name": f"zone {i}"},
                      "geometry": {"type": "Polygon",
                                   "coordinates": [ring(cx - w, cy - h, cx + w, cy + h)]}})
    court = [ring(lon0 - 0.0006, lat0 - 0.0004, lon0 + 0.0006, lat0 + 0.0004),
             ring(lon0 - 0.0004, lat0 - 0.0002, lon0 + 0.0004, lat0 + 0.0002)[::-1]]
    feats.append({"type": "Feature", "properties": {"name": "courtyard"},
                  "geometry": {"type": "Polygon", "coordinates": court}})
    feats.append({"type": "Feature", "properties": {"name": "area", "boundary": True},
                  "geometry": {"type": "Polygon", "coordinates": [
                      ring(lon0 - 0.004, lat0 - 0.0025, lon0 + 0.004, lat0 + 0.0025)]}})
    path = tmp_path / "zones.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": feats}))
    return load_world(path, frame="enu")


@pytest.mark.parametrize("which", ["city", "zones"])
@pytest.mark.parametrize("mode", ["step", "arc"])
def test_with_the_escape_a_reachable_goal_is_reached_or_the_run_says_why(tmp_path, which,
                                                                        mode):
    """Seeded start and goal pairs in examples/city.csv and a GeoJSON world, with the
    escape on: a goal that the free plane joins to the start (shapely's connected parts,
    not the escape's raster) is reached; one it does not (the courtyard) ends stuck
    saying it is not reachable. Before, runs ended stuck with 0 escape moves when the
    field's move and its half were blocked, or used up their moves going round a trap
    or round the goal."""
    from skyroute import load_world
    from tests.conftest import ROOT

    if which == "city":
        world = load_world(ROOT / "examples" / "city.csv", altitude=10, safety=2,
                           frame="enu")
        kw = dict(step=1.0, tolerance=0.5, max_turn=math.radians(15))
    else:
        world = _zones_world(tmp_path)
        kw = dict(step=2.0, tolerance=1.0, max_turn=math.radians(30))
    parts = _free_parts(world)
    rng = np.random.default_rng(3)
    x0, y0, x1, y1 = world.bounds
    pairs = []
    while len(pairs) < 8:
        pair = rng.uniform((x0, y0), (x1, y1), size=(2, 2))
        if world.segments_free(pair, pair).all():
            pairs.append(pair)
    if which == "zones":  # two into the courtyard
        pairs += [(pairs[0][0], (0.0, 0.0)), (pairs[1][0], (5.0, -3.0))]
    else:  # from larger samples: in arc mode stuck with 0 escape moves (a start 9 cm
        # from a building), out of moves going round the goal, stuck on the escape
        pairs += [((16.8255, -161.5762), (86.6758, 12.4584)),
                  ((-55.0629, -94.2381), (12.2775, 148.3878)),
                  ((57.5622, 9.8137), (8.4930, 162.3644))]
    for start, goal in pairs:
        run = run_field(world, start, goal, mode=mode, **kw)
        assert world.segments_free(_flown(run)[:-1], _flown(run)[1:]).all()
        if _reachable(parts, start, goal):
            assert run.reached, (start, goal, run)
            assert math.dist(run.path[-1], goal) < kw["tolerance"]
        else:
            assert run.status.value == "stuck", (start, goal, run)
            assert run.why.startswith("the goal is not reachable from here on the "
                                      "navigation function's raster"), run.why
            assert run.metrics()["why"] == run.why


@pytest.mark.parametrize("mode", ["step", "arc"])
def test_a_goal_the_escape_raster_cannot_hold_is_named_not_an_index_error(mode):
    """The goal in a slot 0.3 m wide, behind the C: every cell round it is in the
    raster's clearance, so the wavefront's source joined no cell and the escape ended in
    an IndexError traceback. It now ends stuck saying why; with a step short enough for
    the slot's cells, the goal is reached."""
    boxes = [(30, 15, 34, 45), (18, 41, 34, 45), (18, 15, 34, 19), (50, 20, 51.85, 40),
             (52.15, 20, 54, 40)]
    world = _box_world(boxes)
    run = run_field(world, (5.0, 30.0), (52.0, 30.0), mode=mode)
    assert run.status.value == "stuck"
    assert run.why == ("the goal is not reachable from here on the navigation function's "
                       "raster (cells of step=0.5, obstacles grown by half a cell's "
                       "diagonal): no free cell in sight has a way to the goal (a shorter "
                       "step makes the cells finer)")
    assert run.metrics()["why"] == run.why and run.why in repr(run)
    fine = run_field(world, (5.0, 30.0), (52.0, 30.0), mode=mode, step=0.1,
                     tolerance=0.1, max_moves=5000)
    assert fine.reached and fine.escaped > 0, fine


def test_the_escape_raster_is_capped_well_below_the_grid_planners():
    """The escape's wavefront is a scipy Dijkstra over a sparse graph of its cells, about
    235 bytes a cell: a robot trapped in the C with its goal 1.2 km away at step 0.5 made
    5.8 million cells (1.4 GB), and a goal 5.5 km away at step 1 took 42 s and 7.2 GB
    (found by a review), under the grid planners' MAX_CELLS. Over ESCAPE_MAX_CELLS (2**22)
    it is one OptionError naming step, before anything is allocated."""
    from skyroute.motion import potential

    with pytest.raises(OptionError) as err:
        run_field(_open_c(), (25.0, 30.0), (1200.0, 1200.0))
    assert err.value.param == "step" and "more than 4,194,304 cells" in str(err.value)
    assert potential.ESCAPE_MAX_CELLS == 1 << 22


def test_an_escape_raster_too_large_is_refused_before_the_first_move():
    """With the escape on, a raster over ESCAPE_MAX_CELLS was refused only when the robot
    first stalled, after it had flown (a run of many moves then ended in exit 2, its path
    lost): it is refused at once, also for a run that would never stall."""
    with pytest.raises(OptionError) as err:
        run_field(_open_c(), (5.0, 30.0), (1200.0, 1200.0), max_moves=10)
    assert err.value.param == "step"
    run = run_field(_open_c(), (5.0, 30.0), (1200.0, 1200.0), max_moves=10, escape=False)
    assert run.moves == 10 and not run.reached


# -- the escape's raster made anew where the robot has left it -----------------------------

def _open_wall() -> World:
    """A wall 20 m long, no boundary: the escape's raster covers the wall, the start,
    the robot and the goal, 8 cells round them."""
    return World(np.array([shapely.box(20, 10, 21, 30)], dtype=object), np.full(1, -np.inf),
                 np.full(1, np.inf), (), None, "enu")


def _count_rasters(monkeypatch) -> list:
    """(robot position, grid) of each escape raster made (the escape's _navigation)."""
    from skyroute.motion import potential

    made, real = [], potential._navigation

    def navigation(world, goal, resolution, points):
        out = real(world, goal, resolution, points)
        made.append((points[-1].copy(), out[0]))
        return out

    monkeypatch.setattr(potential, "_navigation", navigation)
    return made


def test_the_escape_raster_is_made_anew_when_the_robot_has_left_it(monkeypatch):
    """Arc mode, starting on a heading along the wall with a wide turn (0.02 rad a move)
    and a 3-move stall window (its slow turning start counts as a stall): the escape
    takes over at once, its turn-limited arcs carry the robot past the raster's top
    edge (the wall's end, 30 m, plus 8 cells), and the next escape move makes the
    raster anew round it. That rebuild never ran in 600 random runs; the run reaches the
    goal, and its arcs never cross the wall (shapely, not the world's own check)."""
    from skyroute.motion.potential import _holds

    made = _count_rasters(monkeypatch)
    world = _open_wall()
    run = run_field(world, (10.0, 20.0), (30.0, 20.0), mode="arc", heading=math.pi / 2,
                    max_turn=0.02, window=3)
    assert len(made) >= 2, made
    assert _holds(made[0][1], made[0][0]) and not _holds(made[0][1], made[1][0])
    assert made[1][0][1] > 30  # past the wall's end, where the first raster stops
    assert _holds(made[1][1], made[1][0])
    assert run.reached and run.why == "" and run.escaped > 0, run
    flown = shapely.LineString(run.trace)
    assert not flown.intersects(shapely.box(20, 10, 21, 30))
    assert math.dist(run.path[-1], (30.0, 20.0)) < 0.5


def test_a_robot_too_far_for_a_new_escape_raster_stops_saying_why(monkeypatch):
    """The robot, turning 0.01 rad a move, flies so far from the wall and the goal that a
    raster holding it would pass ESCAPE_MAX_CELLS (here 4,000 cells): the run raised an
    OptionError after its moves ("use a larger step", though the step was checked before
    the first move). It now ends stuck with its path, saying where the robot flew."""
    from skyroute.motion import potential

    monkeypatch.setattr(potential, "ESCAPE_MAX_CELLS", 4000)
    made = _count_rasters(monkeypatch)
    world = _open_wall()
    run = run_field(world, (10.0, 20.0), (30.0, 20.0), mode="arc", heading=math.pi,
                    max_turn=0.01, window=3)
    assert run.status.value == "stuck" and run.moves > 1 and len(made) >= 2, run
    end = run.path[-1]
    assert run.why.startswith(f"the robot flew to ({end[0]:.2f}, {end[1]:.2f}), "
                              f"{math.dist(end, (30.0, 20.0)):.6g} from the goal, outside "
                              "the escape's raster, and one holding it (cells of step=0.5 "
                              "over "), run.why
    assert run.why.endswith("would have more than 4,000 cells; a larger step makes fewer")
    assert not shapely.LineString(run.trace).intersects(shapely.box(20, 10, 21, 30))


def test_the_sensor_reads_the_outlines_in_range_and_sees_what_the_union_shows(monkeypatch):
    """Each sense intersected its rays with the union of every outline in the world:
    50 ms a move in the FCND city (a 300 m run took 22 s). It now takes the outlines the
    obstacles' index finds within range, and the hits are those of the union."""
    import skyroute
    from skyroute.motion import potential
    from tests.conftest import ROOT

    world = skyroute.load_world(str(ROOT / "examples" / "city.csv"), frame="ned",
                                altitude=10, safety=2)
    union = shapely.unary_union([shapely.boundary(g) for g in world.obstacles])
    total = int(shapely.get_num_coordinates(union))
    rng = np.random.default_rng(4)
    pts = rng.uniform(*np.array(world.bounds).reshape(2, 2), size=(200, 2))
    for p in pts[world.is_free(pts)][:60]:
        got = potential._sense(world, p, 6.0, 36)
        ang = np.arange(36) * 2 * math.pi / 36
        ends = p + 6.0 * np.c_[np.cos(ang), np.sin(ang)]
        hit = shapely.intersection(shapely.linestrings(
            np.stack([np.broadcast_to(p, ends.shape), ends], axis=1)), union)
        d = shapely.distance(shapely.Point(p), hit)
        ok = ~shapely.is_empty(hit)
        want = p + (d[ok] / 6.0)[:, None] * (ends[ok] - p)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)
    sizes = []
    intersection = shapely.intersection

    def spy(a, b, **kw):
        sizes.append(int(shapely.get_num_coordinates(b).sum()))
        return intersection(a, b, **kw)

    monkeypatch.setattr(shapely, "intersection", spy)
    run = run_field(world, (0.0, 0.0), (-60.0, 60.0), step=1.0, tolerance=1.0)
    assert run.reached and sizes
    assert max(sizes) < total / 4, (max(sizes), total)
