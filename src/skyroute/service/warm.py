"""Warm a worker before it takes requests: load the planners' compiled kernels and the
libraries ``POST /plan`` imports, so that no caller's first query pays for them.

A fresh process's first ``POST /plan`` imports numba, scipy, shapely and pyproj and loads
each kernel it runs from numba's on-disk cache: about 0.5 s on a bundled map and 2 s on a
world on an idle machine, five times that under load, paid by whichever caller came
first (and again for the first query of each algorithm). :func:`warm` runs a few tiny
queries through the same code as ``POST /plan`` - every grid algorithm and pruning on a
small map, each world reader and algorithm on a one-building world - and reads the
bundled maps. The app's lifespan calls it before the server accepts a connection
(``Settings.warm``; ``skyroute serve --no-warm`` skips it). With numba's cache in place it
takes about as long as those first queries did; without one (a fresh installation, or a
cache directory it cannot write) it compiles the kernels, as the first queries would
have, once.

A query that fails here is logged and skipped: warming never stops a server.
"""

from __future__ import annotations

import logging
import time

from skyroute.service.resources import Resources

log = logging.getLogger("skyroute.service")

# 8 x 5 cells with a wall to go round: every grid kernel expands, prunes and traces
TINY_MAP = """type octile
height 5
width 8
map
........
..@@@...
..@.@...
..@.....
........
"""
# one building in a FCND colliders.csv (metres round the home in its first line)
TINY_COLLIDERS = """lat0 55.944494, lon0 -3.186874
posX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ
0.0,0.0,10.0,5.0,5.0,10.0
"""
# one no-fly square inside a confinement area, in lon/lat
TINY_ZONES = """{"type": "FeatureCollection", "features": [
 {"type": "Feature", "properties": {"name": "zone"}, "geometry": {"type": "Polygon",
  "coordinates": [[[-3.1870, 55.9443], [-3.1866, 55.9443], [-3.1866, 55.9446],
                   [-3.1870, 55.9446], [-3.1870, 55.9443]]]}}]}
"""


def queries() -> list[dict]:
    """The ``POST /plan`` bodies :func:`warm` runs: each grid algorithm (astar also with
    each pruning, weighted and on a grown map) on :data:`TINY_MAP`, and each world
    algorithm on each world format."""
    grid = {"map_text": TINY_MAP, "start": [0, 0], "goal": [3, 2]}
    out = [{**grid, "algorithm": a} for a in ("astar", "dijkstra", "jps", "theta",
                                              "lazy_theta")]
    out.append({**grid, "algorithm": "bfs", "connectivity": 4})
    out += [{**grid, "prune": p} for p in ("collinear", "los")]
    out += [{**grid, "weight": 1.5}, {**grid, "safety": 0.5, "goal": [7, 4]}]
    west, east = [-3.18725, 55.94449], [-3.18650, 55.94449]
    for text, fmt in ((TINY_COLLIDERS, "colliders"), (TINY_ZONES, "geojson")):
        world = {"world_text": text, "world_format": fmt, "start": west, "goal": east,
                 "altitude": 5.0, "safety": 1.0}
        out.append({**world, "algorithm": "visibility"})
        out += [{**world, "algorithm": a, "resolution": 4.0} for a in ("astar", "theta")]
        out.append({**world, "algorithm": "prm", "samples": 50})
    return out


def warm(res: Resources) -> dict:
    """Run :func:`queries` through ``POST /plan``'s code on ``res`` and read the bundled
    maps into it; ``{"queries", "failed", "seconds"}``, also logged at INFO. A query that
    fails is logged as a warning and counted, never raised."""
    from skyroute.service.routers.plan import PlanRequest, _plan
    from skyroute.world.load import bundled_maps

    t0 = time.perf_counter()
    bodies = queries()
    failed = 0
    for body in bodies:
        try:
            _plan(PlanRequest.model_validate(body), res)
        except Exception as exc:  # a cold worker is slower, not broken
            failed += 1
            log.warning("warming the planners: %s on %s failed: %s",
                        body.get("algorithm"), "map_text" if "map_text" in body
                        else body["world_format"], " ".join(str(exc).split()))
    for body in bodies:  # a graph read from the disk cache loaded no build kernel
        if body.get("algorithm") == "visibility":
            _build_graph(body)
    for name in bundled_maps():
        res.grid(name)
    seconds = time.perf_counter() - t0
    log.info("warmed the planners in %.1f s (%d queries%s)", seconds, len(bodies),
             f", {failed} failed" if failed else "")
    return {"queries": len(bodies), "failed": failed, "seconds": seconds}


def _build_graph(body: dict) -> None:
    """Build the visibility graph of a warm-up world again, past the disk cache: a tiny
    world's graph built once (slowly, on a loaded machine or a cold numba cache) is kept
    there, and a warm-up that read it back left the build's kernels to the first real
    world's query. Logged and skipped on failure, as the queries are."""
    from skyroute.roadmap.visibility import VisibilityGraph
    from skyroute.service.routers.plan import PlanRequest, _world

    try:
        VisibilityGraph(_world(PlanRequest.model_validate(body)), cache=False)
    except Exception as exc:  # a cold worker is slower, not broken
        log.warning("warming the planners: the %s graph build failed: %s",
                    body["world_format"], " ".join(str(exc).split()))
