"""Synthetic benchmark maps: uniformly random blocked cells with far queries whose optimal
octile lengths come from scipy's Dijkstra (an independent solver), as a ``Scenario``.

``512:0.2`` is a 512x512 map with each cell blocked with probability 0.2 (numpy seed
given). Queries join cells of the largest free region (8-connected, no corner cutting,
the MovingAI rule) at octile distance at least half the map's side, so every query
crosses the map's scattered obstacles: the hard case for A* and JPS.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components, dijkstra

from skyroute.errors import OptionError
from skyroute.world.grid import Grid
from skyroute.world.movingai import Scenario

SQRT2 = 2.0 ** 0.5
ROWS_BYTES = 256 << 20  # scipy's distance rows held at once while finding the optima


def parse_random(text: str) -> tuple[int, float]:
    """``512:0.2`` -> (512, 0.2): side in cells and blocked share."""
    side, _, share = text.partition(":")
    try:
        n, p = int(side), float(share)
    except ValueError:
        n, p = 0, -1.0
    if not (2 <= n <= 4096 and 0.0 <= p < 1.0):
        raise OptionError(f"--random {text!r}: expected SIDE:SHARE with 2 <= SIDE <= 4096 and "
                          "0 <= SHARE < 1, e.g. 512:0.2", param="random")
    return n, p


def random_grid(side: int, share: float, seed: int = 0) -> Grid:
    """A ``side`` x ``side`` grid, each cell blocked with probability ``share``."""
    rng = np.random.default_rng(seed)
    return Grid(rng.random((side, side)) < share, name=f"random-{side}-{share:g}-s{seed}")


def octile_graph(blocked: np.ndarray):
    """The free cells' 8-connected graph without corner cutting, as a scipy CSR matrix
    (cell index y * width + x; straight edges 1, diagonal sqrt 2)."""
    h, w = blocked.shape
    idx = np.arange(h * w).reshape(h, w)
    free = ~blocked
    rows, cols, wts = [], [], []

    def add(a, b, ok, cost):
        rows.append(a[ok])
        cols.append(b[ok])
        wts.append(np.full(int(ok.sum()), cost))

    add(idx[:, :-1], idx[:, 1:], free[:, :-1] & free[:, 1:], 1.0)
    add(idx[:-1, :], idx[1:, :], free[:-1, :] & free[1:, :], 1.0)
    side = free[:-1, :-1] & free[1:, 1:] & free[:-1, 1:] & free[1:, :-1]
    add(idx[:-1, :-1], idx[1:, 1:], side, SQRT2)
    add(idx[:-1, 1:], idx[1:, :-1], side, SQRT2)
    r, c, v = np.concatenate(rows), np.concatenate(cols), np.concatenate(wts)
    return coo_matrix((v, (r, c)), shape=(h * w, h * w)).tocsr()


def far_queries(grid: Grid, count: int, seed: int = 0) -> Scenario:
    """``count`` queries between cells of the largest free region at octile distance
    >= side / 2 (where the region holds no such pair, the farthest of 1000 tried), with
    optima from scipy's Dijkstra, as a ``Scenario``."""
    blocked = grid.blocked
    h, w = blocked.shape
    graph = octile_graph(blocked)
    _, labels = connected_components(graph, directed=False)
    labels = np.where(blocked.ravel(), -1, labels)
    sizes = np.bincount(labels[labels >= 0])
    if sizes.size == 0 or sizes.max() < 2:  # no free cell at all, or only lone ones
        raise OptionError(f"{grid.name}: fewer than two free cells; lower the blocked share",
                          param="random")
    cells = np.flatnonzero(labels == sizes.argmax())
    rng = np.random.default_rng(seed)
    want = max(w, h) / 2
    starts, goals = [], []
    for _ in range(count):
        best = (-1.0, 0, 0)  # a small region may hold no far pair: keep the farthest tried
        for _tries in range(1000):
            a, b = rng.choice(cells, 2, replace=False)
            dx, dy = abs(a % w - b % w), abs(a // w - b // w)
            best = max(best, (max(dx, dy) + (SQRT2 - 1) * min(dx, dy), a, b))
            if best[0] >= want:
                break
        starts.append(best[1])
        goals.append(best[2])
    starts, goals = np.array(starts), np.array(goals)
    optimal = _optima(graph, starts, goals)
    xy = lambda c: np.stack([c % w, c // w], axis=1).astype(np.int64)  # noqa: E731
    return Scenario(path=Path(f"{grid.name}.scen"), map_name=grid.name, width=w, height=h,
                    buckets=np.zeros(count, dtype=np.int64), starts=xy(starts),
                    goals=xy(goals), optimal=optimal,
                    tolerance=np.full(count, 1e-9))


def _optima(graph, starts: np.ndarray, goals: np.ndarray) -> np.ndarray:
    """scipy's Dijkstra distance from each start to its goal, a few starts at a time: one
    distance row per start is a float per cell, 2.7 GB for 20 starts on a 4096x4096 map."""
    step = max(1, ROWS_BYTES // (8 * graph.shape[0]))
    parts = []
    for i in range(0, len(starts), step):
        dist = dijkstra(graph, directed=False, indices=starts[i:i + step])
        parts.append(dist[np.arange(len(dist)), goals[i:i + step]])
    return np.concatenate(parts)
