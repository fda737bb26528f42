"""CPU time of the step drone's fewest-moves search (``skyroute.motion.step_drone.
plan_moves``) on a colliders.csv city or on the ILP map, with what each query found, so
that two source trees can be compared.

Each query is planned once untimed (the per-world tables: zone edges and their bucket
grid, the corner table, the goal's corner distances; every kernel compiled), then
``--reps`` times under ``time.process_time``. One JSON line per query: status, moves,
expansions, a sha1 of the move list (``Flight.rows()``) and the CPU seconds of each
repetition; then one line of totals (CPU per repetition summed over the queries, and a
sha1 of every query's sha1 in order). On a city (``--city``) the points are in metres
in the NED frame, as ``skyroute fly --frame ned`` takes them (the drone flies the ILP
rules on the lon/lat plane); with ``--ilp`` the queries are every ordered pair of the ILP
places (testing/all.geojson) in the no-fly zones and the confinement area. Run it with
the skyroute to measure importable; to compare two trees, run it with each on
``PYTHONPATH`` in turn, alternating (the expansions and sha1 must agree).

Example (docs/benchmarks.md, section 6)::

    PYTHONPATH=src python benchmarks/step_cpu.py --city ../shared/data/fcnd/colliders.csv \\
        --altitude 5 --safety 5 --reps 2 '0,0;489.77,-199.23' '0,0;300,-199'
    PYTHONPATH=src python benchmarks/step_cpu.py --ilp ../shared/data/ilp2021 --reps 2
"""

from __future__ import annotations

import argparse
import hashlib
import itertools
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import Fail, check_counts, ned_queries, parser, run_main


def parse(argv=None) -> argparse.Namespace:
    p = parser("step_cpu.py", __doc__.split("\n\n")[0])
    where = p.add_mutually_exclusive_group(required=True)
    where.add_argument("--city", type=Path, help="a colliders.csv file (give QUERIES)")
    where.add_argument("--ilp", type=Path, metavar="DIR",
                       help="the ILP data folder: every ordered pair of its places")
    p.add_argument("queries", nargs="*", metavar="S;G",
                   help="with --city: start and goal, 'N,E;N,E' in metres (NED)")
    p.add_argument("--altitude", type=float, default=None, help="flight altitude (m)")
    p.add_argument("--safety", type=float, default=0.0, help="safety margin (m)")
    p.add_argument("--reps", type=int, default=3, help="timed repetitions (default 3)")
    return p.parse_args(argv)


def city_queries(args: argparse.Namespace) -> tuple:
    """(the world in the degrees frame, [(label, start, goal)]) of ``--city``."""
    from skyroute.cli.world_args import load_world_file

    queries = ned_queries(args.queries, headings=False)
    if not queries:
        raise Fail("--city: give one or more queries 'N,E;N,E'")
    if not args.city.is_file():
        raise Fail(f"{args.city}: no such file")
    world = load_world_file(args.city, altitude=args.altitude, safety=args.safety,
                            boundary=None, frame="ned")
    for q, s, g in queries:
        world.check_point(s, f"query {q!r}: start")
        world.check_point(g, f"query {q!r}: goal")
    return world.in_frame("degrees"), [(q, world.to_lonlat(s)[0], world.to_lonlat(g)[0])
                                       for q, s, g in queries]


def ilp_queries(args: argparse.Namespace) -> tuple:
    """(the ILP world, [(label, start, goal)] for every ordered pair of its places)."""
    from skyroute.bench.motion import load_ilp

    if args.queries or args.altitude is not None or args.safety:
        raise Fail("--ilp: the queries are the ILP places' pairs; give no queries, "
                   "--altitude or --safety")
    if not args.ilp.is_dir():
        raise Fail(f"--ilp {args.ilp}: no such folder")
    world, places = load_ilp(args.ilp)
    return world, [(f"{a} -> {b}", places[a], places[b])
                   for a, b in itertools.permutations(places, 2)]


def main() -> None:
    args = parse()
    check_counts(args, ("reps",))
    from skyroute.motion.step_drone import plan_moves

    world, queries = city_queries(args) if args.city is not None else ilp_queries(args)
    totals = [0.0] * args.reps
    digest = hashlib.sha1()
    for q, s, g in queries:
        plan_moves(world, s, g)  # this goal's tables, every kernel compiled
        cpu = []
        for _ in range(args.reps):
            c0 = time.process_time()
            f = plan_moves(world, s, g)
            cpu.append(round(time.process_time() - c0, 4))
        totals = [t + c for t, c in zip(totals, cpu, strict=True)]
        sha1 = hashlib.sha1(repr(f.rows()).encode()).hexdigest()[:10]
        digest.update(sha1.encode())
        print(json.dumps({"query": q, "status": f.status.value, "moves": f.moves,
                          "expanded": f.expanded, "sha1": sha1, "cpu": cpu}), flush=True)
    print(json.dumps({"total": len(queries), "sha1": digest.hexdigest()[:10],
                      "cpu": [round(t, 4) for t in totals]}), flush=True)


if __name__ == "__main__":
    run_main(main)
