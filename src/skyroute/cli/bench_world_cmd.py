"""``skyroute bench world``: skyroute's continuous planners against OMPL."""

from __future__ import annotations

import math
import os
import sys
import tempfile
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.table import Table

from skyroute.bench.machine import machine
from skyroute.bench.world import (
    OMPL_PLANNERS,
    bench_query,
    check_altitude,
    city_queries,
    free_pair,
    load_city,
    ompl_available,
    random_rect_world,
)
from skyroute.cli.bench_cmd import bench_app
from skyroute.cli.parse import parse_items, parse_list
from skyroute.cli.tables import plain_console, print_table, progress_bar, wide_console
from skyroute.errors import SEED_MAX, OptionError, SkyrouteError, check_choice
from skyroute.files import check_writable, write_atomic
from skyroute.io.json_text import to_json
from skyroute.motion.step_drone import MERGE


@bench_app.command("world")
def bench_world(
    worlds: Annotated[int, typer.Option(min=0, help="Random 20-rectangle worlds.")] = 5,
    seed: Annotated[int, typer.Option(
        min=0, max=SEED_MAX, help="Seed of the first world and its query.")] = 0,
    city: Annotated[Path | None, typer.Option(
        help="Also a colliders.csv city (at --altitude, with --safety).")] = None,
    altitude: Annotated[float, typer.Option(help="City altitude (m).")] = 5.0,
    safety: Annotated[float, typer.Option(help="City safety margin (m).")] = 5.0,
    city_queries_n: Annotated[int, typer.Option(
        "--city-queries", min=0, help="Random far pairs timed on the city's graph once built.")]
        = 30,
    no_path: Annotated[int, typer.Option(
        min=0, help="City pairs in different free regions to time (no path).")] = 5,
    seconds: Annotated[float, typer.Option(
        "--seconds", "--budget", help="Seconds per OMPL solve (--budget: old name).")] = 1.0,
    planners: Annotated[str, typer.Option(help="OMPL planners, comma-separated.")] =
        ",".join(OMPL_PLANNERS),
    json_out: Annotated[Path | None, typer.Option("--json", help="Write the report here.")] =
        None,
) -> None:
    """Path length relative to the visibility-graph optimum, and time, against OMPL."""
    chosen = _check_world_options(worlds, city, altitude, seconds, planners, json_out)
    with tempfile.TemporaryDirectory() as cache:  # builds are timed cold, not from disk
        os.environ["SKYROUTE_CACHE"], old = cache, os.environ.get("SKYROUTE_CACHE")
        try:
            _bench_world(worlds, seed, city, altitude, safety, city_queries_n, no_path,
                         seconds, chosen, json_out)
        finally:
            if old is None:
                os.environ.pop("SKYROUTE_CACHE", None)
            else:
                os.environ["SKYROUTE_CACHE"] = old
    _exit_past_ompl()


def _check_world_options(worlds, city, altitude, seconds, planners, json_out) -> tuple:
    """The options that need no file read, checked before anything runs; the OMPL
    planners chosen."""
    chosen = tuple(parse_list(planners))
    for p in chosen:
        check_choice("planners", p, OMPL_PLANNERS)
    if worlds == 0 and city is None:
        raise OptionError("--worlds 0 and no --city: nothing to run; give --worlds N or "
                          "--city FILE")
    check_altitude(altitude)
    _positive("--seconds", seconds)
    if json_out:
        check_writable(json_out)
    return chosen


def _positive(flag: str, value: float) -> float:
    """``value`` when it is a positive finite number, else an OptionError naming ``flag``."""
    if not (math.isfinite(value) and value > 0):
        raise OptionError(f"{flag} {value!r} must be a positive finite number")
    return value


