"""Every SkyrouteError child survives pickle, as a process pool or Dask sends a task's
error back: the same type, message, ``param`` and attributes.

Python pickles an exception as ``type(err)(*err.args)``: a child whose constructor takes
other arguments than its message (``DaysFailedError(stored, failed, days)``) did not
unpickle ("missing 2 required positional arguments"), and a local pool reported such an
error from a worker as the worker having 'terminated abruptly'.
"""

from __future__ import annotations

import datetime as dt
import importlib
import pickle
import pkgutil
import warnings

import pytest

import skyroute
from skyroute.errors import SkyrouteError

DAY = dt.date(2024, 1, 1)


def _every_child() -> list[type]:
    with warnings.catch_warnings():  # (skyroute.world_plan: a deprecated alias)
        warnings.simplefilter("ignore", DeprecationWarning)
        for m in pkgutil.walk_packages(skyroute.__path__, "skyroute."):
            if not m.name.endswith("__main__"):  # (it runs the CLI)
                importlib.import_module(m.name)
    seen, todo = set(), [SkyrouteError]
    while todo:
        for child in todo.pop().__subclasses__():
            if child.__module__.startswith("skyroute.") and child not in seen:
                seen.add(child)
                todo.append(child)
    return sorted(seen, key=lambda c: f"{c.__module__}.{c.__qualname__}")


def _example(cls: type) -> SkyrouteError:
    """An instance of ``cls``: built from its own arguments where its constructor is not
    SkyrouteError's (a new such child needs a line here)."""
    from skyroute.jobs.deliver import DayFailed

    own = {
        "InputFormatError": lambda: cls("maps/a.map", "expected 'type octile'", line=1),
        "CityNotWallsError": lambda: cls("colliders.csv", "a city, not walls"),
        "GridNotWorldError": lambda: cls("walls.csv", "wall segments, not a city", line=1),
        "DayKeptError": lambda: cls(DAY, 3, "every order is invalid"),
        "WorldNotGridError": lambda: cls("zones.geojson", "GeoJSON zones, not a grid map"),
        "OrdersChangedError": lambda: cls([(DAY, 7, "customer", "Ann", "Bob")], [DAY]),
        "DaysFailedError": lambda: cls([], [DayFailed(DAY, f"{DAY}: gone", True)], 3),
        "TasksLostError": lambda: cls({1: "its worker process died (exit code 3)"},
                                      [10, None, 30]),
        "RunsLostError": lambda: cls(
            [{"scheduler": "seed", "airspace": "shared", "runs": 1}],
            [{"scheduler": "seed", "airspace": "shared", "rate_per_hour": None, "seed": 1,
              "error": "its worker process died"}], 4),
    }
    if cls.__name__ in own:
        return own[cls.__name__]()
    assert cls.__init__ is SkyrouteError.__init__, \
        f"{cls.__qualname__} has its own constructor: add an example to _example"
    return cls("something=3 is not valid", param="something")


@pytest.mark.parametrize("cls", _every_child(), ids=lambda c: c.__qualname__)
def test_every_skyroute_error_round_trips_through_pickle(cls):
    err = _example(cls)
    back = pickle.loads(pickle.dumps(err))
    assert type(back) is cls
    assert str(back) == str(err) and back.args == err.args
    assert back.param == err.param
    assert vars(back) == vars(err)  # date, failed, lost, rows, ...


def test_the_children_are_found():
    names = {c.__name__ for c in _every_child()}
    assert {"OptionError", "DaysFailedError", "TasksLostError", "ExecutorClosedError",
            "RunChangedError", "DayKeptError", "RunsLostError"} <= names
