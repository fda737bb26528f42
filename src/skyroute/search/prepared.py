"""Prepared grids: build a subgoal graph once, answer many exact queries fast.

``prepare(grid)`` returns a :class:`PreparedGrid` whose ``plan(start, goal)`` gives the
same :class:`~skyroute.PlanResult` as ``skyroute.plan`` with the A* default: the octile
optimum without corner cutting, every cell of the path. Its Python side is kept to one
compiled call and a cheap result, because on small maps a query takes microseconds.
``save`` writes the index as ``.npz`` (format version, the map's shape and a hash of its
blocked cells); ``load_index`` refuses an index built for another map.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from skyroute.errors import InputFormatError, OptionError, check_choice
from skyroute.files import as_path
from skyroute.keywords import strict_keywords, unknown_keywords
from skyroute.result import STATUS_OF_CODE, PlanResult
from skyroute.search import subgoal_table
from skyroute.search.cache_lines import line_aligned
from skyroute.search.canonical import CANONICAL
from skyroute.search.entry_points import entry_point
from skyroute.search.index_file import CH_ARRAYS, read_index, write_index
from skyroute.search.pivots import DENSE_PIVOTS, PIVOTS, jump_query, largest_region, pivot_distances
from skyroute.search.space import space_of, workspace
from skyroute.search.subgoal_build import clearances, link, subgoal_ids
from skyroute.search.subgoal_ch_query import WS_ROWS as CH_WS_ROWS
from skyroute.search.subgoal_ch_query import ch_query
from skyroute.search.subgoal_contract import hierarchy
from skyroute.search.subgoal_landmarks import landmark_distances
from skyroute.search.subgoal_query import WS_ROWS, heap_capacity, subgoal_query
from skyroute.search.subgoal_table import distance_table, table_query
from skyroute.world.grid import Grid

METHODS = ("auto", "subgoal", "jump")
SAMPLE = 32  # query pairs that "auto" times each candidate index on
NO_HIERARCHY = {"ch_offs": np.empty(0, np.int64), "ch_nbr": np.empty(0, np.int32),
                "ch_len": np.empty(0), "ch_mid": np.empty(0, np.int32),
                "ch_core": np.empty(0, np.int32), "ch_dist": np.empty((0, 0)),
                "ch_pred": np.empty((0, 0), np.int16)}


class PreparedGrid:
    """A grid with its index: ``plan(start, goal)`` answers exact octile queries.

    ``method`` is the index kind: "subgoal" (a subgoal graph) or "jump" (JPS with the
    differential bounds of 16 or 24 pivots). ``build_seconds`` is how long :func:`prepare`
    took (0 for a loaded index); ``nbytes`` counts the index arrays and the query
    workspace; ``accelerator`` names what answers: for a subgoal graph "table" (<= 2048
    subgoals), "hierarchy" (a contraction hierarchy with a table for its core) or
    "landmarks" (A* with landmark bounds, for graphs too dense to contract in time); for
    the other kind "jump". ``candidates`` holds what :func:`prepare`'s "auto" measured
    (seconds per sample query of each kind), empty when it did not choose.
    """

    def __init__(self, grid: Grid, arrays: dict, *, method: str = "subgoal",
                 build_seconds: float = 0.0) -> None:
        self.grid, self.method, self.build_seconds = grid, method, build_seconds
        self.candidates: dict[str, float] = {}
        self._space = space = space_of(grid)
        self.Wp, self._blk = space.Wp, space.blocked
        self._arrays = arrays
        if method == "jump":
            self.accelerator = "jump"
            self._kernel = jump_query
            arrays["piv"] = line_aligned(arrays["piv"])  # a loaded index: copied once
            self._args = (space.move_mask(8, False), CANONICAL, space.jump_table(),
                          arrays["label"], arrays["piv"], *workspace(self._blk.size),
                          space.f_scale(pivots=True), self.Wp)
            self._call = entry_point(self._kernel, *self._args, 0, 0)
            return
        cells = arrays["cells"]
        sg = np.full(self._blk.size, -1, np.int32)
        sg[cells] = np.arange(cells.size, dtype=np.int32)
        self._sg = sg
        m, lmd = cells.size, arrays["lmd"]
        if arrays["dist"].size:  # a small graph: its all-pairs table answers
            self.accelerator = "table"
            self._kernel = table_query
            self._args = (self._blk, sg, arrays["clr"], arrays["label"], cells,
                          arrays["dist"], arrays["pred"], np.zeros((3, m + 2), np.int64),
                          self.Wp)
        elif arrays["ch_offs"].size:  # a contraction hierarchy answers
            self.accelerator = "hierarchy"
            cid = arrays["ch_core"]
            self._kernel = ch_query
            self._args = (self._blk, sg, arrays["clr"], arrays["label"], cells,
                          *(arrays[k] for k in CH_ARRAYS[:4]), cid,
                          np.flatnonzero(cid >= 0).astype(np.int32), arrays["ch_dist"],
                          arrays["ch_pred"], np.zeros((CH_WS_ROWS, m + 2), np.int64),
                          np.zeros((2, m)), np.zeros((2, m)), self.Wp)
        else:
            self.accelerator = "landmarks"
            ws = np.zeros((WS_ROWS, m + 3), np.int64)
            ws[3, :m], ws[4, :m] = cells % self.Wp, cells // self.Wp
            cap = heap_capacity(m, arrays["nbr"].size)
            self._kernel = subgoal_query
            self._args = (self._blk, sg, arrays["clr"], arrays["offs"], arrays["nbr"],
                          arrays["label"], lmd, np.zeros((3, lmd.shape[1])), ws,
                          np.zeros(m + 2), np.zeros((2, cap)), np.zeros(cap, np.int64),
                          self.Wp)
        self._call = entry_point(self._kernel, *self._args, 0, 0)

    @property
    def subgoals(self) -> int:
        """How many subgoals (graph nodes) the index holds (0 for a "jump" index)."""
        return int(self._arrays["cells"].size) if "cells" in self._arrays else 0

    @property
    def edges(self) -> int:
        """How many directed edges the graph holds (0 for a "jump" index)."""
        return int(self._arrays["nbr"].size) if "nbr" in self._arrays else 0

    @property
    def pivots(self) -> int:
        """How many pivots bound a "jump" index's heuristic (0 for a subgoal graph)."""
        return int(self._arrays["piv"].shape[1]) if "piv" in self._arrays else 0

    def describe(self) -> str:
        """One line: the index kind and its size."""
        if self.method == "jump":
            return f"jump index, {self.pivots:,} pivots"
        return (f"subgoal index ({self.accelerator}), {self.subgoals:,} subgoals, "
                f"{self.edges:,} edges")

    def __repr__(self) -> str:
        return f"<PreparedGrid {self.grid.name!r}: {self.describe()}>"

    @property
    def nbytes(self) -> int:
        """Bytes of the index arrays, the padded grid and the query workspace."""
        return int(sum(a.nbytes for a in self._args if isinstance(a, np.ndarray)))

    @strict_keywords
    def plan(self, start, goal, **misspelt) -> PlanResult:
        """The exact octile path from cell ``start`` to ``goal``, both (x, y).

        Same contract as ``skyroute.plan(grid, start, goal)``: ``status`` found or
        no_path (at once, from component labels, when they lie in different free
        regions), ``path`` every cell, ``cost``; ``expanded`` counts graph nodes.
        """
        if misspelt:
            raise unknown_keywords(self.plan, misspelt)
        s, t = self._space.flat_pair(start, goal)
        t0 = time.perf_counter()
        code, path, cost, expanded, frontier = self._call(*self._args, s, t)
        seconds = time.perf_counter() - t0
        return PlanResult.of_search(STATUS_OF_CODE[code], path, cost, expanded, frontier,
                                    0, seconds, self.method, {})

    def __reduce__(self) -> tuple:
        """Pickled as the grid and the index arrays (its compiled entry and workspace are
        made anew where it is unpickled), so an index can go to other processes, e.g. Dask
        workers."""
        return _unpickled, (self.grid, self._arrays, self.method, self.build_seconds,
                            self.candidates)

    def save(self, path: str | Path) -> Path:
        """Write the index to ``path`` (``.npz`` format, whatever its suffix), whole or not
        at all; return the path written."""
        path = as_path(path, "path")
        write_index(path, self.method, np.asarray(self.grid.blocked, dtype=bool),
                    self._arrays)
        return path