def _world_cases(worlds, seed, city, altitude, safety) -> list[tuple]:
    """(world, (start, goal), other query) for each random world and the city, all drawn
    before any timing: a city too crowded for a query fails before the long work."""
    cases = [random_rect_world(seed + i) for i in range(worlds)]
    if city is not None:
        cases.append(load_city(city, altitude=altitude, safety=safety))
    out = []
    for i, world in enumerate(cases):
        rng = np.random.default_rng(seed + i)
        size = max(world.bounds[2] - world.bounds[0], world.bounds[3] - world.bounds[1])
        try:
            out.append((world, free_pair(world, rng, 0.6 * size),
                        free_pair(world, rng, 0.6 * size)))
        except SkyrouteError:
            if i < worlds:  # random worlds always have room
                raise
            raise SkyrouteError(f"--city {city}: no two far free points joined by a path at "
                                f"--altitude {altitude:g} with --safety {safety:g}; try a "
                                "smaller --safety or another --altitude") from None
    return out


def _bench_world(worlds, seed, city, altitude, safety, city_queries_n, no_path, seconds,
                 chosen, json_out) -> None:
    console = plain_console(stderr=True)
    cases = _world_cases(worlds, seed, city, altitude, safety)
    if not ompl_available():
        console.print("OMPL is not installed; skyroute only "
                      "(pip install 'skyroute[bench]')", style="yellow")
    reports = []
    with progress_bar(console) as progress:
        task = progress.add_task("worlds", total=len(cases))
        for world, (s, g), other in cases:
            reports.append(bench_query(world, s, g, seconds=seconds, planners=chosen,
                                       rrt_budgets=(0.1, 0.3, 1.0, 3.0), other=other))
            progress.advance(task)
    out = wide_console()  # 160 columns in a file or a pipe, as every wide table
    for rep in reports:
        t = Table(title=f"{rep['world']}: optimum {rep['optimum']:.3f}; RRT* within 1% "
                        f"after {rep['rrtstar_budget_within_1pct'] or 'more than 3'} s")
        for col in ("runner", "seconds", "length / optimum", "simplified / optimum",
                    "exactly free"):
            t.add_column(col, justify="left" if col == "runner" else "right")
        for row in rep["rows"]:
            ratio = row.get("length_ratio", row.get("raw_ratio"))
            t.add_row(row["runner"], f"{row['seconds']:,.4f}",
                      "-" if ratio is None else f"{ratio:.4f}",
                      "-" if row.get("simplified_ratio") is None else
                      f"{row['simplified_ratio']:.4f}",
                      {True: "yes", False: "no", None: "-"}[row.get("valid")])
        print_table(out, t)
    city_timing = None
    if city is not None and city_queries_n > 0:
        c = city_timing = city_queries(cases[-1][0], city_queries_n,
                                       np.random.default_rng(seed), no_path=no_path)
        out.print(f"{cases[-1][0].name}: visibility graph of {c['corners']:,} corners built "
                  f"in {c['build_seconds']:,.3f} s ({c['cached_build_seconds']:,.3f} s from "
                  f"the disk cache); first query {c['first_seconds'] * 1e3:,.1f} ms (with the "
                  f"build {c['first_with_build_seconds']:,.3f} s); {city_queries_n:,} far "
                  f"pairs (>= {c['min_dist']:,.0f} m apart, {c['found']:,} with a path): "
                  f"median {c['median_ms']:,.2f} ms, 95th percentile {c['p95_ms']:,.2f} ms, "
                  f"max {c['max_ms']:,.2f} ms; {c['no_path_pairs']:,} pairs in different free "
                  "regions: no path in median "
                  + ("-" if c["no_path_median_ms"] is None else
                     f"{c['no_path_median_ms']:,.2f} ms, max {c['no_path_max_ms']:,.2f} ms"))
    if json_out:
        settings = {"worlds": worlds, "seed": seed, "seconds": seconds, "planners": chosen,
                    "city": city and str(city), "altitude": altitude, "safety": safety,
                    "city_queries": city_queries_n, "no_path": no_path}
        write_atomic(json_out, to_json({**settings, "settings": settings,
                                           "machine": machine(("ompl",)), "worlds": reports,
                                           "city_queries": city_timing},
                                          indent=1, default=float))


