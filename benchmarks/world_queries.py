"""CPU time of a World's exact queries on a colliders city, for one or more source trees,
and how many segments through the faces its boxes share each tree calls free.

Each tree is a folder (a checkout, its ``src``, any folder holding ``skyroute/``) or a
commit of this repository. For ``--rounds`` rounds, one fresh process per tree and
safety, in turn: it loads the city at ``--altitude`` (timed: ``load_world``, ``at`` and
the obstacles' STRtree) and times, as process CPU time (best of ``--repeats``),
``is_free`` on 20,000 seeded random points, ``segments_free`` on 5,000 random 40 m
segments, ``segment_free`` on the first 1,000 one by one, and ``segments_free`` on the
segments between two box corners less than 60 m apart. It then counts the faces two
boxes share, run 3 m past both ends: those whose ends lie outside the union of the
boxes and that meet its interior (they pass through a building), and how many of those
the tree calls free (``through_called_free``; 0 is right).

Example (docs/benchmarks.md, section 5, "Touching obstacles as one building")::

    python benchmarks/world_queries.py 5fc9d67 src --city ../shared/data/fcnd/colliders.csv
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import Fail, check_counts, load_average, measure_in, resolve_tree, run_main

MEASURE = """
import json, sys, time
import numpy as np, shapely
import skyroute
from skyroute.world.load import load_world
city, altitude, safety, repeats = json.loads(sys.argv[1])
t0 = time.process_time()
w = load_world(city, safety=safety, frame="enu").at(altitude)
w.tree
load = time.process_time() - t0
if len(w.obstacles) == 0:
    raise SystemExit(f"no obstacle at altitude {altitude}")
rng = np.random.default_rng(1)
x0, y0, x1, y1 = w.bounds
pts = rng.uniform([x0, y0], [x1, y1], size=(20000, 2))
a = rng.uniform([x0, y0], [x1, y1], size=(5000, 2))
ang = rng.uniform(0, 2 * np.pi, 5000)
b = a + 40 * np.c_[np.cos(ang), np.sin(ang)]
cs = shapely.get_coordinates(w.obstacles)
ca, cb = cs[rng.integers(0, len(cs), 3000)], cs[rng.integers(0, len(cs), 3000)]
near = np.linalg.norm(ca - cb, axis=1) < 60
ca, cb = ca[near], cb[near]
ms = {}
for name, f in (("is_free", lambda: w.is_free(pts)),
                ("segments_free", lambda: w.segments_free(a, b)),
                ("segment_free", lambda: [w.segment_free(a[i], b[i]) for i in range(1000)]),
                ("corner_segments", lambda: w.segments_free(ca, cb))):
    f()
    ts = []
    for _ in range(repeats):
        t = time.process_time()
        f()
        ts.append(time.process_time() - t)
    ms[name] = 1e3 * min(ts)
union = shapely.union_all(w.obstacles)
shapely.prepare(union)
i, j = w.tree.query(w.obstacles, predicate="intersects")
keep = i < j
shared = shapely.intersection(w.obstacles[i[keep]], w.obstacles[j[keep]])
faces = [g for g in shapely.get_parts(shared) if g.geom_type == "LineString" and g.length > 0]
ends = []
for g in faces:
    p, q = np.asarray(g.coords)[[0, -1]]
    d = (q - p) / np.linalg.norm(q - p)
    ends.append((p - 3 * d, q + 3 * d))
ends = np.array(ends).reshape(-1, 2, 2)
outside = ~shapely.contains(union, shapely.points(ends[:, 0])) & \\
    ~shapely.contains(union, shapely.points(ends[:, 1]))
enters = np.array([union.relate_pattern(shapely.LineString(e), "T********") for e in ends],
                  dtype=bool)
through = outside & enters
free = w.segments_free(ends[:, 0], ends[:, 1])
print(json.dumps({"skyroute": skyroute.__file__, "load_ms": 1e3 * load, "ms": ms,
                  "corner_segments": int(len(ca)), "shared_faces": len(faces),
                  "through": int(through.sum()),
                  "through_called_free": int((free & through).sum())}))
"""


def parse(argv=None) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog="world_queries.py", description=__doc__.split("\n\n")[0])
    p.add_argument("trees", metavar="TREE", nargs="+",
                   help="a folder holding skyroute, or a commit of this repository")
    p.add_argument("--city", type=Path, required=True, help="a colliders.csv file")
    p.add_argument("--altitude", type=float, default=5.0,
                   help="altitude in metres (default 5)")
    p.add_argument("--safety", type=float, nargs="+", default=[0.0, 5.0],
                   help="safety margins in metres, one process each (default 0 5)")
    p.add_argument("--repeats", type=int, default=7,
                   help="timings of each query, the best kept (default 7)")
    p.add_argument("--rounds", type=int, default=3,
                   help="processes a tree and safety, in turn with the others (default 3)")
    p.add_argument("--json", type=Path, help="also write the runs to this file")
    a = p.parse_args(argv)
    if not a.city.is_file():
        raise Fail(f"--city {a.city}: no such file")
    if not all(0.0 <= s < 1e4 for s in a.safety) or not 0.0 <= a.altitude < 1e4:
        raise Fail("--altitude and --safety: expected 0 to 10,000 m")
    check_counts(a, ("repeats", "rounds"))
    return a


def main(argv=None) -> None:
    a = parse(argv)
    keep: list = []
    trees = [(spec, resolve_tree(spec, keep)) for spec in a.trees]
    runs = []
    for r in range(a.rounds):
        for safety in a.safety:
            job = json.dumps([str(a.city.resolve()), a.altitude, safety, a.repeats])
            for spec, tree in trees:
                load = load_average()
                got = measure_in(tree, ["-c", MEASURE, job], repr(spec))
                runs.append({"tree": spec, "round": r + 1, "safety": safety, "load": load,
                             **got})
                times = ", ".join(f"{k} {v:.1f}" for k, v in got["ms"].items())
                print(f"{spec}: safety {safety:g}: load {got['load_ms']:.0f}, {times} ms; "
                      f"{got['through_called_free']} of {got['through']} segments through "
                      f"shared faces called free ({load})", flush=True)
    if a.json:
        a.json.write_text(json.dumps({"city": str(a.city), "altitude": a.altitude,
                                      "runs": runs}, indent=1))


if __name__ == "__main__":
    run_main(main)
