"""Peak resident memory that ``skyroute.prepare()`` adds on a random map, by
``getrusage``.

For each blocked share, a fresh Python process (so nothing an earlier build held is
counted) prepares a small random map of the same share and method first (96x96: both
kinds of index built), which loads their compiled kernels, then reads its
maximum resident set (``resource.getrusage``'s ``ru_maxrss``), runs
``prepare(random_grid(SIDE, SHARE, SEED), method=METHOD)`` (the bench's ``random_grid``:
the same cells) and reads it again. The figure is the rise:
what the build needed above the most the process had held before. A high-water mark
already above the build's own needs (a large import, the small build) hides part of it,
so it is a lower bound of the build's peak; ``skyroute bench grid --prepared`` measures
the build's peak differently (``build_peak_bytes``: the kernel's record reset through
``/proc/self/clear_refs`` before a second build). MB here are 10**6 bytes.

Run it with the skyroute to measure importable (``PYTHONPATH=src``).

Example (docs/benchmarks.md, section 13 round 3)::

    PYTHONPATH=src python benchmarks/prepare_memory.py --side 512 --share 0.1 0.2 0.3
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import Fail, load_average, random_blocked, run_main

METHODS = ("auto", "subgoal", "jump")


def parse(argv=None) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog="prepare_memory.py",
                                description=__doc__.split("\n\n")[0])
    p.add_argument("--side", type=int, default=512, help="map side in cells (default 512)")
    p.add_argument("--share", type=float, nargs="+", default=[0.1, 0.2, 0.3],
                   help="blocked shares, one process each (default 0.1 0.2 0.3)")
    p.add_argument("--seed", type=int, default=0, help="map seed (default 0)")
    p.add_argument("--method", choices=METHODS, default="auto",
                   help="prepare()'s method (default auto)")
    p.add_argument("--warm-side", type=int, default=None,
                   help="side of the small map built first to load the kernels (default "
                        "96, at most --side: the smallest random map whose subgoal graph "
                        "outgrows the all-pairs table at 10-30%%, so that both kinds of "
                        "index are built and their kernels loaded; at 64 the table answers "
                        "and the big build loaded the others' kernels itself)")
    p.add_argument("--json", type=Path, metavar="PATH", help="also write the figures here")
    p.add_argument("--worker", nargs=5, help=argparse.SUPPRESS)
    a = p.parse_args(argv)
    if a.worker is None:
        if a.warm_side is None:
            a.warm_side = min(a.side, 96)
        if not 8 <= a.side <= 4096:
            raise Fail(f"--side {a.side} must be 8..4096")
        if not 8 <= a.warm_side <= a.side:
            raise Fail(f"--warm-side {a.warm_side} must be 8..--side ({a.side})")
        bad = [s for s in a.share if not 0.0 <= s < 1.0]
        if bad:
            raise Fail(f"--share {bad[0]:g} must be 0 <= SHARE < 1")
        if a.json is not None and not a.json.parent.is_dir():
            raise Fail(f"--json {a.json}: the folder {a.json.parent} does not exist")
    return a


def measure(side: int, share: float, seed: int, method: str, warm_side: int) -> dict:
    """In the fresh process: the build's rise of the maximum resident set."""
    import gc
    import resource
    import time

    import skyroute
    from skyroute.world.grid import Grid

    def grid(n: int) -> Grid:  # the bench's random_grid(n, share, seed)
        return Grid(random_blocked(n, share, seed), name=f"random-{n}-{share:g}-s{seed}")

    skyroute.prepare(grid(warm_side), method=method)  # loads the kernels
    gc.collect()
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # KB on Linux
    t0 = time.perf_counter()
    index = skyroute.prepare(grid(side), method=method)
    seconds = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    return {"skyroute": skyroute.__file__, "map": f"random-{side}-{share:g}-s{seed}",
            "method": method, "accelerator": getattr(index, "accelerator", None),
            "index_bytes": int(getattr(index, "nbytes", 0)), "seconds": seconds,
            "maxrss_before_bytes": before, "maxrss_after_bytes": after,
            "added_bytes": after - before}


def main(argv=None) -> None:
    a = parse(argv)
    if a.worker is not None:
        side, share, seed, method, warm = a.worker
        print(json.dumps(measure(int(side), float(share), int(seed), method, int(warm))))
        return
    print(f"prepare(random_grid({a.side}, SHARE, {a.seed}), method={a.method!r}), one fresh "
          f"process a share after a {a.warm_side}x{a.warm_side} build; {load_average()}")
    rows = []
    for share in a.share:
        proc = subprocess.run([sys.executable, __file__, "--worker", str(a.side), repr(share),
                               str(a.seed), a.method, str(a.warm_side)],
                              capture_output=True, text=True)
        if proc.returncode != 0:
            last = (proc.stderr.strip().splitlines() or ["no message"])[-1]
            raise Fail(f"share {share:g}: the measuring process failed: {last}")
        rows.append(json.loads(proc.stdout.strip().splitlines()[-1]))
    print(f"skyroute {rows[0]['skyroute']}")
    print("| map | answers by | build s | max resident before MB | added MB | index MB |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['map']} | {r['accelerator']} | {r['seconds']:.2f} | "
              f"{r['maxrss_before_bytes'] / 1e6:.1f} | +{r['added_bytes'] / 1e6:.1f} | "
              f"{r['index_bytes'] / 1e6:.1f} |")
    if a.json is not None:
        a.json.write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    run_main(main)
