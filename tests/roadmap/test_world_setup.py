"""A world plan's first query times what it sets up (the roadmap, the compiled kernels)
apart from its search, as a grid plan does: ``plan-world`` on the FCND city reported
the query kernels' first load (4.1 s) as its search time and the graph's build nowhere."""

from __future__ import annotations

import json
import re
import types
from pathlib import Path

import numpy as np
import pytest
import shapely

import skyroute
from skyroute.roadmap import visibility, world_plan
from tests.cli.test_cli import run

CITY = str(Path(__file__).parents[2] / "examples" / "city.csv")


def _world() -> skyroute.World:
    return skyroute.World([shapely.box(1, 1, 3, 3)], [0], [50], ("tower",))


@pytest.fixture
def clock(monkeypatch):
    """A clock that the roadmap's build moves 100 s and each search 1 s, read by the
    world planner and the visibility graph alike; no query has run in this process."""
    now = [0.0]
    fake = types.SimpleNamespace(perf_counter=lambda: now[0])
    build, search = world_plan.VisibilityGraph, visibility.corner_astar

    def slow_build(world, **kw):
        now[0] += 100.0
        return build(world, **kw)

    def slow_search(*args):
        now[0] += 1.0
        return search(*args)

    monkeypatch.setattr(world_plan, "time", fake, raising=False)
    monkeypatch.setattr(visibility, "time", fake)
    monkeypatch.setattr(world_plan, "VisibilityGraph", slow_build)
    monkeypatch.setattr(visibility, "corner_astar", slow_search)
    monkeypatch.setattr(world_plan, "_QUERIED", set(), raising=False)
    return now


def test_the_first_query_times_its_set_up_apart(clock):
    world = _world()
    first = skyroute.plan(world, (0, 2), (4, 2))
    # the build (100) and, the process's first query, the same query once more (1)
    assert first.extra["setup_seconds"] == 101.0 and first.seconds == 1.0
    again = skyroute.plan(world, (0, 2), (4, 2))  # the graph looked up: no time passes
    assert again.extra["setup_seconds"] == 0.0 and again.seconds == 1.0
    other = skyroute.plan(_world(), (0, 2), (4, 2))  # a new world: its graph is built
    assert other.extra["setup_seconds"] == 100.0 and other.seconds == 1.0
    for r in (first, again, other):
        assert r.cost == pytest.approx(2 + 2 * np.sqrt(2))


def test_a_prm_roadmap_is_set_up_once(monkeypatch):
    built = []
    prm = world_plan.PRM
    monkeypatch.setattr(world_plan, "PRM", lambda *a, **kw: built.append(kw) or prm(*a, **kw))
    world = _world()
    first = skyroute.plan(world, (0, 2), (4, 2), algorithm="prm", samples=200)
    again = skyroute.plan(world, (0, 2), (4, 2), algorithm="prm", samples=200)
    other = skyroute.plan(world, (0, 2), (4, 2), algorithm="prm", samples=300)
    assert [kw["samples"] for kw in built] == [200, 300]  # the second query reused it
    for r in (first, again, other):
        assert r.extra["setup_seconds"] >= 0 and r.status is skyroute.Status.FOUND


def test_plan_world_shows_the_set_up_as_its_own_row_and_field(monkeypatch, capsys):
    points = ["--start=-3.1890,55.9456", "--goal=-3.1850,55.9432", "--altitude", "10"]
    code, out, err = run(monkeypatch, capsys, "plan-world", CITY, *points)
    assert code == 0, err
    rows = {line.split("│")[1].strip(): line.split("│")[2].strip()
            for line in out.splitlines() if line.count("│") == 3}
    assert rows["search time"].endswith(" ms")
    assert re.fullmatch(r"[\d,]+\.\d{3} ms \(first query: the visibility graph,.*",
                        rows["set-up time"])
    code, out, err = run(monkeypatch, capsys, "plan-world", CITY, *points, "--json")
    doc = json.loads(out)
    assert code == 0 and doc["setup_seconds"] > 0 and doc["seconds"] > 0
