"""``skyroute bench grid``: MovingAI scenarios through skyroute's planners and the peers.

All runners answer the same queries in one process, interleaved (the order rotates each
query, so drift in machine speed spreads evenly), after one untimed warm-up query each.
Times are wall clock around one call: ``skyroute.plan`` for ours (validation included),
``PreparedGrid.plan`` for the ``prepared`` runner (its index is built once per map, timed
apart as ``build_seconds``, its size the arrays' ``nbytes``, the build's peak resident
memory from a fresh process as ``build_peak_bytes``), the peer's own query call
for a peer (its one-off set-up is not timed). What the bench does with an answer
(checking and re-measuring its path, reading a result's fields) happens after the clock
stops. A line is matched when the answer is a legal path for the query and its length,
re-measured from the path (:mod:`skyroute.bench.path_check`), equals the optimum; an
answer that is no legal path, or whose reported cost is not its path's length, is
counted as ``invalid``.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from skyroute.bench.build_memory import build_peak_bytes
from skyroute.bench.path_check import Checker, legal_length, path_length
from skyroute.bench.peers import PEERS, available, skip_reason
from skyroute.bench.random_maps import far_queries, parse_random, random_grid
from skyroute.errors import InputFormatError, OptionError, check_choice
from skyroute.files import need_folder
from skyroute.planner import plan
from skyroute.search.grid_plan import ANY_ANGLE, GRID_ALGORITHMS
from skyroute.search.prepared import prepare
from skyroute.world.grid import Grid
from skyroute.world.movingai import Scenario, query_line, read_map, read_scen

# Algorithms whose cost must equal the scenario's octile optimum.
OPTIMAL = ("dijkstra", "astar", "jps")
# Queries a map: the largest MovingAI scenario file here has 12,121 lines (per_map=0
# runs them all); the documented runs sample 20-40.
MAX_PER_MAP = 10_000
# A random map's optima are one scipy Dijkstra over its cells per query (0.06 s on
# 512x512, 0.35 s on 1024x1024): queries x cells is limited to minutes of them; the
# default 20 queries on the largest map (4096x4096) are 335 million.
MAX_RANDOM_CELL_QUERIES = 1 << 29


def find_pairs(folder: str | Path, names: Sequence[str] = ()) -> list[tuple[Path, Path]]:
    """(map, scen) pairs in ``folder``: ``X.map`` with ``X.map.scen`` or ``X-*.scen``."""
    folder = need_folder(folder, "of .map and .scen files")
    pairs = {}
    for m in sorted(folder.glob("*.map")):
        scen = m.with_name(m.name + ".scen")
        if not scen.exists():
            alts = sorted(folder.glob(m.stem + "-*.scen"))
            scen = alts[0] if alts else None
        if scen is not None:
            pairs[m.stem] = (m, scen)
    if names:
        wanted = list(dict.fromkeys(n.removesuffix(".map") for n in names))  # once each
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
    invalid: int = 0
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
            "invalid": self.invalid,
            "mean_cost_ratio": float(np.mean(self.ratios)) if self.ratios else None,
            "max_cost_ratio": float(np.max(self.ratios)) if self.ratios else None,
        }


# A runner is (query, score): query(s, t) is the timed call, score(answer, s, t) turns
# its answer into (path length or None for no path, legal, expanded, search seconds)
# after the clock has stopped.
Runner = tuple[Callable, Callable]


def _result_scorer(check: Checker, *, any_angle: bool = False) -> Callable:
    """Score a PlanResult by its path, re-measured; legal only when the path answers
    the query and its reported cost is that path's length."""
    def score(r, s, t):
        if not r.found:
            return None, False, r.expanded, r.seconds
        length = check(r.path, s, t, any_angle)
        legal = length is not None and abs(r.cost - length) <= 1e-9 * max(1.0, length)
        return path_length(r.path), legal, r.expanded, r.seconds

    return score


def _ours(grid: Grid, algorithm: str, check: Checker) -> Runner:
    def run(s, t):
        return plan(grid, s, t, algorithm=algorithm)

    return run, _result_scorer(check, any_angle=algorithm in ANY_ANGLE)


def _prepared(grid: Grid, info: dict, check: Checker) -> Runner:
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

    return index.plan, _result_scorer(check)


def _peer(grid: Grid, name: str, check: Checker) -> Runner:
    peer = PEERS[name]

    def score(answer, s, t):
        cells = peer.cells(answer)
        if cells is None:
            return None, False, 0, 0.0
        return path_length(cells), check(cells, s, t) is not None, 0, 0.0

    return peer.prepare(grid), score


