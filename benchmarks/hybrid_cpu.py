"""CPU time of Hybrid A* queries (``skyroute.motion.hybrid.plan``) on a colliders.csv
city, with what each query found, so that two source trees can be compared.

Each query is planned once untimed (the per-world tables: edge buckets, corner graph, the
goal's corner distances; the first query also once in full, so that every kernel is
compiled), then ``--reps`` times under ``time.process_time``. One JSON line per query:
status, expansions, analytic tries, length, a sha1 of the pieces (kind, start pose,
length), and the CPU seconds of each repetition. Points and headings (degrees, clockwise
from north) are in the NED frame, as ``skyroute fly --frame ned``. Run it with the
skyroute to measure importable; to compare two trees, run it with each on
``PYTHONPATH`` in turn, alternating (the expansions and sha1 must agree).

Example (docs/benchmarks.md, section 8)::

    PYTHONPATH=src python benchmarks/hybrid_cpu.py ../shared/data/fcnd/colliders.csv \\
        --altitude 5 --safety 5 --radius 10 --reps 2 '0,0;-300,250' '0,0;250,-300'
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import Fail, check_counts, ned_queries, parser, run_main


def parse(argv=None) -> argparse.Namespace:
    p = parser("hybrid_cpu.py", __doc__.split("\n\n")[0])
    p.add_argument("city", type=Path, help="a colliders.csv file")
    p.add_argument("queries", nargs="+", metavar="S;G",
                   help="start and goal, 'N,E[,HEADING];N,E[,HEADING]' in metres (NED)")
    p.add_argument("--altitude", type=float, default=None, help="flight altitude (m)")
    p.add_argument("--safety", type=float, default=0.0, help="safety margin (m)")
    p.add_argument("--radius", type=float, default=10.0, help="turning radius (m)")
    p.add_argument("--reps", type=int, default=3, help="timed repetitions (default 3)")
    return p.parse_args(argv)


def main() -> None:
    args = parse()
    check_counts(args, ("reps",))
    queries = ned_queries(args.queries)
    if not args.city.is_file():
        raise Fail(f"{args.city}: no such file")
    from skyroute.cli.world_args import load_world_file
    from skyroute.motion.hybrid import plan

    world = load_world_file(args.city, altitude=args.altitude, safety=args.safety,
                            boundary=None, frame="ned")
    for n, (q, s, g) in enumerate(queries):
        plan(world, s, g, args.radius, max_expansions=50)  # this goal's tables
        if n == 0:
            plan(world, s, g, args.radius)  # every kernel a found path runs, compiled
        cpu = []
        for _ in range(args.reps):
            c0 = time.process_time()
            r = plan(world, s, g, args.radius)
            cpu.append(round(time.process_time() - c0, 4))
        pieces = repr([(p.kind, p.start, p.length) for p in r.segments]).encode()
        print(json.dumps({"query": q, "status": r.status.value, "expanded": r.expanded,
                          "tries": r.extra.get("tries"), "length": round(r.length, 6),
                          "sha1": hashlib.sha1(pieces).hexdigest()[:10], "cpu": cpu}),
              flush=True)


if __name__ == "__main__":
    run_main(main)
