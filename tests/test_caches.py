"""Caches are keyed by what changes their value and can be cleared from Python."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

import skyroute
from skyroute.delivery import assemble
from skyroute.roadmap.world_plan import roadmap_edges
from skyroute.search.space import _SPACES


def test_clear_caches_empties_roadmaps_and_search_spaces():
    world = skyroute.World([shapely.box(1, 1, 3, 3)], [0], [50], ("tower",))
    grid = skyroute.load_map("den312d")
    skyroute.plan(world, (0, 2), (4, 2))
    skyroute.plan(grid, (50, 76), (60, 13))
    assert roadmap_edges(world, "visibility") is not None and id(grid) in _SPACES
    skyroute.clear_caches()
    assert roadmap_edges(world, "visibility") is None and id(grid) not in _SPACES
    again = skyroute.plan(world, (0, 2), (4, 2))  # rebuilt on demand
    assert round(again.cost, 6) == 4.828427


def test_a_search_space_goes_with_its_grid():
    import gc

    grids = [skyroute.Grid(np.zeros((5, 5), bool)) for _ in range(3)]
    for g in grids:
        skyroute.plan(g, (0, 0), (4, 4))
    keys = [id(g) for g in grids]
    assert all(k in _SPACES for k in keys)
    skyroute.clear_caches()
    skyroute.plan(grids[0], (0, 0), (4, 4))  # a second entry for the same grid
    del grids, g
    gc.collect()
    assert not any(k in _SPACES for k in keys)
    # grids made and dropped one after another reuse ids: each gets its own space
    for i in range(40):
        h, w = 2 + i % 5, 2 + i % 3
        g = skyroute.Grid(np.zeros((h, w), bool))
        r = skyroute.plan(g, (0, 0), (w - 1, h - 1))
        dx, dy = w - 1, h - 1
        assert r.cost == pytest.approx(max(dx, dy) + (np.sqrt(2) - 1) * min(dx, dy))
        assert r.path[-1].tolist() == [dx, dy]
        with pytest.raises(skyroute.QueryError):  # the bounds are this grid's
            skyroute.plan(g, (0, 0), (w, 0))
        del g


def test_leg_cache_is_keyed_by_world():
    """The same start and goal among other zones is another leg, not a cache hit."""
    box = shapely.box(-3.20, 55.94, -3.18, 55.95)
    open_world = skyroute.World([], [], [], (), box, "degrees")
    wall = shapely.box(-3.1905, 55.9420, -3.1895, 55.9480)
    walled = skyroute.World([wall], [-np.inf], [np.inf], ("wall",), box, "degrees")
    start, goal = np.array([-3.1950, 55.9450]), (-3.1850, 55.9450)
    straight = assemble.leg(open_world, start, goal)
    around = assemble.leg(walled, start, goal)
    assert around.moves > straight.moves
    assert walled in assemble._LEGS and open_world in assemble._LEGS
    skyroute.clear_caches()
    assert len(assemble._LEGS) == 0