@dataclass(frozen=True, eq=False)
class Case:
    """One map to bench, read and checked: its label, grid, scenario and how many of the
    scenario's lines to sample (0: all). ``made``: the queries were made for a random map
    (:func:`random_case`), not read from a scenario file."""

    label: str
    grid: Grid
    scen: Scenario
    per_map: int
    made: bool = False

    @property
    def queries(self) -> int:
        """How many queries each runner will answer on this map."""
        return len(self.scen) if self.per_map <= 0 else min(self.per_map, len(self.scen))


def load_case(map_path: Path, scen_path: Path, *, per_map: int) -> Case:
    """Read a map and its scenario and check that every line can be run on it
    (:func:`check_scenario`), so bad input fails before any timing."""
    grid = read_map(map_path)
    scen = read_scen(scen_path)
    check_scenario(grid, scen, Path(map_path).name)
    return Case(Path(map_path).name, grid, scen, per_map)


def random_case(spec: str, *, per_map: int, seed: int) -> Case:
    """A synthetic ``SIDE:SHARE`` map (numpy seed ``seed``) with ``per_map`` far queries
    whose optima come from scipy; all of them are run."""
    side, share = parse_random(spec)
    check_random_per_map(per_map, side)
    grid = random_grid(side, share, seed)
    return Case(grid.name, grid, far_queries(grid, per_map, seed), 0, made=True)


def check_per_map(per_map: int) -> None:
    """An OptionError past :data:`MAX_PER_MAP` queries a map (0, every line, is fine)."""
    if per_map > MAX_PER_MAP:
        raise OptionError(f"per_map={per_map:,} is over the limit of {MAX_PER_MAP:,} queries "
                          "a map (0 runs every scenario line)", param="per_map")


def check_random_per_map(per_map: int, side: int | None = None) -> None:
    """A random map's queries are made, not sampled from a file: ``per_map=0`` (every
    scenario line) cannot apply to it, so it is refused rather than guessed; nor may
    ``per_map`` x the cells of a ``side`` x ``side`` map pass
    :data:`MAX_RANDOM_CELL_QUERIES` (each query's optimum searches the whole map)."""
    if per_map <= 0:
        raise OptionError(f"per_map={per_map} (every scenario line) has no meaning for random "
                          "maps, which have no scenario file; give a count >= 1",
                          param="per_map")
    check_per_map(per_map)
    if side is not None and per_map * side * side > MAX_RANDOM_CELL_QUERIES:
        most = MAX_RANDOM_CELL_QUERIES // (side * side)
        raise OptionError(f"per_map={per_map:,} far queries on a {side}x{side} random map "
                          f"would each search its {side * side:,} cells for the optimum; "
                          f"at most {most:,} on a map that size", param="per_map")


def check_scenario(grid: Grid, scen: Scenario, map_name: str) -> None:
    """Raise InputFormatError naming the .scen file and line unless the scenario names
    the map (its second column's file name; a folder before it is ignored), is for the
    grid's size (a version-0 file gives none) and every line's start and goal lie on
    free cells of it."""
    named = scen.map_name.replace("\\", "/").rsplit("/", 1)[-1]
    if named != map_name:
        raise InputFormatError(scen.path, f"scenario is for {named} (its map column), not "
                               f"{map_name}", line=query_line(scen.path, 0))
    if scen.width is not None and (scen.width, scen.height) != (grid.width, grid.height):
        raise InputFormatError(scen.path, f"scenario is for a {scen.width}x{scen.height} map, "
                               f"{map_name} is {grid.width}x{grid.height}",
                               line=query_line(scen.path, 0))
    bad_start, bad_goal = _off_free(grid, scen.starts), _off_free(grid, scen.goals)
    if not (bad_start.any() or bad_goal.any()):
        return
    i = int(np.argmax(bad_start | bad_goal))
    what, cells = ("start", scen.starts) if bad_start[i] else ("goal", scen.goals)
    x, y = (int(v) for v in cells[i])
    where = (f"lies outside {map_name} ({grid.width}x{grid.height})"
             if not grid.in_bounds((x, y)) else f"is on a blocked cell of {map_name}")
    raise InputFormatError(scen.path, f"{what} ({x}, {y}) {where}", line=query_line(scen.path, i))


def _off_free(grid: Grid, cells: np.ndarray) -> np.ndarray:
    """Per (x, y) row of ``cells``: True where it is outside the grid or blocked."""
    x, y = cells[:, 0], cells[:, 1]
    inside = (x >= 0) & (x < grid.width) & (y >= 0) & (y < grid.height)
    bad = ~inside
    bad[inside] = grid.blocked[y[inside], x[inside]]
    return bad


