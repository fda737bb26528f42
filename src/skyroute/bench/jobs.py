"""``skyroute bench jobs``: a range of delivery days on each executor, and more workers
simulated from the measured task times.

Each run is what ``skyroute deliver --from --to`` does after its set-up: a fresh SQLite
store (orders imported, untimed), the shared leg table filled once before the first run
(untimed), then the range as one task per day on the executor, each day's GeoJSON and
report written by the caller as it arrives. ``start_seconds`` is the executor's start
(spawning the pool or the ``LocalCluster``), ``wall_seconds`` the range itself.

More workers than this machine has cores cannot be measured here, so they are simulated:
the one-process run gives every task's duration (in that run the tasks follow each other
in this process, so the gaps between results are the tasks), and N workers take the
tasks in date order, each the next task when it is free (what the executors do). A Dask
run adds the overhead per task measured on one Dask worker over one local process.
"""

from __future__ import annotations

import heapq
import tempfile
import time
from pathlib import Path

from skyroute.delivery.days import open_store, prepare_legs
from skyroute.delivery.orders import read_csv_orders
from skyroute.delivery.site import load_site
from skyroute.delivery.source import open_source
from skyroute.delivery.store import import_orders
from skyroute.errors import OptionError
from skyroute.io.day_out import write_outputs
from skyroute.jobs.deliver import days_between, run_days, summarise
from skyroute.jobs.executor import open_executor

KINDS = ("local", "dask")


def parse_runs(text: str) -> list[tuple[str, int]]:
    """``local:1,dask:2`` -> [("local", 1), ("dask", 2)]."""
    runs = []
    for part in (p.strip() for p in text.split(",") if p.strip()):
        kind, _, n = part.partition(":")
        if kind not in KINDS or not n.isdigit() or int(n) < 1:
            raise OptionError(f"--runs {part!r}: expected KIND:WORKERS with KIND local or "
                              "dask and WORKERS >= 1, e.g. local:2", param="runs")
        runs.append((kind, int(n)))
    if not runs:
        raise OptionError("--runs is empty", param="runs")
    return runs


def parse_counts(text: str) -> list[int]:
    """``1,2,4`` -> [1, 2, 4]: worker counts to simulate (``''``: none)."""
    parts = [p.strip() for p in text.split(",") if p.strip()]
    if not all(p.isdigit() and int(p) >= 1 for p in parts):
        raise OptionError(f"--simulate {text!r}: expected worker counts >= 1, e.g. 1,2,4,8",
                          param="simulate")
    return [int(p) for p in parts]


def makespan(durations: list[float], workers: int, overhead: float = 0.0) -> float:
    """Finish time of tasks taken in order by ``workers`` workers, each the next task as
    soon as it is free; every task costs ``overhead`` more."""
    free = [0.0] * workers
    end = 0.0
    for d in durations:
        t = heapq.heappop(free) + d + overhead
        end = max(end, t)
        heapq.heappush(free, t)
    return end


def bench_jobs(data: Path, first, last, runs: list[tuple[str, int]], *,
               method: str = "milp", on_day=None) -> dict:
    """Time the range on each (kind, workers) of ``runs``; per-task durations from the
    first ``local:1`` run (None without one)."""
    src = open_source(data, None)
    site = load_site(src)
    orders = read_csv_orders(data)
    rows, durations = [], None
    with tempfile.TemporaryDirectory(prefix="skyroute-bench-jobs-") as tmp:
        for k, (kind, workers) in enumerate(runs):
            engine = open_store(f"sqlite:///{Path(tmp) / f'run{k}.db'}")
            import_orders(engine, orders)
            by_date = days_between(engine, first, last)
            if k == 0:
                prepare_legs(site, [o for v in by_date.values() for o in v])
            out = Path(tmp) / f"out{k}"
            out.mkdir()
            stamps: list[float] = []

            def arrived(r, out=out, stamps=stamps):
                write_outputs(site, r, out, plot=False)
                stamps.append(time.perf_counter())
                if on_day:
                    on_day()

            t0 = time.perf_counter()
            with open_executor(kind, workers=workers) as ex:
                t1 = time.perf_counter()
                results = run_days(engine, src, by_date, executor=ex, method=method,
                                   on_day=arrived)
                t2 = time.perf_counter()
            engine.dispose()
            s = summarise(results)
            rows.append({"executor": kind, "workers": workers, "days": len(results),
                         "start_seconds": t1 - t0, "wall_seconds": t2 - t1,
                         "mean_pct": s.get("mean_pct"), "min_pct": s.get("min_pct")})
            if durations is None and (kind, workers) == ("local", 1):
                durations = [b - a for a, b in zip([t1, *stamps[:-1]], stamps, strict=True)]
    return {"rows": rows, "durations": durations}


def simulate(rows: list[dict], durations: list[float], workers: list[int]) -> list[dict]:
    """Simulated wall seconds for each worker count, local and Dask (the Dask overhead
    per task from the measured ``dask:1`` run over ``local:1``; None without one)."""
    base = sum(durations)
    by = {(r["executor"], r["workers"]): r["wall_seconds"] for r in rows}
    over = None
    if ("dask", 1) in by and ("local", 1) in by:
        over = max(0.0, (by["dask", 1] - by["local", 1]) / len(durations))
    out = []
    for n in workers:
        local = makespan(durations, n)
        dask = None if over is None else makespan(durations, n, over)
        out.append({"workers": n, "local_seconds": local, "dask_seconds": dask,
                    "speedup": base / local,
                    "dask_speedup": None if dask is None else base / dask})
    return out
