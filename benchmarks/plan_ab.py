"""A/B timing of ``skyroute.plan`` between two source trees, in-process and by CPU time.

Each tree is a folder (a checkout, its ``src``, any folder holding ``skyroute/``) or a
commit of this repository (``git archive COMMIT src`` into a temporary folder). The maps
and queries are made once, by the skyroute this script imports, as ``skyroute bench
grid`` makes them (a random map's far queries; a MovingAI map's scenario lines sampled
with the seed), and handed to every measuring process, so both trees answer the very
same queries.

Then ``--processes`` rounds of one fresh process per tree, alternating which tree goes
first. Each process imports its tree alone (``PYTHONPATH``), answers the first query once
with each runner (loading the kernels, building the index for ``prepared``), then times
``--rounds`` rounds: every query through every runner in turn (the order rotating each
round), each call timed by ``time.thread_time`` (CPU time of the thread: time the
scheduler gives other processes is not counted), optionally after reading ``--cold-mb``
MB so the caches are as cold as in the bench. A round's figure is its mean ms a query;
a process reports the median of its rounds. Runners: ``astar``, ``jps`` (``skyroute.plan``
with that algorithm), ``prepared`` (``skyroute.prepare(grid)`` once, then its ``plan``),
and ``--peer pyastar2d`` (its ``astar_path``, as the bench calls it).

The table gives each tree's process medians and B / A, the median of B's process
medians over A's; the two trees' path lengths are compared query by query.

Example (docs/benchmarks.md, section 13)::

    python benchmarks/plan_ab.py b7bd029 6a8a1bd --random 512:0.2 --random 512:0.3 \\
        --algorithms astar,jps --peer pyastar2d --rounds 7 --processes 3
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import (
    Fail,
    case_of,
    load_average,
    measure_in,
    resolve_tree,
    run_main,
)

RUNNERS = ("astar", "jps", "prepared")
PEERS = ("pyastar2d",)


def parse(argv=None) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog="plan_ab.py", description=__doc__.split("\n\n")[0],
        epilog="Run from the repository root with this checkout's skyroute importable "
               "(PYTHONPATH=src): it makes the maps and queries.")
    p.add_argument("tree_a", metavar="TREE_A", help="a folder holding skyroute (a "
                   "checkout, its src) or a commit of this repository")
    p.add_argument("tree_b", metavar="TREE_B", help="the same, compared with TREE_A")
    p.add_argument("--random", action="append", default=[], metavar="SIDE:SHARE",
                   help="a random map (the bench's random_grid, seed --seed), e.g. 512:0.2; "
                        "repeat for several")
    p.add_argument("--map", action="append", default=[], metavar="PATH",
                   help="a MovingAI .map with its .scen beside it; repeat for several")
    p.add_argument("--queries", type=int, default=20, help="queries a map (default 20)")
    p.add_argument("--seed", type=int, default=0, help="map and query seed (default 0)")
    p.add_argument("--algorithms", default="astar,jps",
                   help=f"comma-separated, of {', '.join(RUNNERS)} (default astar,jps)")
    p.add_argument("--peer", action="append", default=[], choices=PEERS,
                   help="also time this peer in the same turns")
    p.add_argument("--rounds", type=int, default=7, help="rounds a process (default 7)")
    p.add_argument("--processes", type=int, default=3,
                   help="processes a tree, alternating (default 3)")
    p.add_argument("--cold-mb", type=float, default=0.0, metavar="MB",
                   help="read this many MB before each call (32: caches as cold as in the "
                        "bench; default 0, warm)")
    p.add_argument("--json", type=Path, metavar="PATH", help="also write every figure here")
    p.add_argument("--worker", type=Path, help=argparse.SUPPRESS)
    a = p.parse_args(argv)
    if a.worker is None:
        check(a)
    return a


def check(a: argparse.Namespace) -> None:
    algorithms = [x for x in a.algorithms.split(",") if x]
    bad = [x for x in algorithms if x not in RUNNERS]
    if bad or not algorithms:
        raise Fail(f"--algorithms {a.algorithms!r}: choose from {', '.join(RUNNERS)}")
    a.algorithms = algorithms
    for flag, value in (("--queries", a.queries), ("--rounds", a.rounds),
                        ("--processes", a.processes)):
        if value < 1:
            raise Fail(f"{flag} {value} must be at least 1")
    if a.cold_mb < 0:
        raise Fail(f"--cold-mb {a.cold_mb:g} must be 0 or more")
    if not a.random and not a.map:
        a.random = ["512:0.2", "512:0.3"]
    if a.json is not None and not a.json.parent.is_dir():
        raise Fail(f"--json {a.json}: the folder {a.json.parent} does not exist")


def main(argv=None) -> None:
    a = parse(argv)
    if a.worker is not None:
        print(json.dumps(measure(json.loads(a.worker.read_text()))))
        return
    keep: list = []
    trees = {"A": resolve_tree(a.tree_a, keep), "B": resolve_tree(a.tree_b, keep)}
    with tempfile.TemporaryDirectory(prefix="plan-ab-") as tmp:
        maps = []
        for spec in a.random:
            maps.append(case_of(random=spec, queries=a.queries, seed=a.seed))
        for path in a.map:
            maps.append(case_of(map_path=path, queries=a.queries, seed=a.seed))
        job = {"maps": [], "runners": a.algorithms + a.peer, "rounds": a.rounds,
               "cold_bytes": int(a.cold_mb * 1e6)}
        for k, case in enumerate(maps):
            path = Path(tmp) / f"map{k}.npz"
            np.savez(path, **{key: v for key, v in case.items() if key != "name"})
            job["maps"].append({"name": case["name"], "npz": str(path)})
        spec = Path(tmp) / "job.json"
        spec.write_text(json.dumps(job))
        cold = f"{a.cold_mb:g} MB read before each call" if a.cold_mb else "warm"
        print(f"A = {a.tree_a} ({trees['A']}), B = {a.tree_b} ({trees['B']}); "
              f"{a.queries} queries a map, {a.rounds} rounds a process, {a.processes} "
              f"processes a tree, {cold}; {load_average()} at the start")
        runs: dict[str, list] = {"A": [], "B": []}
        for p in range(a.processes):
            for label in ("AB" if p % 2 == 0 else "BA"):
                runs[label].append(_run(trees[label], spec, label))
    report = summary(runs, job)
    print(table(report, a.processes))
    print(f"{load_average()} at the end")
    if a.json is not None:
        a.json.write_text(json.dumps({"trees": {"A": a.tree_a, "B": a.tree_b},
                                      "settings": {k: v for k, v in vars(a).items()
                                                   if k not in ("json", "worker")},
                                      "rows": report, "processes": runs}, indent=1,
                                     default=str))


def _run(tree: Path, spec: Path, label: str) -> dict:
    return measure_in(tree, [__file__, "A", "B", "--worker", str(spec)], label)


def measure(job: dict) -> dict:
    """In the measuring process: every map's runners timed; ``{"skyroute", "maps"}``."""
    import time

    import skyroute
    from skyroute.world.grid import Grid

    cold = np.ones(max(job["cold_bytes"] // 8, 1))
    out = {"skyroute": skyroute.__file__, "maps": []}
    for m in job["maps"]:
        data = np.load(m["npz"])
        grid = Grid(data["blocked"], name=m["name"])
        pairs = [(tuple(s.tolist()), tuple(t.tolist()))
                 for s, t in zip(data["starts"], data["goals"], strict=True)]
        runners = {name: _runner(name, grid) for name in job["runners"]}
        costs = {name: [] for name in runners}
        for run, _ in runners.values():  # warm-up: kernels, index, caches
            run(*pairs[0])
        for s, t in pairs:
            for name, (run, cost) in runners.items():
                costs[name].append(cost(run(s, t)))
        rounds = {name: [] for name in runners}
        order = list(runners)
        for r in range(job["rounds"]):
            total = dict.fromkeys(order, 0.0)
            turn = order[r % len(order):] + order[:r % len(order)]
            for s, t in pairs:
                for name in turn:
                    run = runners[name][0]
                    if job["cold_bytes"]:
                        cold.sum()  # read: evicts the last call's data from the caches
                    t0 = time.thread_time()
                    run(s, t)
                    total[name] += time.thread_time() - t0
            for name in order:
                rounds[name].append(total[name] * 1e3 / len(pairs))
        out["maps"].append({"map": m["name"], "runners": {
            name: {"median_ms": statistics.median(rounds[name]), "rounds_ms": rounds[name],
                   "costs": costs[name]} for name in order}})
    return out


def _runner(name: str, grid):
    """(call(start, goal), the answer's path length or None)."""
    if name == "pyastar2d":
        import pyastar2d

        weights = np.where(grid.blocked, np.inf, 1.0).astype(np.float32)

        def peer(s, t):
            return pyastar2d.astar_path(weights, (s[1], s[0]), (t[1], t[0]),
                                        allow_diagonal=True)

        def peer_cost(path):
            if path is None:
                return None
            d = np.abs(np.diff(path, axis=0)).sum(axis=1)
            return float(np.where(d == 2, 2 ** 0.5, 1.0).sum())
        return peer, peer_cost

    def cost(r):
        return float(r.cost) if r.status.value == "found" else None

    if name == "prepared":
        return __import__("skyroute").prepare(grid).plan, cost
    plan = __import__("skyroute").plan
    return (lambda s, t: plan(grid, s, t, algorithm=name)), cost


def summary(runs: dict, job: dict) -> list[dict]:
    """One row a map and runner: each tree's process medians, B / A, and whether the two
    trees' path lengths agree on every query."""
    rows = []
    for k, m in enumerate(job["maps"]):
        for name in job["runners"]:
            per = {label: [p["maps"][k]["runners"][name] for p in runs[label]]
                   for label in "AB"}
            a = [x["median_ms"] for x in per["A"]]
            b = [x["median_ms"] for x in per["B"]]
            ca, cb = per["A"][0]["costs"], per["B"][0]["costs"]
            same = all((x is None) == (y is None) and (x is None or abs(x - y) <= 1e-9)
                       for x, y in zip(ca, cb, strict=True))
            rows.append({"map": m["name"], "runner": name, "a_ms": a, "b_ms": b,
                         "b_over_a": statistics.median(b) / statistics.median(a),
                         "same_lengths": same})
    return rows


def table(rows: list[dict], processes: int) -> str:
    head = "| map | runner | A ms | B ms | B / A | same lengths |\n|---|---|---|---|---|---|"
    body = [f"| {r['map']} | {r['runner']} | {' / '.join(f'{x:.3f}' for x in r['a_ms'])} | "
            f"{' / '.join(f'{x:.3f}' for x in r['b_ms'])} | {r['b_over_a']:.3f} | "
            f"{'yes' if r['same_lengths'] else 'NO'} |" for r in rows]
    return "\n".join([head, *body])


if __name__ == "__main__":
    run_main(main)
