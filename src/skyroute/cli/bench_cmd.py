"""``skyroute bench grid``: the benchmark table, with a progress bar."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.table import Table

from skyroute.bench.grid import (
    Case,
    bench_case,
    check_per_map,
    check_random_per_map,
    check_runners,
    find_pairs,
    load_case,
    random_case,
)
from skyroute.bench.machine import machine
from skyroute.bench.peers import PEERS, skip_reason
from skyroute.bench.random_maps import parse_random
from skyroute.cli.parse import parse_list
from skyroute.cli.tables import plain_console, print_table, progress_bar, wide_console
from skyroute.errors import SEED_MAX, OptionError
from skyroute.files import check_writable, write_atomic
from skyroute.io.json_text import to_json
from skyroute.world.load import bundled_maps

bench_app = typer.Typer(help="Benchmarks against peer libraries.", no_args_is_help=True)


@bench_app.command("grid")
def bench_grid(
    maps: Annotated[Path | None, typer.Option(
        help="Folder of MovingAI .map + .scen files (default: the bundled maps).")] = None,
    map_names: Annotated[list[str] | None, typer.Option(
        "--map", help="Only this map (repeatable), e.g. den312d.")] = None,
    per_map: Annotated[int, typer.Option(
        min=0, help="Scenario lines sampled per map (0 = all; with --random, give a count "
                    ">= 1: a random map has no lines).")] = 20,
    algorithms: Annotated[str, typer.Option(help="Comma-separated skyroute algorithms.")] =
        "astar,jps",
    peers: Annotated[str, typer.Option(help="Comma-separated peers: pyastar2d, pathfinding, "
                                       "networkx ('' for none). networkx is skipped, with a "
                                       "note, on maps over 2048x2048 cells (its graph needs "
                                       "about 1.5 KB a cell).")] =
        "pyastar2d,pathfinding,networkx",
    seed: Annotated[int, typer.Option(
        min=0, max=SEED_MAX, help="Seed for sampling scenario lines.")] = 0,
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
    """Run MovingAI scenarios through skyroute's planners and the installed peers.

    Every map and scenario is read and checked before any timing.
    """
    check_per_map(per_map)
    folder = maps or next(iter(bundled_maps().values())).parent
    algs, have, missing = check_runners(parse_list(algorithms), parse_list(peers))
    if not (algs or have or prepared):
        raise OptionError("nothing to run: give --algorithms, --peers or --prepared" +
                          (f" (not installed: {', '.join(missing)})" if missing else ""))
    randoms = _random_specs(random or (), per_map)
    if json_out:
        check_writable(json_out)
    only_random = randoms and maps is None and not map_names
    pairs = [] if only_random else find_pairs(folder, map_names or ())
    console = plain_console(stderr=True)
    for p in missing:
        console.print(f"peer {p} is not installed; skipped "
                      "(pip install 'skyroute[bench]')", style="yellow")
    cases = [load_case(m, s, per_map=per_map) for m, s in pairs]
    cases += [random_case(spec, per_map=per_map, seed=seed) for spec in randoms]
    _note_skipped_peers(console, cases, have, ours=bool(algs) or prepared)
    reports = _run(console, cases, algorithms=algs, peers=have, seed=seed, prepared=prepared)
    out = wide_console()  # 160 columns in a file or a pipe, as every wide table
    for rep in reports:
        if rep.get("prepared", {}).get("build_peak_error"):
            console.print(f"{rep['map']}: {rep['prepared']['build_peak_error']}",
                          style="yellow")
        # the speed-ups and the cost ratios stay longest on a narrow terminal
        print_table(out, _table(rep), optional=(
            *(f"x faster than {row['runner']}" for row in rep["rows"] if row["peer"]),
            "cost/opt max", "cost/opt mean", "M exp/s"))
    if json_out:
        # --map as given: a re-run of the report needs it (only "maps", the folder, was
        # kept, so the report of two maps read as a run of every map in the folder)
        doc = {"settings": {"maps": None if only_random else str(folder),
                            "map": list(dict.fromkeys(map_names or ())),
                            "per_map": per_map, "random": randoms,
                            "prepared": prepared,
                            "algorithms": algs, "peers": have, "missing_peers": missing,
                            "seed": seed},
               "machine": machine([PEERS[p].module for p in have]),
               "maps": reports}
        write_atomic(json_out, to_json(doc, indent=1))


def _random_specs(specs: list[str] | tuple, per_map: int) -> list[str]:
    """The --random specs, each checked and each map once (as first given)."""
    seen: dict[tuple, str] = {}
    for spec in specs:
        seen.setdefault(parse_random(spec), spec)
    for side, _share in seen:
        check_random_per_map(per_map, side)
    return list(seen.values())


def _note_skipped_peers(console: Console, cases: list[Case], peers: list[str], *,
                        ours: bool) -> None:
    """Say, before the run, which peer each map is too large for; with no runner of
    ``ours`` and no peer left for a map, refuse it."""
    for case in cases:
        skipped = {p: why for p in peers if (why := skip_reason(p, case.grid))}
        if not ours and len(skipped) == len(peers):
            raise OptionError(f"nothing to run on {case.label}: every peer is skipped there "
                              f"({'; '.join(f'{p}: {w}' for p, w in skipped.items())}); give "
                              "--algorithms or --prepared")
        for p, why in skipped.items():
            console.print(f"peer {p} skipped on {case.label}: {why}", style="yellow")


def _run(console: Console, cases: list[Case], **options) -> list[dict]:
    """Bench every case under one progress bar; their reports."""
    reports = []
    with progress_bar(console) as progress:
        task = progress.add_task("queries", total=sum(c.queries for c in cases))
        for case in cases:
            progress.update(task, description=case.label)
            reports.append(bench_case(case, on_query=lambda: progress.advance(task), **options))
    return reports


def _fmt(v, spec):
    return "-" if v is None else format(v, spec)


def _table(rep: dict) -> Table:
    prep = rep.get("prepared")
    peers = [row["runner"] for row in rep["rows"] if row["peer"]]
    caption = (f"prepared: built in {prep['build_seconds']:,.3f} s, peak "
               f"{_fmt(prep['build_peak_bytes'] and prep['build_peak_bytes'] / 1e6, ',.1f')} "
               f"MB resident, {prep['index_bytes'] / 1e6:,.1f} MB (arrays' nbytes), "
               f"{prep['index']}" if prep else None)
    # a random map's queries are made, with scipy's optima: it has no scenario lines
    what = (f"{rep['queries']:,} far queries, optima from scipy" if rep["scen_lines"] is None
            else f"{rep['queries']:,} of {rep['scen_lines']:,} scenario lines")
    t = Table(title=f"{rep['map']} ({rep['size'][0]}x{rep['size'][1]}): {what}",
              caption=caption)
    for col in ("runner", "median ms", "M exp/s", "matched", "invalid", "cost/opt mean",
                "cost/opt max"):
        t.add_column(col, justify="left" if col == "runner" else "right")
    for p in peers:
        t.add_column(f"x faster than {p}", justify="right")
    for row in rep["rows"]:
        eps = row["expansions_per_s"]
        cells = [row["runner"] + (" (peer)" if row["peer"] else ""),
                 _fmt(row["median_ms"], ",.3f"), _fmt(eps and eps / 1e6, ",.2f"),
                 f"{row['matched']:,}/{rep['queries']:,}", f"{row['invalid']:,}",
                 _fmt(row["mean_cost_ratio"], ".4f"),
                 _fmt(row["max_cost_ratio"], ".4f")]
        cells += [_fmt(row["speedup_vs"].get(p), ",.2f") if not row["peer"] else ""
                  for p in peers]
        t.add_row(*cells)
    return t
