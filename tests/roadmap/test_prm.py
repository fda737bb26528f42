"""PRM: reproducible for a seed (in one process and across processes), honest statistics."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

import skyroute
from skyroute.bench.world import random_rect_world
from skyroute.roadmap.prm import PRM

QUERY = ((5.0, 5.0), (95.0, 95.0))


def plan_twice(seed: int) -> tuple:
    world = random_rect_world(11)
    a = skyroute.plan(world, *QUERY, algorithm="prm", samples=400, seed=seed)
    b = skyroute.plan(world, *QUERY, algorithm="prm", samples=400, seed=seed)  # cached map
    c = skyroute.plan(random_rect_world(11), *QUERY, algorithm="prm", samples=400, seed=seed)
    return a, b, c


def test_same_seed_same_path_on_every_call():
    a, b, c = plan_twice(4)
    assert a.found
    np.testing.assert_array_equal(a.path, b.path)  # second query on the same roadmap
    np.testing.assert_array_equal(a.path, c.path)  # a new world, a new roadmap
    other = plan_twice(5)[0]
    assert not np.array_equal(a.path, other.path)  # the seed matters


def test_same_seed_same_path_in_another_process():
    code = ("import json, skyroute; from skyroute.bench.world import random_rect_world; "
            f"r = skyroute.plan(random_rect_world(11), {QUERY[0]}, {QUERY[1]}, "
            "algorithm='prm', samples=400, seed=4); print(json.dumps(r.path.tolist()))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    np.testing.assert_array_equal(json.loads(out), plan_twice(4)[0].path)


def test_max_expansions_is_refused_and_expanded_counts_settled_nodes():
    world = random_rect_world(11)
    with pytest.raises(skyroute.OptionError, match="max_expansions"):
        skyroute.plan(world, *QUERY, algorithm="prm", samples=200, max_expansions=10)
    rm = PRM(world, samples=300, seed=1)
    near = rm.plan(np.array([5.0, 5.0]), np.array([6.0, 5.0]))
    far = rm.plan(np.array([5.0, 5.0]), np.array([95.0, 95.0]))
    assert near.found and far.found
    # Dijkstra settles the nodes no farther than the goal: few for a near goal
    assert 0 < near.expanded < far.expanded <= 302
    with pytest.raises(skyroute.OptionError, match="seed"):
        PRM(world, samples=300, seed=-1)
