"""``skyroute bench grid``: MovingAI scenarios through skyroute's planners and the peers.

All runners answer the same queries in one process, interleaved (the order rotates each
query, so drift in machine speed spreads evenly), after one untimed warm-up query each.
Times are wall clock around one call: ``skyroute.plan`` for ours (validation included),
``PreparedGrid.plan`` for the ``prepared`` runner (its index is built once per map, timed
apart as ``build_seconds``, its size the arrays' ``nbytes``, the build's peak resident
memory from a fresh process as ``build_peak_bytes``), the peer's own query call
for a peer (its one-off set-up is not timed). What the bench does with an answer (the
peer path's octile cost, reading a result's fields) happens after the clock stops.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from skyroute.bench.build_memory import build_peak_bytes
from skyroute.bench.peers import PEERS, available, octile_cost
from skyroute.bench.random_maps import far_queries, parse_random, random_grid
from skyroute.errors import InputFormatError, OptionError, check_choice
from skyroute.planner import plan
from skyroute.search.grid_plan import GRID_ALGORITHMS
from skyroute.search.prepared import prepare
from skyroute.world.grid import Grid
from skyroute.world.movingai import Scenario, read_map, read_scen

# Algorithms whose cost must equal the scenario's octile optimum.
OPTIMAL = ("dijkstra", "astar", "jps")


def find_pairs(folder: str | Path, names: Sequence[str] = ()) -> list[tuple[Path, Path]]:
    """(map, scen) pairs in ``folder``: ``X.map`` with ``X.map.scen`` or ``X-*.scen``."""
    folder = Path(folder)
    if not folder.is_dir():
        raise InputFormatError(folder, "not a folder of .map and .scen files")
    pairs = {}
    for m in sorted(folder.glob("*.map")):
        scen = m.with_name(m.name + ".scen")
        if not scen.exists():
            alts = sorted(folder.glob(m.stem + "-*.scen"))
            scen = alts[0] if alts else None
        if scen is not None:
            pairs[m.stem] = (m, scen)
    if names:
        wanted = [n.removesuffix(".map") for n in names]
        unknown = [n for n in wanted if n not in pairs]
        if unknown:
            raise OptionError(f"names={', '.join(unknown)} not found in {folder}; "
                              f"valid: {', '.join(pairs)}", param="names")
        return [pairs[n] for n in wanted]
    if not pairs:
        raise InputFormatError(folder, "no .map file with a matching .scen file")
    return list(pairs.values())


@dataclass
class RunnerStats:
    """What one runner did on one map."""

    name: str
    peer: bool
    times: list = field(default_factory=list)
    ratios: list = field(default_factory=list)
    matched: int = 0
    failed: int = 0
    expanded: int = 0
    search_seconds: float = 0.0

    def row(self) -> dict:
        med = statistics.median(self.times) * 1e3 if self.times else None
        return {
            "runner": self.name,
            "peer": self.peer,
            "median_ms": med,
            "expansions_per_s": (self.expanded / self.search_seconds
                                 if self.search_seconds > 0 and not self.peer else None),
            "matched": self.matched,
            "failed": self.failed,
            "mean_cost_ratio": float(np.mean(self.ratios)) if self.ratios else None,
            "max_cost_ratio": float(np.max(self.ratios)) if self.ratios else None,
        }


# A runner is (query, score): query(s, t) is the timed call, score(answer) turns its
# answer into (cost or None, expanded, search seconds) after the clock has stopped.
Runner = tuple[Callable, Callable]


def _score_result(r) -> tuple:
    return r.cost if r.found else None, r.expanded, r.seconds


def _ours(grid: Grid, algorithm: str) -> Runner:
    def run(s, t):
        return plan(grid, s, t, algorithm=algorithm)

    return run, _score_result


def _prepared(grid: Grid, info: dict) -> Runner:
    index = prepare(grid)  # first build: loads the compiled kernels from numba's cache
    index = prepare(grid)
    try:
        peak, peak_error = build_peak_bytes(grid.blocked), None
    except RuntimeError as exc:  # the bench goes on; the report says why the figure is missing
        peak, peak_error = None, str(exc)
    info.update(build_seconds=index.build_seconds, index_bytes=index.nbytes,
                build_peak_bytes=peak, build_peak_error=peak_error,
                subgoals=index.subgoals, edges=index.edges, pivots=index.pivots,
                accelerator=index.accelerator, index=index.describe(),
                candidates_us={k: v * 1e6 for k, v in index.candidates.items()})

    return index.plan, _score_result


def _peer(grid: Grid, name: str) -> Runner:
    peer = PEERS[name]

    def score(answer):
        cells = peer.cells(answer)
        return (None if cells is None else octile_cost(cells)), 0, 0.0

    return peer.prepare(grid), score


def bench_map(map_path: Path, scen_path: Path, *, per_map: int, algorithms: Sequence[str],
              peers: Sequence[str], seed: int, prepared: bool = False,
              on_query: Callable[[], None] | None = None) -> dict:
    """Run one map's sampled queries through every runner (with ``prepared``, also
    through a prepared index); return its report."""
    grid = read_map(map_path)
    scen: Scenario = read_scen(scen_path)
    if (scen.width, scen.height) != (grid.width, grid.height):
        raise InputFormatError(scen_path, f"scenario is for a {scen.width}x{scen.height} map, "
                               f"{map_path.name} is {grid.width}x{grid.height}")
    return bench_queries(grid, scen, map_path.name, per_map=per_map, algorithms=algorithms,
                         peers=peers, seed=seed, prepared=prepared, on_query=on_query)


def bench_random(spec: str, *, per_map: int, algorithms: Sequence[str],
                 peers: Sequence[str], seed: int, prepared: bool = False,
                 on_query: Callable[[], None] | None = None) -> dict:
    """A synthetic ``SIDE:SHARE`` map (numpy seed ``seed``) with ``per_map`` far queries
    whose optima come from scipy; its report as :func:`bench_map`'s."""
    side, share = parse_random(spec)
    grid = random_grid(side, share, seed)
    scen = far_queries(grid, max(per_map, 1), seed)
    return bench_queries(grid, scen, grid.name, per_map=0, algorithms=algorithms,
                         peers=peers, seed=seed, prepared=prepared, on_query=on_query)


