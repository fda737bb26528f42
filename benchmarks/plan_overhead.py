"""Where the time of one ``skyroute.plan`` call on a small grid goes: the compiled search
against the Python around it.

On a 32x32 map pyastar2d answers in 11-18 us, so the fixed cost of our call decides the
ratio (docs/benchmarks.md, section 13). This script times, warm, in one process, with
``timeit`` (best of ``--repeat`` x ``--number`` calls, us a call):

- ``plan()``: the whole call, ``skyroute.plan(grid, start, goal, algorithm=A)``;
- its parts, each alone, as ``plan()`` runs them on a grid: the option set from its cache
  (``grid_plan._grid_options``), the grid's search space (``space_of``), the two cells
  checked and flattened (``SearchSpace.flat_pair``), the option set's query call looked
  up in the grid's table (``runners``), the compiled call (the kernel's compiled entry,
  its arguments bound, and the tuple it hands back), the result built
  (``PlanResult.of_search``);
- the rest: the whole less its parts (calls between them, the clock reads, the tests in
  ``plan()``).

Every part is called through a Python function, as is the whole; the cost of calling an
empty one (printed) is taken off each. A part a tree does not have (older code) is shown
as ``-`` and the rest is then not given. Run it with the skyroute to measure importable
(``PYTHONPATH=src``); the first line says which was imported.

Example (docs/benchmarks.md, section 13 round 11)::

    PYTHONPATH=src python benchmarks/plan_overhead.py \\
        --map ../shared/data/movingai/random-32-32-10.map --query neighbours \\
        --algorithms jps --repeat 5 --number 200000
"""

from __future__ import annotations

import argparse
import json
import sys
import timeit
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import Fail, load_average, parse_random, random_blocked, run_main

ALGORITHMS = ("astar", "jps", "dijkstra", "theta", "lazy_theta")
PARTS = ("option set", "space_of", "flat_pair", "runner lookup", "compiled call",
         "of_search")


def parse(argv=None) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog="plan_overhead.py",
                                description=__doc__.split("\n\n")[0])
    where = p.add_mutually_exclusive_group()
    where.add_argument("--map", type=Path, metavar="PATH", help="a MovingAI .map file")
    where.add_argument("--random", metavar="SIDE:SHARE", default=None,
                       help="a random map (the bench's random_grid, --seed); the default, "
                            "32:0.1")
    p.add_argument("--seed", type=int, default=0, help="random map seed (default 0)")
    p.add_argument("--query", choices=("neighbours", "self"), default="neighbours",
                   help="two neighbouring free cells (the first in row order), or a cell "
                        "to itself (default neighbours)")
    p.add_argument("--start", metavar="X,Y", help="the start cell instead of --query")
    p.add_argument("--goal", metavar="X,Y", help="the goal cell (with --start)")
    p.add_argument("--algorithms", default="astar,jps",
                   help=f"comma-separated, of {', '.join(ALGORITHMS)} (default astar,jps)")
    p.add_argument("--repeat", type=int, default=5, help="timeit repeats (default 5)")
    p.add_argument("--number", type=int, default=100_000,
                   help="calls a repeat (default 100,000)")
    p.add_argument("--json", type=Path, metavar="PATH", help="also write the figures here")
    a = p.parse_args(argv)
    a.algorithms = [x for x in a.algorithms.split(",") if x]
    bad = [x for x in a.algorithms if x not in ALGORITHMS]
    if bad or not a.algorithms:
        raise Fail(f"--algorithms {','.join(a.algorithms)!r}: choose from "
                   f"{', '.join(ALGORITHMS)}")
    for flag, value in (("--repeat", a.repeat), ("--number", a.number)):
        if value < 1:
            raise Fail(f"{flag} {value} must be at least 1")
    if (a.start is None) != (a.goal is None):
        raise Fail("give --start and --goal together")
    if a.json is not None and not a.json.parent.is_dir():
        raise Fail(f"--json {a.json}: the folder {a.json.parent} does not exist")
    return a


def _cell(flag: str, text: str) -> tuple[int, int]:
    try:
        x, y = (int(v) for v in text.split(","))
    except ValueError:
        raise Fail(f"{flag} {text!r}: expected X,Y (two integers)") from None
    return x, y


def the_grid(a: argparse.Namespace):
    from skyroute.world.grid import Grid

    if a.map is not None:
        from skyroute.world.movingai import read_map

        if not a.map.is_file():
            raise Fail(f"--map {a.map}: no such file")
        return read_map(a.map)
    side, share = parse_random(a.random or "32:0.1")
    return Grid(random_blocked(side, share, a.seed),
                name=f"random-{side}-{share:g}-s{a.seed}")


