"""``bench world``'s city timing on the synthetic city: what it reports, not how fast."""

import numpy as np

import skyroute
from skyroute.bench.world import city_queries
from skyroute.world.synth import synth_city


def test_city_queries_reports_far_pairs_and_a_cached_build(tmp_path, monkeypatch):
    monkeypatch.setenv("SKYROUTE_CACHE", str(tmp_path))
    p = tmp_path / "c.csv"
    p.write_text(synth_city(np.random.default_rng(3)))
    world = skyroute.load_world(p, altitude=10, safety=2, frame="enu")
    rep = city_queries(world, 6, np.random.default_rng(0), no_path=1)
    xmin, ymin, xmax, ymax = world.bounds
    assert rep["min_dist"] == 0.6 * max(xmax - xmin, ymax - ymin)
    assert rep["queries"] == 6 and 0 < rep["found"] <= 6
    assert 0 < rep["median_ms"] <= rep["p95_ms"] <= rep["max_ms"]
    assert rep["first_with_build_seconds"] == rep["build_seconds"] + rep["first_seconds"]
    assert list(tmp_path.glob("visibility-*.npz"))  # the cached build read this file
    assert rep["no_path_pairs"] <= 1
