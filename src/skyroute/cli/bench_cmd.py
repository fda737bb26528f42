"""``skyroute bench grid``: the benchmark table, with a progress bar."""

from __future__ import annotations

import json
import platform
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table

from skyroute.bench.grid import bench_map, bench_random, check_runners, count_queries, find_pairs
from skyroute.bench.random_maps import parse_random
from skyroute.cli.parse import parse_list
from skyroute.files import write_atomic
from skyroute.world.load import bundled_maps

bench_app = typer.Typer(help="Benchmarks against peer libraries.", no_args_is_help=True)


@bench_app.command("grid")
def bench_grid(
    maps: Annotated[Path | None, typer.Option(
        help="Folder of MovingAI .map + .scen files (default: the bundled maps).")] = None,
    map_names: Annotated[list[str] | None, typer.Option(
        "--map", help="Only this map (repeatable), e.g. den312d.")] = None,
    per_map: Annotated[int, typer.Option(
        min=0, help="Scenario lines sampled per map (0 = all).")] = 20,
    algorithms: Annotated[str, typer.Option(help="Comma-separated skyroute algorithms.")] =
        "astar,jps",
    peers: Annotated[str, typer.Option(help="Comma-separated peers: pyastar2d, pathfinding, "
                                       "networkx ('' for none).")] =
        "pyastar2d,pathfinding,networkx",
    seed: Annotated[int, typer.Option(help="Seed for sampling scenario lines.")] = 0,
    random: Annotated[list[str] | None, typer.Option(
        help="Also a synthetic SIDE:SHARE map (repeatable), e.g. 512:0.2: SHARE of the cells "
             "blocked at random (numpy --seed), --per-map far queries with optima from "
             "scipy. Alone, only these maps run.")] = None,
    prepared: Annotated[bool, typer.Option(
        "--prepared", help="Also a prepared index per map (skyroute.prepare): its build "
                           "seconds, peak memory and bytes, and its queries as one more "
                           "runner.")] = False,
    json_out: Annotated[Path | None, typer.Option("--json", help="Write the report here.")] =
        None,
) -> None:
    """Run MovingAI scenarios through skyroute's planners and the installed peers."""
    folder = maps or next(iter(bundled_maps().values())).parent
    algs, have, missing = check_runners(parse_list(algorithms), parse_list(peers))
    randoms = list(random or ())
    for spec in randoms:
        parse_random(spec)
    only_random = randoms and maps is None and not map_names
    pairs = [] if only_random else find_pairs(folder, map_names or ())
    total = count_queries(pairs, per_map) + len(randoms) * max(per_map, 1)
    console = Console(stderr=True)
    for p in missing:
        console.print(f"[yellow]peer {p} is not installed; skipped "
                      "(pip install 'skyroute[bench]')[/yellow]")
    reports = []
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
               TimeRemainingColumn())
    with Progress(*columns, console=console, transient=True) as progress:
        task = progress.add_task("queries", total=total)
        for map_path, scen_path in pairs:
            progress.update(task, description=map_path.stem)
            reports.append(bench_map(map_path, scen_path, per_map=per_map, algorithms=algs,
                                     peers=have, seed=seed, prepared=prepared,
                                     on_query=lambda: progress.advance(task)))
        for spec in randoms:
            progress.update(task, description=f"random {spec}")
            reports.append(bench_random(spec, per_map=per_map, algorithms=algs, peers=have,
                                        seed=seed, prepared=prepared,
                                        on_query=lambda: progress.advance(task)))
    out = Console()
    for rep in reports:
        if rep.get("prepared", {}).get("build_peak_error"):
            console.print(f"[yellow]{rep['map']}: {rep['prepared']['build_peak_error']}"
                          "[/yellow]")
        out.print(_table(rep, have))
    if json_out:
        doc = {"settings": {"maps": str(folder), "per_map": per_map, "random": randoms,
                            "prepared": prepared,
                            "algorithms": algs, "peers": have, "missing_peers": missing,
                            "seed": seed},
               "machine": {"python": platform.python_version(),
                           "processor": platform.processor() or platform.machine()},
               "maps": reports}
        write_atomic(json_out, json.dumps(doc, indent=1))


def _fmt(v, spec):
    return "-" if v is None else format(v, spec)


def _table(rep: dict, peers: list[str]) -> Table:
    prep = rep.get("prepared")
    caption = (f"prepared: built in {prep['build_seconds']:.3f} s, peak "
               f"{_fmt(prep['build_peak_bytes'] and prep['build_peak_bytes'] / 1e6, '.1f')} "
               f"MB resident, {prep['index_bytes'] / 1e6:.1f} MB (arrays' nbytes), "
               f"{prep['index']}" if prep else None)
    t = Table(title=f"{rep['map']} ({rep['size'][0]}x{rep['size'][1]}): "
                    f"{rep['queries']} of {rep['scen_lines']} scenario lines", caption=caption)
    for col in ("runner", "median ms", "M exp/s", "matched", "cost/opt mean", "cost/opt max"):
        t.add_column(col, justify="left" if col == "runner" else "right")
    for p in peers:
        t.add_column(f"x faster than {p}", justify="right")
    for row in rep["rows"]:
        eps = row["expansions_per_s"]
        cells = [row["runner"] + (" (peer)" if row["peer"] else ""),
                 _fmt(row["median_ms"], ".3f"), _fmt(eps and eps / 1e6, ".2f"),
                 f"{row['matched']}/{rep['queries']}", _fmt(row["mean_cost_ratio"], ".4f"),
                 _fmt(row["max_cost_ratio"], ".4f")]
        cells += [_fmt(row["speedup_vs"].get(p), ".2f") if not row["peer"] else ""
                  for p in peers]
        t.add_row(*cells)
    return t