def the_query(a: argparse.Namespace, grid) -> tuple[tuple[int, int], tuple[int, int]]:
    if a.start is not None:
        return _cell("--start", a.start), _cell("--goal", a.goal)
    free = ~np.asarray(grid.blocked, dtype=bool)
    pairs = np.argwhere(free[:, :-1] & free[:, 1:]) if a.query == "neighbours" else \
        np.argwhere(free)
    if not len(pairs):
        what = "two neighbouring free cells" if a.query == "neighbours" else "a free cell"
        raise Fail(f"{grid.name}: no {what} for --query {a.query}")
    y, x = (int(v) for v in pairs[0])
    return (x, y), ((x + 1, y) if a.query == "neighbours" else (x, y))


def best_us(fns: dict, repeat: int, number: int) -> dict:
    """us a call of each ``fns[name]()``: the best of ``repeat`` rounds of ``number``
    calls, the calls interleaved round by round so that a slower minute of the machine
    falls on every one alike."""
    timers = {name: timeit.Timer(fn) for name, fn in fns.items()}
    best = dict.fromkeys(fns, float("inf"))
    for _ in range(repeat):
        for name, timer in timers.items():
            best[name] = min(best[name], timer.timeit(number))
    return {name: b / number * 1e6 for name, b in best.items()}


def parts(grid, start, goal, algorithm: str) -> dict:
    """Each part of ``plan()``'s grid path, as a call of no arguments, where this tree
    has it (None where not)."""
    out: dict = dict.fromkeys(PARTS)
    try:
        from skyroute.result import STATUS_OF_CODE, PlanResult
        from skyroute.search.grid_plan import _grid_options
        from skyroute.search.space import space_of
    except ImportError:
        return out
    opts = _grid_options(algorithm, None, False, None, 1.0, None, None)
    space = space_of(grid)
    out["option set"] = lambda: _grid_options(algorithm, None, False, None, 1.0, None, None)
    out["space_of"] = lambda: space_of(grid)
    if not hasattr(space, "flat_pair") or not hasattr(space, "runners"):
        return out
    s, t = space.flat_pair(start, goal)
    out["flat_pair"] = lambda: space.flat_pair(start, goal)
    entry = space.runners.get(id(opts))
    if entry is None:
        return out
    run = entry[1]
    out["runner lookup"] = lambda: space.runners.get(id(opts))
    out["compiled call"] = lambda: run(s, t)
    code, expanded, frontier, los, path, cost = run(s, t)
    if hasattr(PlanResult, "of_search"):
        status = STATUS_OF_CODE[code]
        out["of_search"] = lambda: PlanResult.of_search(status, path, cost, expanded,
                                                        frontier, los, 1e-6, algorithm, {})
    return out


def main(argv=None) -> None:
    a = parse(argv)
    import skyroute

    grid = the_grid(a)
    start, goal = the_query(a, grid)
    skyroute.plan(grid, start, goal, algorithm=a.algorithms[0])  # a bad cell: one line now
    print(f"skyroute {skyroute.__file__}; {grid.name} {grid.width}x{grid.height}, "
          f"{start} -> {goal}; best of {a.repeat} x {a.number:,} calls; {load_average()}")
    report = {"map": grid.name, "start": start, "goal": goal, "algorithms": {}}
    empties = []
    for alg in a.algorithms:
        r = skyroute.plan(grid, start, goal, algorithm=alg)  # loads the kernel, builds
        fns = {"empty": lambda: None,
               "plan": lambda alg=alg: skyroute.plan(grid, start, goal, algorithm=alg)}
        found = parts(grid, start, goal, alg)
        fns.update({name: fn for name, fn in found.items() if fn is not None})
        us = best_us(fns, a.repeat, a.number)
        empty = us.pop("empty")
        empties.append(empty)
        row = {name: None if name not in us else us[name] - empty
               for name in ("plan", *PARTS)}
        known = [row[n] for n in PARTS]
        row["rest"] = None if None in known else row["plan"] - sum(known)
        row.update(expanded=int(r.expanded), cost=float(r.cost))
        report["algorithms"][alg] = row
    report["empty_call_us"] = min(empties)
    print(table(report, a.algorithms))
    if a.json is not None:
        a.json.write_text(json.dumps(report, indent=1))


def table(report: dict, algorithms: list[str]) -> str:
    rows = ["| us a call | " + " | ".join(algorithms) + " |",
            "|---|" + "---|" * len(algorithms)]
    for name in ("plan", *PARTS, "rest"):
        label = "plan() (whole)" if name == "plan" else name
        cells = [report["algorithms"][alg][name] for alg in algorithms]
        rows.append(f"| {label} | " + " | ".join("-" if c is None else f"{c:.3f}"
                                                 for c in cells) + " |")
    rows.append("| (expanded, length) | " + " | ".join(
        f"{report['algorithms'][alg]['expanded']}, {report['algorithms'][alg]['cost']:.3f}"
        for alg in algorithms) + " |")
    rows.append(f"(an empty call, taken off each: about {report['empty_call_us']:.3f} us)")
    return "\n".join(rows)


if __name__ == "__main__":
    run_main(main)