@bench_app.command("motion")
def bench_motion(
    data: Annotated[Path | None, typer.Option(
        help="The ILP data folder (website/, testing/): Dubins batch and step drone.")] =
        None,
    curvature: Annotated[bool, typer.Option(
        "--curvature", help="Hybrid A* vs OMPL RRT*/BIT* on seeded worlds (and --city), "
                            "then Dubins tours vs nearest-first.")] = False,
    worlds: Annotated[int, typer.Option(min=0, help="--curvature: seeded random worlds.")] = 10,
    seed: Annotated[int, typer.Option(
        min=0, max=SEED_MAX, help="--curvature: seed of worlds and queries.")] = 0,
    budgets: Annotated[str, typer.Option(
        help="--curvature: OMPL seconds per solve, comma-separated.")] = "1,5",
    city: Annotated[Path | None, typer.Option(
        help="--curvature: also plan on this colliders city (10 m altitude, 2 m safety).")]
        = None,
    tours: Annotated[int, typer.Option(
        min=0, help="--curvature: seeded 10-target tour instances (0: none).")] = 20,
    dubins: Annotated[bool, typer.Option(
        "--dubins", help="Only the Dubins batch against OMPL (100k and 1M queries, 1 and 2 "
                         "threads); needs no --data.")] = False,
    max_expansions: Annotated[int, typer.Option(
        "--max-expansions", "--budget", min=1,
        help="plan_moves expansions per leg (--budget: old name).")] = 200_000,
    merge: Annotated[float, typer.Option(help="plan_moves merge lattice (degrees).")] =
        MERGE,
    json_out: Annotated[Path | None, typer.Option("--json", help="Write the report here.")] =
        None,
) -> None:
    """Dubins batch speed vs OMPL and step-drone fewest moves vs following a Theta* path
    (--data); Hybrid A* vs OMPL and Dubins tours (--curvature)."""
    secs = _budgets(budgets)
    _positive("--merge", merge)
    if data is None and not (curvature or dubins):
        raise OptionError("bench motion needs --data DIR (the ILP data), --dubins or "
                          "--curvature")
    if curvature and not (worlds or city or tours):
        raise OptionError("--curvature with --worlds 0, --tours 0 and no --city: nothing to "
                          "run")
    from skyroute.bench.motion import dubins_speed, load_ilp, step_drone_pairs

    ilp = load_ilp(data) if data is not None else None  # checked even where not used
    if json_out:
        check_writable(json_out)
    if curvature:
        _bench_curvature(worlds, seed, secs, city, tours, json_out)
        return
    out = wide_console()  # 160 columns in a file or a pipe, as every wide table
    d = dubins_speed()
    print_table(out, _dubins_table(d))
    if dubins:
        if json_out:
            write_atomic(json_out, to_json({"machine": machine(("ompl",)), "dubins": d},
                                              indent=1))
        _exit_past_ompl()
        return
    with progress_bar(plain_console(stderr=True)) as progress:
        task = progress.add_task("pairs", total=14 * 13)
        r = step_drone_pairs(*ilp, max_expansions=max_expansions, merge=merge,
                             on_pair=lambda: progress.advance(task))
    both = sum(1 for x in r["rows"] if x["moves"] is not None and x["follow"] is not None)
    out.print(f"step drone over {r['pairs']:,} ordered pairs: plan_moves solved "
              f"{r['solved']:,} (max expansions {max_expansions:,}, merge {merge:g}), follow "
              f"{r['follow_solved']:,}; on the {both:,} both solved: {r['moves_total']:,} "
              f"moves vs {r['follow_total']:,} (ratio {r['ratio']:.4f}); plan_moves per leg "
              f"median {r['median_ms']:,.1f} ms, p90 {r['p90_ms']:,.1f} ms, max "
              f"{r['max_ms']:,.1f} ms")
    if json_out:
        write_atomic(json_out, to_json(
            {"settings": {"data": str(data), "max_expansions": max_expansions, "merge": merge},
             "machine": machine(("ompl",)), "dubins": d, "step_drone": r}, indent=1))
    _exit_past_ompl()


def _dubins_table(d: dict) -> Table:
    """The Dubins batch rows: us per query (median, best), OMPL's, the ratio."""
    table = Table(title=f"Dubins lengths, r = {d['radius']} (numba threading layer "
                        f"{d['threading_layer']}; max |skyroute - OMPL| "
                        f"{d.get('max_abs_diff_ompl', float('nan')):.1e})")
    for col in ("queries", "threads", "skyroute us/query", "best", "OMPL us/call", "ratio"):
        table.add_column(col, justify="right")
    for row in d["rows"]:
        ompl = row.get("ompl_us")
        table.add_row(f"{row['queries']:,}", f"{row['threads']:,}",
                      f"{row['skyroute_us']:,.4f}", f"{row['skyroute_min_us']:,.4f}",
                      "-" if ompl is None else f"{ompl:,.3f}",
                      "-" if ompl is None else f"{ompl / row['skyroute_us']:.1f}x")
    return table


