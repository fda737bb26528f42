"""The synthetic city generator and the OMPL world benchmark."""

import json

import numpy as np
import pytest

import skyroute
from skyroute.bench.world import ompl_available, random_rect_world
from skyroute.world.synth import synth_city


def test_synth_city_is_seeded_and_home_is_free(tmp_path):
    a = synth_city(np.random.default_rng(3))
    assert a == synth_city(np.random.default_rng(3)) != synth_city(np.random.default_rng(4))
    p = tmp_path / "c.csv"
    p.write_text(a)
    world = skyroute.load_world(p, altitude=10, safety=2, frame="enu")
    assert world.is_free([[0, 0]])[0] and len(world.obstacles) > 36
    r = skyroute.plan(world, (0, 0), (-180, 120))
    assert r.found and world.segments_free(r.path[:-1], r.path[1:]).all()


@pytest.mark.parametrize("blocks", [0, 101, 10**9, 2.5, True])
def test_synth_city_blocks_are_limited(blocks):
    from skyroute.errors import OptionError
    from skyroute.world.synth import MAX_BLOCKS

    with pytest.raises(OptionError, match=f"must be a whole number from 1 to {MAX_BLOCKS}"):
        synth_city(np.random.default_rng(0), blocks=blocks)
    assert synth_city(np.random.default_rng(0), blocks=1).count("\n") >= 4


def test_random_rect_worlds_are_seeded():
    a, b = random_rect_world(5), random_rect_world(5)
    assert len(a.obstacles) == 20
    assert all(x.equals(y) for x, y in zip(a.obstacles, b.obstacles, strict=True))


@pytest.mark.slow
@pytest.mark.early_process("-m", "skyroute", "bench", "world", "--worlds", "1", "--budget",
                           "0.05", "--planners", "RRTConnect,PRM", "--json", "bw.json")
def test_bench_world_runs_end_to_end(early_process):
    # In a process of its own: OMPL's bindings (nanobind) report leaked instances only
    # when the interpreter exits, which an in-process run cannot see. Started when the
    # run begins (conftest), as its OMPL solves take their full time budgets.
    code, out, err, folder = early_process
    assert code == 0, err
    assert "visibility (1st, with build)" in out  # 160 columns in a pipe: not wrapped
    doc = json.loads((folder / "bw.json").read_text())
    rows = {r["runner"]: r for r in doc["worlds"][0]["rows"]}
    assert rows["visibility (again)"]["length_ratio"] == 1.0
    assert rows["prm, shortcut"]["length_ratio"] >= 1.0 - 1e-9
    if ompl_available():
        raw = rows["ompl RRTConnect"]
        simplified = rows["ompl RRTConnect, simplified"]  # timed with its simplification
        assert raw["exact"] and isinstance(raw["valid"], bool)
        assert simplified["seconds"] == pytest.approx(raw["seconds"] +
                                                      simplified["simplify_seconds"])
        # OMPL checks its motions at a resolution, so its paths may cut an obstacle's
        # corner (valid False, re-checked exactly) and then be shorter than the optimum;
        # a path that is exactly free never is
        if raw["valid"]:
            assert raw["raw_ratio"] >= 1.0 - 1e-9
        if simplified["valid"]:
            assert simplified["simplified_ratio"] >= 1.0 - 1e-9
    assert "leaked" not in err
