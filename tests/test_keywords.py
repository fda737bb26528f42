"""A misspelt keyword to a public facade is a KeywordError (an OptionError and still a
TypeError) naming it, the closest valid keyword and the valid ones; Python's own
TypeError ("got an unexpected keyword argument 'algoritm'") named neither."""

from __future__ import annotations

import inspect
import pydoc

import numpy as np
import pytest

import skyroute
from skyroute.errors import KeywordError, OptionError
from skyroute.keywords import strict_keywords, unknown_keywords
from skyroute.motion import dubins, hybrid, potential, step_drone, turn_lattice
from skyroute.roadmap.world_plan import plan_world


def _index():
    return skyroute.prepare(skyroute.Grid(np.zeros((3, 3), bool)))


# (what, the function, its positional arguments, a misspelt keyword, the one meant):
# the keyword is refused before any argument is read, so placeholders do
CASES = [
    ("skyroute.plan", lambda: skyroute.plan, (None, None, None), "algoritm", "algorithm"),
    ("skyroute.plan on a World", lambda: skyroute.plan, (None, None, None), "sampels",
     "samples"),
    ("skyroute.prepare", lambda: skyroute.prepare, (None,), "metod", "method"),
    ("PreparedGrid.plan", lambda: _index().plan, (None, None), "gaol", "goal"),
    ("skyroute.load_index", lambda: skyroute.load_index, (None, None), "gird", "grid"),
    ("skyroute.load_map", lambda: skyroute.load_map, (None,), "saftey", "safety"),
    ("skyroute.load_world", lambda: skyroute.load_world, (None,), "altitdue", "altitude"),
    ("plan_world", lambda: plan_world, (None, None, None), "neighbors", "neighbours"),
    ("hybrid.plan", lambda: hybrid.plan, (None, None, None, 1.0), "heading_bin",
     "heading_bins"),
    ("dubins.tour", lambda: dubins.tour, (None, None, 1.0), "wrld", "world"),
    ("dubins.shortest_path", lambda: dubins.shortest_path, (None, None, 1.0), "raduis",
     "radius"),
    ("dubins.lengths", lambda: dubins.lengths, (None, None, 1.0), "goal", "goals"),
    ("step_drone.plan_moves", lambda: step_drone.plan_moves, (None, None), "stepp", "step"),
    ("potential.run_field", lambda: potential.run_field, (None, None, None), "sensor_rnage",
     "sensor_range"),
    ("turn_lattice.plan_turns", lambda: turn_lattice.plan_turns, (None, None, None),
     "Headings", "headings"),
]


def _keywords(func) -> list[str]:
    return [p.name for p in inspect.signature(func).parameters.values()
            if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]


@pytest.mark.parametrize(("what", "get", "args", "bad", "meant"), CASES,
                         ids=[c[0] for c in CASES])
def test_a_misspelt_keyword_names_the_closest_and_the_valid_ones(what, get, args, bad,
                                                                 meant):
    func = get()
    with pytest.raises(KeywordError) as err:
        func(*args, **{bad: 1})
    msg = str(err.value)
    assert f"got an unknown keyword {bad} (did you mean {meant}?)" in msg
    valid = (_keywords(func) if func is not plan_world else
             ["world", "start", "goal", "algorithm", "max_expansions", "samples",
              "neighbours", "prm_star", "seed", "resolution", "connectivity",
              "corner_cutting", "heuristic", "weight", "prune"])
    assert meant in valid
    assert msg.endswith(f"; its keywords are {', '.join(valid)}")
    assert err.value.param == bad
    # caught as before (TypeError) and as skyroute's option errors (the CLI's exit 2)
    assert isinstance(err.value, TypeError) and isinstance(err.value, OptionError)


@pytest.mark.parametrize(("what", "get"), [(c[0], c[1]) for c in CASES if c[1]() is not
                                           plan_world], ids=lambda v: v if isinstance(
                                               v, str) else "")
def test_the_signature_shows_the_options_not_the_catch_all(what, get):
    func = get()
    params = inspect.signature(func).parameters.values()
    assert all(p.kind is not p.VAR_KEYWORD for p in params)
    assert "**misspelt" not in pydoc.render_doc(func)
    assert _keywords(func)  # the real parameters are still there


def test_the_signature_of_plan_is_its_options():
    assert _keywords(skyroute.plan) == [
        "grid", "start", "goal", "algorithm", "connectivity", "corner_cutting", "heuristic",
        "weight", "prune", "max_expansions", "resolution", "samples", "neighbours",
        "prm_star", "seed"]


def test_several_misspelt_keywords_are_all_named():
    grid = skyroute.Grid(np.zeros((3, 3), bool))
    with pytest.raises(KeywordError, match=r"got unknown keywords algoritm \(did you mean "
                                           r"algorithm\?\), colour; its keywords are grid,"):
        skyroute.plan(grid, (0, 0), (2, 2), algoritm="jps", colour="red")


def test_an_unknown_keyword_with_no_close_one_lists_the_valid_ones():
    with pytest.raises(KeywordError, match=r"^PreparedGrid\.plan\(\) got an unknown keyword "
                                           r"algorithm; its keywords are start, goal$"):
        _index().plan((0, 0), (2, 2), algorithm="jps")


def test_correct_keywords_still_plan():
    grid = skyroute.Grid(np.zeros((3, 3), bool))
    r = skyroute.plan(grid, (0, 0), (2, 2), algorithm="jps", max_expansions=100)
    assert r.status is skyroute.Status.FOUND and r.cost == pytest.approx(2 * np.sqrt(2))


def test_a_function_without_the_catch_all_is_refused_at_import():
    def f(a, *, b=1):
        return a

    with pytest.raises(TypeError, match="needs a last \\*\\*misspelt parameter"):
        strict_keywords(f)


def test_the_error_helper_reads_the_decorated_signature():
    @strict_keywords
    def f(a, /, b, *, colour=None, **misspelt):
        if misspelt:
            raise unknown_keywords(f, misspelt)
        return a

    assert str(inspect.signature(f)) == "(a, /, b, *, colour=None)"
    with pytest.raises(KeywordError, match=r"unknown keyword color \(did you mean colour\?\); "
                                           r"its keywords are b, colour$"):
        f(1, 2, color="red")
