"""A worker is warm before its first request: the app's start-up (its lifespan, which
uvicorn finishes before it accepts a connection) loads every numba kernel that
``POST /plan`` runs, so no caller's query loads or compiles one.

Checked without a clock, in a fresh interpreter (the test process has loaded kernels
already): numba's record of each kernel's loaded signatures, taken after the start-up
and again after a battery of real queries, must not change."""

from __future__ import annotations

import json
import logging

import pytest

from tests.conftest import ROOT

# Runs in a process of its own: prints {"started": ..., "after": ..., "statuses": ...}
SCRIPT = r"""
import json, sys, warnings
from pathlib import Path
warnings.simplefilter("ignore")
from numba.core.dispatcher import Dispatcher
from fastapi.testclient import TestClient
from skyroute.service.app import create_app
from skyroute.service.settings import Settings

def loaded():
    # every compiled kernel of skyroute's modules and the signatures it has loaded
    out = {}
    for name, mod in list(sys.modules.items()):
        if name.startswith("skyroute"):
            for attr, obj in list(vars(mod).items()):
                if isinstance(obj, Dispatcher):
                    out[obj.py_func.__module__ + "." + obj.py_func.__qualname__] = \
                        sorted(str(s) for s in obj.signatures)
    return out

root = Path(sys.argv[1])
city = (root / "examples" / "city.csv").read_text()
zones = json.dumps({"type": "FeatureCollection", "features": [{"type": "Feature",
    "properties": {}, "geometry": {"type": "Polygon", "coordinates": [[
    [-3.1880, 55.9440], [-3.1870, 55.9440], [-3.1870, 55.9450], [-3.1880, 55.9450],
    [-3.1880, 55.9440]]]}}]})
queries = []
for name, s, g in [("den312d", [50, 76], [60, 13]), ("Berlin_1_256", [10, 10], [240, 245]),
                   ("Paris_1_512", [10, 10], [500, 500])]:
    for a in ("astar", "dijkstra", "jps", "theta", "lazy_theta"):
        queries.append({"map": name, "start": s, "goal": g, "algorithm": a})
    queries += [{"map": name, "start": s, "goal": g, "algorithm": "bfs", "connectivity": 4},
                {"map": name, "start": s, "goal": g, "prune": "los"},
                {"map": name, "start": s, "goal": g, "prune": "collinear", "weight": 2.0},
                {"map": name, "start": s, "goal": g, "algorithm": "theta",
                 "corner_cutting": True, "heuristic": "octile"}]
queries.append({"map": "den312d", "start": [61, 77], "goal": [20, 3], "safety": 1.5})
for text, fmt, s, g in [(city, "colliders", [-3.1890, 55.9456], [-3.1850, 55.9432]),
                        (zones, "geojson", [-3.1885, 55.9445], [-3.1865, 55.9445])]:
    for a in ("visibility", "prm", "astar", "jps", "lazy_theta"):
        queries.append({"world_text": text, "world_format": fmt, "start": s, "goal": g,
                        "altitude": 10, "safety": 2, "algorithm": a})
token = "warm-test-token-0001"
with TestClient(create_app(Settings(token=token, db_url="sqlite:///s.db"))) as client:
    started = loaded()
    statuses = [client.post("/plan", json=q, headers={"Authorization": f"Bearer {token}"})
                .status_code for q in queries]
    after = loaded()
print(json.dumps({"started": started, "after": after, "statuses": statuses}))
"""


@pytest.mark.slow
@pytest.mark.early_process("-c", SCRIPT, str(ROOT))
def test_no_query_loads_a_kernel_after_the_start_up(early_process):
    code, out, err, _ = early_process
    assert code == 0, err
    doc = json.loads(out)
    assert set(doc["statuses"]) == {200}, doc["statuses"]
    started, after = doc["started"], doc["after"]
    for kernel in ("skyroute.search.astar.astar_kernel", "skyroute.search.jps.jps_kernel",
                   "skyroute.search.theta.theta_kernel", "skyroute.search.bfs.bfs_kernel",
                   "skyroute.search.prune.prune_los"):
        assert started.get(kernel), (kernel, sorted(k for k, v in started.items() if v))
    loaded_late = {k: v for k, v in after.items() if started.get(k) != v}
    assert loaded_late == {}, "kernels a query loaded after the start-up"


def test_warming_can_be_turned_off_and_never_stops_the_app(tmp_path, monkeypatch, caplog):
    """``Settings(warm=False)`` starts without warming; a warm-up query that fails is
    one warning, and the app starts and answers all the same."""
    from fastapi.testclient import TestClient

    from skyroute.service import warm
    from skyroute.service.app import create_app
    from skyroute.service.settings import Settings

    db = f"sqlite:///{tmp_path / 's.db'}"
    with TestClient(create_app(Settings(token="warm-test-token-0001", db_url=db, warm=False))) as c:
        assert not hasattr(c.app.state, "warmed")
    broken = [*warm.queries(), {"map_text": "not a map", "start": [0, 0], "goal": [1, 1]}]
    monkeypatch.setattr(warm, "queries", lambda: broken)
    with TestClient(create_app(Settings(token="warm-test-token-0001", db_url=db))) as c:
        assert c.app.state.warmed["queries"] == len(broken)
        assert c.app.state.warmed["failed"] == 1
        assert c.get("/health").status_code == 200
    warned = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert len(warned) == 1 and "warming the planners: None on map_text failed: " \
        "map_text: line 1" in warned[0], warned


def test_the_warm_up_queries_are_found_paths():
    """Each warm-up query plans a path (a query that finds none might skip the kernels'
    tracing and pruning)."""
    from skyroute.service.resources import Resources
    from skyroute.service.routers.plan import PlanRequest, _plan
    from skyroute.service.settings import Settings
    from skyroute.service.warm import queries

    res = Resources(Settings(token="warm-test-token-0001"))
    for body in queries():
        out = _plan(PlanRequest.model_validate(body), res)
        assert out["status"] == "found" and len(out["path"]) >= 2, body


def test_the_warm_up_builds_its_graphs_past_the_disk_cache(tmp_path, monkeypatch):
    """A warm-up world's graph kept in the disk cache (its first build took longer than
    ``SAVE_AFTER``, as on a loaded machine) is built again all the same: read back, it
    loaded no build kernel, and the first real world's query loaded them (found by the
    test above, under load)."""
    from skyroute.roadmap import visibility
    from skyroute.service.resources import Resources
    from skyroute.service.settings import Settings
    from skyroute.service.warm import warm

    monkeypatch.setenv("SKYROUTE_CACHE", str(tmp_path))
    monkeypatch.setattr(visibility, "SAVE_AFTER", -1.0)  # every graph is kept
    res = Resources(Settings(token="warm-test-token-0001"))
    assert warm(res)["failed"] == 0
    kept = sorted(p.name for p in tmp_path.glob("visibility-*.npz"))
    assert len(kept) == 2, kept  # one for each world format, read back from now on
    built = []
    real = visibility._build
    monkeypatch.setattr(visibility, "_build", lambda w: built.append(w) or real(w))
    assert warm(res)["failed"] == 0
    assert len(built) == 2, built
