"""Wall time of ``skyroute.prepare()`` on a random map, for one or more source trees.

Each tree is a folder (a checkout, its ``src``, any folder holding ``skyroute/``) or a
commit of this repository. For ``--rounds`` rounds, one fresh process per tree, in turn:
it builds a small map of the same share and method first (96x96, which loads the
compiled kernels), then ``--builds`` builds of ``random_grid(SIDE, SHARE, SEED)`` (the
bench's cells), each timed by the wall clock (``time.perf_counter``: a build waiting on
a thread that is not scheduled counts, which is the point when the machine is busy).
The load average is printed before each process, so a quiet run and a busy one can be
told apart.

Example (docs/benchmarks.md, section 12, "Contraction under load")::

    python benchmarks/prepare_time.py 9d611fd src --share 0.3 --method subgoal
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import Fail, check_counts, load_average, measure_in, resolve_tree, run_main

METHODS = ("auto", "subgoal", "jump")

MEASURE = """
import json, sys, time
import skyroute
from skyroute.bench.random_maps import random_grid
side, share, seed, method, builds = json.loads(sys.argv[1])
skyroute.prepare(random_grid(96, share, seed), method=method)
grid = random_grid(side, share, seed)
times, kinds = [], []
for _ in range(builds):
    t0 = time.perf_counter()
    index = skyroute.prepare(grid, method=method)
    times.append(time.perf_counter() - t0)
    kinds.append(index.accelerator)
print(json.dumps({"skyroute": skyroute.__file__, "seconds": times, "accelerator": kinds}))
"""


def parse(argv=None) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog="prepare_time.py", description=__doc__.split("\n\n")[0])
    p.add_argument("trees", metavar="TREE", nargs="+",
                   help="a folder holding skyroute, or a commit of this repository")
    p.add_argument("--side", type=int, default=512, help="map side in cells (default 512)")
    p.add_argument("--share", type=float, default=0.3,
                   help="share of blocked cells, 0 <= SHARE < 1 (default 0.3)")
    p.add_argument("--seed", type=int, default=0, help="the map's seed (default 0)")
    p.add_argument("--method", default="subgoal", choices=METHODS,
                   help="prepare()'s method (default subgoal)")
    p.add_argument("--builds", type=int, default=3, help="builds a process (default 3)")
    p.add_argument("--rounds", type=int, default=2,
                   help="processes a tree, in turn with the other trees (default 2)")
    p.add_argument("--json", type=Path, help="also write the runs to this file")
    a = p.parse_args(argv)
    if not 16 <= a.side <= 4096:
        raise Fail(f"--side {a.side}: expected 16 to 4096 cells")
    if not 0.0 <= a.share < 1.0:
        raise Fail(f"--share {a.share}: expected 0 <= SHARE < 1")
    check_counts(a, ("builds", "rounds"))
    return a


def main(argv=None) -> None:
    a = parse(argv)
    keep: list = []
    trees = [(spec, resolve_tree(spec, keep)) for spec in a.trees]
    job = json.dumps([a.side, a.share, a.seed, a.method, a.builds])
    runs = []
    for r in range(a.rounds):
        for spec, tree in trees:
            load = load_average()
            got = measure_in(tree, ["-c", MEASURE, job], repr(spec))
            runs.append({"tree": spec, "round": r + 1, "load": load, **got})
            secs = " ".join(f"{s:.2f}" for s in got["seconds"])
            print(f"{spec}: {secs} s ({', '.join(got['accelerator'])}; {load})",
                  flush=True)
    if a.json:
        a.json.write_text(json.dumps({"side": a.side, "share": a.share, "seed": a.seed,
                                      "method": a.method, "runs": runs}, indent=1))


if __name__ == "__main__":
    run_main(main)
