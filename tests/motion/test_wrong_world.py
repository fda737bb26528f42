"""A wrong object where a planner wants a World or a Grid is an OptionError naming the
argument, not an AttributeError from deep inside the planner."""

import numpy as np
import pytest
import shapely

import skyroute
from skyroute.motion import dubins, hybrid, potential, step_drone, turn_lattice

WORLD = skyroute.World([shapely.box(1, 1, 3, 3)], [0], [50], ("tower",))
GRID = skyroute.Grid(np.zeros((5, 5), bool))

CALLS = {
    "hybrid.plan": (lambda w: hybrid.plan(w, (0, 2, 0), (5, 2, 0), 0.5), "world"),
    "turn_lattice.plan_turns_world":
        (lambda w: turn_lattice.plan_turns_world(w, (0, 2), (5, 2)), "world"),
    "turn_lattice.plan_turns": (lambda w: turn_lattice.plan_turns(w, (0, 0), (4, 4)), "grid"),
    "potential.run_field": (lambda w: potential.run_field(w, (0, 2), (5, 2)), "world"),
    "dubins.tour": (lambda w: dubins.tour((0, 0, 0), [(5, 5)], 1.0, world=w), "world"),
    "step_drone.plan_moves": (lambda w: step_drone.plan_moves(w, (0, 0), (1, 1)), "world"),
}


@pytest.mark.parametrize("name", CALLS)
@pytest.mark.parametrize("wrong", [np.zeros((5, 5), bool), "city.csv"],
                         ids=["array", "path"])
def test_a_wrong_object_is_named(name, wrong):
    call, param = CALLS[name]
    with pytest.raises(skyroute.OptionError, match=f"^{param} must be a skyroute ") as err:
        call(wrong)
    assert err.value.param == param
    assert type(wrong).__name__ in str(err.value)


def test_the_right_objects_still_plan():
    assert hybrid.plan(WORLD, (0, 2, 0), (5, 2, 0), 0.5).found
    assert turn_lattice.plan_turns(GRID, (0, 0), (4, 4)).found
    assert dubins.tour((0, 0, 0), [(5, 5)], 1.0, world=None).found
