"""Potential fields: the plain field on easy and medium, the escape on the C shape."""

import math

import numpy as np
import pytest
import shapely

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