def bench_case(case: Case, *, algorithms: Sequence[str], peers: Sequence[str], seed: int,
               prepared: bool = False, on_query: Callable[[], None] | None = None) -> dict:
    """Run one checked map's queries through every runner; return its report. A random
    map's report has no scenario file: ``scen`` and ``scen_lines`` are None (they named a
    ``random-512-0.2-s0.scen`` that does not exist, and its "lines")."""
    report = bench_queries(case.grid, case.scen, case.label, per_map=case.per_map,
                           algorithms=algorithms, peers=peers, seed=seed, prepared=prepared,
                           on_query=on_query)
    if case.made:
        report.update(scen=None, scen_lines=None)
    return report


def bench_map(map_path: Path, scen_path: Path, *, per_map: int, algorithms: Sequence[str],
              peers: Sequence[str], seed: int, prepared: bool = False,
              on_query: Callable[[], None] | None = None) -> dict:
    """Run one map's sampled queries through every runner (with ``prepared``, also
    through a prepared index); return its report."""
    return bench_case(load_case(map_path, scen_path, per_map=per_map), algorithms=algorithms,
                      peers=peers, seed=seed, prepared=prepared, on_query=on_query)


def bench_random(spec: str, *, per_map: int, algorithms: Sequence[str],
                 peers: Sequence[str], seed: int, prepared: bool = False,
                 on_query: Callable[[], None] | None = None) -> dict:
    """A synthetic ``SIDE:SHARE`` map (numpy seed ``seed``) with ``per_map`` far queries
    whose optima come from scipy; its report as :func:`bench_map`'s."""
    return bench_case(random_case(spec, per_map=per_map, seed=seed), algorithms=algorithms,
                      peers=peers, seed=seed, prepared=prepared, on_query=on_query)


def bench_queries(grid: Grid, scen: Scenario, label: str, *, per_map: int,
                  algorithms: Sequence[str], peers: Sequence[str], seed: int,
                  prepared: bool = False,
                  on_query: Callable[[], None] | None = None) -> dict:
    """Run ``per_map`` sampled lines of ``scen`` (0: all) through every runner."""
    rng = np.random.default_rng(seed)
    n = len(scen) if per_map <= 0 else min(per_map, len(scen))
    idx = np.sort(rng.choice(len(scen), size=n, replace=False))
    check = legal_length(grid)
    runners = [(RunnerStats(a, False), *_ours(grid, a, check)) for a in algorithms]
    info: dict = {}
    if prepared:
        runners.append((RunnerStats("prepared", False), *_prepared(grid, info, check)))
    skipped = {p: why for p in peers if (why := skip_reason(p, grid))}
    runners += [(RunnerStats(p, True), *_peer(grid, p, check)) for p in peers
                if p not in skipped]
    first = idx[0]
    for _, run, score in runners:  # warm-up: compile, caches
        s, t = tuple(scen.starts[first].tolist()), tuple(scen.goals[first].tolist())
        score(run(s, t), s, t)
    for q, i in enumerate(idx):
        s, t = tuple(scen.starts[i].tolist()), tuple(scen.goals[i].tolist())
        opt = float(scen.optimal[i])
        for k in range(len(runners)):
            stats, run, score = runners[(k + q) % len(runners)]
            t0 = time.perf_counter()
            answer = run(s, t)
            stats.times.append(time.perf_counter() - t0)
            cost, legal, expanded, search_s = score(answer, s, t)
            stats.expanded += expanded
            stats.search_seconds += search_s
            if cost is None:
                stats.failed += 1
                continue
            stats.ratios.append(cost / opt if opt > 0 else (1.0 if cost == 0 else np.inf))
            stats.invalid += not legal
            stats.matched += legal and bool(scen.matches(int(i), cost))
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
    if skipped:
        report["skipped_peers"] = skipped
    if prepared:
        report["prepared"] = info
    return report


def check_runners(algorithms: Sequence[str], peers: Sequence[str]) -> tuple[list, list, list]:
    """Validate names; return (algorithms, installed peers, missing peers), each name once
    in the order given."""
    algorithms, peers = list(dict.fromkeys(algorithms)), list(dict.fromkeys(peers))
    for a in algorithms:
        check_choice("algorithms", a, GRID_ALGORITHMS)
    for p in peers:
        check_choice("peers", p, tuple(PEERS))
    have = [p for p in peers if available(p)]
    return algorithms, have, [p for p in peers if p not in have]