def _unpickled(grid: Grid, arrays: dict, method: str, build_seconds: float,
               candidates: dict) -> PreparedGrid:
    index = PreparedGrid(grid, arrays, method=method, build_seconds=build_seconds)
    index.candidates = candidates
    return index


def z_order(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Morton codes of non-negative (x, y) below 2**16: the bits of x and y interleaved."""
    def spread(v):
        v = v.astype(np.uint64) & 0xFFFF
        v = (v | (v << 8)) & 0x00FF00FF
        v = (v | (v << 4)) & 0x0F0F0F0F
        v = (v | (v << 2)) & 0x33333333
        return (v | (v << 1)) & 0x55555555
    return spread(x) | (spread(y) << np.uint64(1))


def _padded(blocked: np.ndarray) -> np.ndarray:
    """A (H, W) blocked array as uint8 with a blocked border one cell wide."""
    padded = np.ones((blocked.shape[0] + 2, blocked.shape[1] + 2), np.uint8)
    padded[1:-1, 1:-1] = blocked
    return padded


def region_labels(blocked: np.ndarray) -> np.ndarray:
    """Each padded flat cell's free region (-1 blocked) for a (H, W) blocked array."""
    from scipy import ndimage  # imported here: a plain 'skyroute plan' must not pay for it

    padded = _padded(blocked)
    # Without corner cutting a diagonal step needs both side cells free, so the free
    # regions under 8-connected moves are exactly the 4-connected ones.
    lab, _ = ndimage.label(padded == 0)
    return (lab.ravel() - 1).astype(np.int32)


def build_arrays(blocked: np.ndarray, label: np.ndarray | None = None) -> dict:
    """The subgoal graph's arrays for a (H, W) blocked array (see subgoal_build) and its
    :func:`region_labels` (computed when not given)."""
    if label is None:
        label = region_labels(blocked)
    Wp = blocked.shape[1] + 2
    blk = _padded(blocked).ravel()
    sg, cells = subgoal_ids(blk, Wp)
    # number the subgoals along a Z-order curve: a node's graph neighbours then sit
    # near it in every per-node array (landmark rows above all), not a row apart
    cells = cells[np.argsort(z_order(cells % Wp, cells // Wp), kind="stable")]
    sg[cells] = np.arange(cells.size, dtype=np.int32)
    clr = clearances(blk, sg, Wp)
    offs, nbr = link(blk, sg, cells, clr, Wp)
    dist, pred = distance_table(cells, offs, nbr, Wp)
    # larger graphs: a hierarchy contracted down to a core the size of a table, unless
    # the graph is too dense to contract in time; then A* with landmarks
    ch = None
    if not dist.size and cells.size:
        ch = hierarchy(blk, cells, offs, nbr, Wp, subgoal_table.TABLE_MAX)
    lmd = landmark_distances(cells, offs, nbr, label[cells], Wp,
                             0 if dist.size or ch else None)
    return {"cells": cells, "clr": clr, "offs": offs, "nbr": nbr, "label": label,
            "lmd": lmd, "dist": dist, "pred": pred, **(ch or NO_HIERARCHY)}


def sample_pairs(label: np.ndarray, count: int = SAMPLE) -> np.ndarray:
    """(count, 2) flat cell pairs drawn (seeded) from the largest free region."""
    region = largest_region(label)
    if not region.size:
        return np.empty((0, 2), np.int64)
    return np.random.default_rng(0).choice(region, size=(count, 2))


def per_query_seconds(index: PreparedGrid, pairs: np.ndarray, rounds: int = 3) -> float:
    """The best of ``rounds`` mean times of ``index``'s compiled query over ``pairs``."""
    call, args = index._call, index._args
    best = np.inf
    for _ in range(rounds):
        t0 = time.perf_counter()
        for s, t in pairs.tolist():
            call(*args, s, t)
        best = min(best, (time.perf_counter() - t0) / max(len(pairs), 1))
    return best


def _require_grid(grid) -> None:
    if not isinstance(grid, Grid):
        from skyroute.world.world import World  # only on this error: shapely is heavy

        hint = ("; a World needs no prepare: skyroute.plan builds its roadmap on the "
                "first query and reuses it") if isinstance(grid, World) else ""
        raise OptionError(f"grid must be a skyroute Grid, got {type(grid).__name__}{hint}",
                          param="grid")


@strict_keywords
def prepare(grid: Grid, *, method: str = "auto", **misspelt) -> PreparedGrid:
    """Build a reusable index of ``grid`` for repeated exact queries.

    ``method`` "subgoal": a simple subgoal graph (Uras, Koenig & Hernandez 2013) with
    component labels, answered by an all-pairs table, a contraction hierarchy or A*
    with landmarks; "jump": JPS whose octile heuristic is sharpened by the exact
    distances from 24 pivots (a differential heuristic: 192 bytes a cell); "auto" (the
    default) builds the subgoal graph, keeps it when its table answers (small maps),
    and otherwise builds both and keeps the one that answers 32 seeded sample queries
    faster (``candidates`` holds the times); its jump index has 16 pivots where the
    subgoal graph was contracted into a hierarchy (that build took the time), else 24.
    docs/benchmarks.md section 12 says why.

    Examples
    --------
    >>> import skyroute
    >>> grid = skyroute.load_map("den312d")
    >>> index = skyroute.prepare(grid)
    >>> r = index.plan((50, 76), (60, 13))  # den312d.map.scen: 112.55634918
    >>> r.status.value, round(r.cost, 8), len(r.path)
    ('found', 112.55634919, 109)
    """
    if misspelt:
        raise unknown_keywords(prepare, misspelt)
    check_choice("method", method, METHODS)
    _require_grid(grid)
    t0 = time.perf_counter()
    blocked = np.asarray(grid.blocked, dtype=bool)
    label = region_labels(blocked)
    built = []
    if method != "jump":
        built.append(PreparedGrid(grid, build_arrays(blocked, label), method="subgoal"))
    if method == "jump" or (method == "auto" and built[0].accelerator != "table"):
        space = space_of(grid)
        contracted = built and built[0].accelerator == "hierarchy"
        piv = pivot_distances(space.move_mask(8, False), label, space.Wp,
                              PIVOTS if contracted else DENSE_PIVOTS)
        built.append(PreparedGrid(grid, {"label": label, "piv": piv}, method="jump"))
    index = built[0]
    if len(built) > 1:  # auto: the faster on the same sample
        pairs = sample_pairs(label)
        times = {b.method: per_query_seconds(b, pairs) for b in built}
        index = min(built, key=lambda b: times[b.method])
        index.candidates = times
    index.build_seconds = time.perf_counter() - t0
    return index


@strict_keywords
def load_index(path: str | Path, grid: Grid, **misspelt) -> PreparedGrid:
    """Read an index written by :meth:`PreparedGrid.save` for ``grid``; an unreadable,
    outdated, malformed or foreign index is an InputFormatError naming the file.
    Distances are trusted as written: load only indexes skyroute wrote (see
    :mod:`skyroute.search.index_file`)."""
    if misspelt:
        raise unknown_keywords(load_index, misspelt)
    _require_grid(grid)
    blocked = np.asarray(grid.blocked, dtype=bool)
    method, arrays = read_index(as_path(path, "path"), blocked, grid.name)
    if not _fits_the_map(blocked, arrays):
        raise InputFormatError(path, "not a skyroute index: its region labels or clearances "
                               "do not fit the map; rebuild it with 'skyroute prepare'")
    return PreparedGrid(grid, arrays, method=method)


def _fits_the_map(blocked: np.ndarray, arrays: dict) -> bool:
    """Whether an index's arrays that the map determines are the map's own, in
    milliseconds: region labels -1 exactly on blocked cells and equal across every free
    edge (so no free region is split: "no path" is never answered where one exists),
    and a subgoal graph's clearances recomputed (so a query never walks by numbers
    another map or a hand gave)."""
    padded = _padded(blocked)
    free, lab = padded == 0, arrays["label"].reshape(padded.shape)
    if not np.array_equal(lab >= 0, free):
        return False
    across = free[:, 1:] & free[:, :-1], free[1:, :] & free[:-1, :]
    if np.any(lab[:, 1:][across[0]] != lab[:, :-1][across[0]]) or \
            np.any(lab[1:, :][across[1]] != lab[:-1, :][across[1]]):
        return False
    if "clr" not in arrays:
        return True
    sg = np.full(padded.size, -1, np.int32)
    sg[arrays["cells"]] = np.arange(arrays["cells"].size, dtype=np.int32)
    return np.array_equal(arrays["clr"], clearances(padded.ravel(), sg, padded.shape[1]))