def _exit_past_ompl() -> None:
    if "ompl" in sys.modules:
        # OMPL's nanobind bindings print a reference-leak report at interpreter exit;
        # everything is written and flushed, so leave without running finalisers.
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(0)


def _budgets(budgets: str) -> tuple[float, ...]:
    """--budgets "1,5" -> (1.0, 5.0): OMPL seconds per solve, each positive and finite."""
    items = parse_items(budgets, "--budgets")  # an OptionError, itself a ValueError
    try:
        secs = tuple(float(b) for b in items)
    except ValueError:
        raise OptionError(f"--budgets {budgets!r}: expected seconds like 1,5") from None
    if not all(math.isfinite(b) and b > 0 for b in secs):
        raise OptionError(f"--budgets {budgets!r}: every budget must be > 0 seconds and "
                          "finite")
    return secs


def _curvature_table(summ: dict) -> Table:
    """The runners of ``bench motion --curvature``: solved, exactly free, median length
    ratio, median and p95 ms; the numbers right-aligned, as in every table (they were
    left-aligned here alone)."""
    table = Table(title="turning radius 5 m: one query per world")
    for col in ("runner", "solved", "exactly free", "median ratio", "median ms", "p95 ms"):
        table.add_column(col, justify="left" if col == "runner" else "right")
    for name, s in summ.items():
        if "found" in s:
            ratio = f"{s['median_ratio']:.3f}" if s["median_ratio"] is not None else "-"
            table.add_row(name, f"{s['found']:,}/{s['queries']:,}",
                          f"{s['valid']:,}/{s['found']:,}", ratio, f"{s['median_ms']:,.1f}",
                          f"{s['p95_ms']:,.1f}")
    return table


def _bench_curvature(worlds, seed, secs, city, tours, json_out) -> None:
    from skyroute.bench.curvature import curvature_queries, run_queries, summary, tour_benchmark

    queries = curvature_queries(worlds, seed, city=city)  # a bad --city fails here, first
    out = wide_console()  # 160 columns in a file or a pipe, as every wide table
    with progress_bar(plain_console(stderr=True)) as progress:
        task = progress.add_task("planner runs", total=None)
        rows = run_queries(queries, secs, on_step=lambda r: progress.advance(task))
    summ = summary(rows)
    print_table(out, _curvature_table(summ))
    for name, s in summ.items():
        if "compared" in s:
            worst = f"{s['worst_ratio']:.4f}" if s["worst_ratio"] is not None else "-"
            out.print(f"{name}: no longer on {s['no_longer']}/{s['compared']}, worst ratio "
                      f"{worst}; solved by the peer but not by skyroute: "
                      f"{s['peer_solved_we_missed']}")
    t = tour_benchmark(tours, seed) if tours else None
    if t:
        out.print(f"tours ({t['instances']} x {t['targets']} targets, r {t['radius']:g} m, "
                  f"{t['headings']} headings): nearest-first is {t['greedy_longer_mean']:.1%} "
                  f"longer on average (min {t['greedy_longer_min']:.1%}, max "
                  f"{t['greedy_longer_max']:.1%}); local search alone {t['local_gap_mean']:.2%} "
                  f"above the exact tour on average (max {t['local_gap_max']:.2%}, exact on "
                  f"{t['local_exact']:,}); exact {t['exact_ms_median']:,.0f} ms, local "
                  f"{t['local_ms_median']:,.0f} ms median")
    if json_out:
        settings = {"worlds": worlds, "seed": seed, "budgets": list(secs),
                    "city": city and str(city), "tours": tours}
        write_atomic(json_out, to_json({"settings": settings, "machine": machine(("ompl",)),
                                           "rows": rows, "summary": summ, "tours": t},
                                          indent=1, default=str))