def bench_queries(grid: Grid, scen: Scenario, label: str, *, per_map: int,
                  algorithms: Sequence[str], peers: Sequence[str], seed: int,
                  prepared: bool = False,
                  on_query: Callable[[], None] | None = None) -> dict:
    """Run ``per_map`` sampled lines of ``scen`` (0: all) through every runner."""
    rng = np.random.default_rng(seed)
    n = len(scen) if per_map <= 0 else min(per_map, len(scen))
    idx = np.sort(rng.choice(len(scen), size=n, replace=False))
    runners = [(RunnerStats(a, False), *_ours(grid, a)) for a in algorithms]
    info: dict = {}
    if prepared:
        runners.append((RunnerStats("prepared", False), *_prepared(grid, info)))
    runners += [(RunnerStats(p, True), *_peer(grid, p)) for p in peers]
    first = idx[0]
    for _, run, score in runners:  # warm-up: compile, caches
        score(run(tuple(scen.starts[first].tolist()), tuple(scen.goals[first].tolist())))
    for q, i in enumerate(idx):
        s, t = tuple(scen.starts[i].tolist()), tuple(scen.goals[i].tolist())
        opt = float(scen.optimal[i])
        for k in range(len(runners)):
            stats, run, score = runners[(k + q) % len(runners)]
            t0 = time.perf_counter()
            answer = run(s, t)
            stats.times.append(time.perf_counter() - t0)
            cost, expanded, search_s = score(answer)
            stats.expanded += expanded
            stats.search_seconds += search_s
            if cost is None:
                stats.failed += 1
                continue
            stats.ratios.append(cost / opt if opt > 0 else (1.0 if cost == 0 else np.inf))
            stats.matched += bool(scen.matches(int(i), cost))
        if on_query:
            on_query()
    rows = [r[0].row() for r in runners]
    for row in rows:
        row["speedup_vs"] = {
            p["runner"]: p["median_ms"] / row["median_ms"]
            for p in rows if p["peer"] and p["median_ms"] and row["median_ms"]
            and not row["peer"]}
    report = {"map": label, "scen": scen.path.name, "size": [grid.width, grid.height],
              "queries": int(n), "scen_lines": len(scen), "rows": rows}
    if prepared:
        report["prepared"] = info
    return report


def check_runners(algorithms: Sequence[str], peers: Sequence[str]) -> tuple[list, list, list]:
    """Validate names; return (algorithms, installed peers, missing peers)."""
    for a in algorithms:
        check_choice("algorithm", a, GRID_ALGORITHMS)
    for p in peers:
        check_choice("peer", p, tuple(PEERS))
    have = [p for p in peers if available(p)]
    return list(algorithms), have, [p for p in peers if p not in have]


def count_queries(pairs: list[tuple[Path, Path]], per_map: int) -> int:
    """Read every map and scenario (so bad input fails before a long run starts) and
    return how many queries the run will make per runner, for a progress bar."""
    total = 0
    for map_path, scen_path in pairs:
        read_map(map_path)
        lines = len(read_scen(scen_path))
        total += lines if per_map <= 0 else min(per_map, lines)
    return total
