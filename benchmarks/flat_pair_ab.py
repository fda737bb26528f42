"""A/B timing of ``SearchSpace.flat_pair`` (a query's two cells checked and flattened)
between two source trees, in one process, by CPU time.

A change to the inline check of every grid query costs tens of nanoseconds, below what
``plan_ab.py``'s processes can tell apart on a busy machine (the same tree against itself
gave 0.87-0.97 there). So this script loads ``skyroute/search/space.py`` of each tree
(a folder or a commit, as ``plan_ab.py`` takes them) as a module of its own, with the
skyroute this process imports for everything else, and swaps its ``flat_pair`` into
``SearchSpace`` in turn. It times, by ``time.thread_time``, ``--number`` calls a round,
the rounds of the two interleaved: the whole ``skyroute.plan(grid, start, goal,
algorithm=A)`` (two neighbouring free cells, the first in row order: a call that is
mostly Python), and ``flat_pair`` alone. It prints the best and median us (or ns) a
call of each and in how many paired rounds B was faster.

Example (docs/benchmarks.md, section 11, "A bool refused as a cell coordinate")::

    PYTHONPATH=src python benchmarks/flat_pair_ab.py main HEAD \\
        --map ../shared/data/movingai/random-32-32-10.map --number 20000 --rounds 21
"""

from __future__ import annotations

import argparse
import importlib.util
import statistics
import sys
import time
import timeit
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import Fail, check_counts, load_average, resolve_tree, run_main


def parse(argv=None) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog="flat_pair_ab.py", description=__doc__.split("\n\n")[0])
    p.add_argument("tree_a", metavar="TREE_A", help="a folder holding skyroute or a commit")
    p.add_argument("tree_b", metavar="TREE_B", help="the same, compared with TREE_A")
    p.add_argument("--map", type=Path, required=True, metavar="PATH",
                   help="a MovingAI .map file")
    p.add_argument("--algorithms", default="astar,jps", help="comma-separated grid "
                   "algorithms (default astar,jps)")
    p.add_argument("--number", type=int, default=20_000, help="calls a round (default "
                   "20,000)")
    p.add_argument("--rounds", type=int, default=21, help="rounds a tree (default 21)")
    a = p.parse_args(argv)
    check_counts(a, ("number",), 1, 10_000_000)
    check_counts(a, ("rounds",), 1, 1000)
    if not a.map.is_file():
        raise Fail(f"--map {a.map}: no such file")
    a.algorithms = [x for x in a.algorithms.split(",") if x]
    return a


def flat_pair_of(tree: Path, label: str):
    """``SearchSpace.flat_pair`` as ``tree``'s space.py defines it."""
    path = tree / "skyroute" / "search" / "space.py"
    if not path.is_file():
        raise Fail(f"tree {label} ({tree}): no skyroute/search/space.py")
    spec = importlib.util.spec_from_file_location(f"_space_{label}", path)
    module = importlib.util.module_from_spec(spec)
    try:
        spec.loader.exec_module(module)
        return module.SearchSpace.flat_pair
    except (ImportError, AttributeError) as exc:
        raise Fail(f"tree {label} ({tree}): its space.py does not load beside this "
                   f"skyroute: {exc}") from None


def rounds(fns: dict, number: int, count: int) -> dict:
    """Seconds a call of each of ``fns`` (name -> (setup, call)), per round, rounds
    interleaved."""
    out = {name: [] for name in fns}
    for _ in range(count):
        for name, (setup, call) in fns.items():
            setup()
            out[name].append(timeit.Timer(call, timer=time.thread_time).timeit(number)
                             / number)
    return out


def line(what: str, res: dict, unit: float, units: str) -> str:
    a, b = res["A"], res["B"]
    faster = sum(y < x for x, y in zip(a, b, strict=True))
    return (f"| {what} | {min(a) * unit:.3f} / {statistics.median(a) * unit:.3f} | "
            f"{min(b) * unit:.3f} / {statistics.median(b) * unit:.3f} | "
            f"{(statistics.median(b) - statistics.median(a)) * unit:+.3f} {units} | "
            f"{faster} of {len(a)} |")


def main(argv=None) -> None:
    a = parse(argv)
    import numpy as np

    import skyroute
    from skyroute.search.space import SearchSpace, space_of
    from skyroute.world.movingai import read_map

    keep: list = []
    pair = {label: flat_pair_of(resolve_tree(spec, keep), label)
            for label, spec in (("A", a.tree_a), ("B", a.tree_b))}
    grid = read_map(a.map)
    free = ~np.asarray(grid.blocked)
    y, x = (int(v) for v in np.argwhere(free[:, :-1] & free[:, 1:])[0])
    start, goal = (x, y), (x + 1, y)
    print(f"skyroute {skyroute.__file__}; {grid.name}, {start} -> {goal}; {a.rounds} "
          f"rounds of {a.number:,} calls, thread CPU time; {load_average()}")
    print("| call | A best / median | B best / median | B - A (medians) | B faster |")
    print("|---|---|---|---|---|")
    original = SearchSpace.flat_pair
    try:
        for alg in a.algorithms:
            skyroute.plan(grid, start, goal, algorithm=alg)  # kernels loaded, space built
            res = rounds({label: (lambda f=f: setattr(SearchSpace, "flat_pair", f),
                                  lambda alg=alg: skyroute.plan(grid, start, goal,
                                                                algorithm=alg))
                          for label, f in pair.items()}, a.number, a.rounds)
            print(line(f"plan() {alg} (us)", res, 1e6, "us"))
        space = space_of(grid)
        res = rounds({label: (lambda: None, lambda f=f: f(space, start, goal))
                      for label, f in pair.items()}, a.number * 5, a.rounds)
        print(line("flat_pair alone (ns)", res, 1e9, "ns"))
    finally:
        SearchSpace.flat_pair = original
        for tmp in keep:
            tmp.cleanup()


if __name__ == "__main__":
    run_main(main)
