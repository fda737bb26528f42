"""A*, Dijkstra and JPS against the MovingAI scenario optima (Sturtevant 2012).

CI checks a seeded sample of lines of each of the 18 maps; `skyroute bench grid
--per-map 0` checks every line (docs/benchmarks.md).
"""

import numpy as np
import pytest

import skyroute
from skyroute.world.movingai import read_map, read_scen
from tests.conftest import movingai_pairs
from tests.search.checks import assert_grid_path_legal

PAIRS = movingai_pairs()
PER_MAP = 12


@pytest.mark.shared_data
@pytest.mark.parametrize("map_path, scen_path", PAIRS, ids=[m.stem for m, _ in PAIRS])
def test_optimal_costs_match_scenarios(map_path, scen_path):
    grid, scen = read_map(map_path), read_scen(scen_path)
    rng = np.random.default_rng(20261122)
    lines = rng.choice(len(scen), size=min(PER_MAP, len(scen)), replace=False)
    lines = np.append(lines, len(scen) - 1)  # the hardest bucket too
    for i in lines:
        s, t = tuple(scen.starts[i]), tuple(scen.goals[i])
        for algorithm in ("astar", "dijkstra", "jps"):
            r = skyroute.plan(grid, s, t, algorithm=algorithm)
            assert r.found, (map_path.name, i, algorithm)
            assert scen.matches(int(i), r.cost), (map_path.name, i, algorithm, r.cost,
                                                  scen.optimal[i])
            assert tuple(r.path[0]) == s and tuple(r.path[-1]) == t
            walked = assert_grid_path_legal(grid.blocked, r.path)
            assert walked == pytest.approx(r.cost, rel=1e-9)


def test_scenario_costs_fail_with_corner_cutting():
    # The control of SOURCES.md: allowing corner cutting gives shorter, wrong costs. It
    # needs only the den312d map and scenarios bundled with skyroute, so it always runs.
    grid = skyroute.load_map("den312d")
    scen = read_scen(skyroute.bundled_maps()["den312d"].with_suffix(".map.scen"))
    shorter = 0
    for i in range(0, len(scen), 10):
        r = skyroute.plan(grid, tuple(scen.starts[i]), tuple(scen.goals[i]),
                          corner_cutting=True)
        assert r.cost <= scen.optimal[i] + 1e-6
        shorter += r.cost < scen.optimal[i] - 1e-6
        assert_grid_path_legal(grid.blocked, r.path, corner_cutting=True)
    assert shorter > 0
