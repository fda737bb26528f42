"""Peer grid planners a user might otherwise pick, behind one small interface.

Each peer builds what it needs from a Grid once (not timed) and then answers queries
in its own form, as a user of that library would get them; ``cells`` turns an answer
into an array of (x, y) cells or None, outside the timed call. Peers are optional
(``skyroute[bench]``); one that is not installed is reported, not fatal.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from skyroute.world.grid import Grid

Query = Callable[[tuple[int, int], tuple[int, int]], object]


@dataclass(frozen=True)
class Peer:
    """A peer: its name, what problem it solves, how to prepare it for a grid and how
    to read its answer as (x, y) cells (None: no path)."""

    name: str
    module: str
    note: str
    prepare: Callable[[Grid], Query]
    cells: Callable[[object], np.ndarray | None]
    max_cells: int | None = None  # larger maps are skipped: the peer would not fit in memory
    bytes_per_cell: int = 0  # the measured memory that sets max_cells, for the note


def _pyastar2d(grid: Grid) -> Query:
    import pyastar2d

    weights = np.where(grid.blocked, np.inf, 1.0).astype(np.float32)

    def query(s, t):
        return pyastar2d.astar_path(weights, (s[1], s[0]), (t[1], t[0]), allow_diagonal=True)

    return query


def _rows_cols(path) -> np.ndarray | None:
    """pyastar2d's (row, col) path as (x, y) cells."""
    return None if path is None else path[:, ::-1]


def _pathfinding(grid: Grid) -> Query:
    from pathfinding.core.diagonal_movement import DiagonalMovement
    from pathfinding.core.grid import Grid as PFGrid
    from pathfinding.finder.a_star import AStarFinder

    pf = PFGrid(matrix=(~grid.blocked).astype(int).tolist())
    finder = AStarFinder(diagonal_movement=DiagonalMovement.only_when_no_obstacle)

    def query(s, t):
        pf.cleanup()
        return finder.find_path(pf.node(*s), pf.node(*t), pf)[0]

    return query


def _nodes(path) -> np.ndarray | None:
    """python-pathfinding's list of nodes as (x, y) cells."""
    return np.array([(n.x, n.y) for n in path]) if path else None


def _networkx(grid: Grid) -> Query:
    import networkx as nx

    free = ~grid.blocked
    G = nx.Graph()
    ys, xs = np.nonzero(free)
    G.add_nodes_from(zip(xs.tolist(), ys.tolist(), strict=True))
    h, w = free.shape
    for dx, dy, cost in ((1, 0, 1.0), (0, 1, 1.0), (1, 1, math.sqrt(2)), (-1, 1, math.sqrt(2))):
        ok = np.zeros_like(free)
        y0, y1 = 0, h - dy
        x0, x1 = max(0, -dx), w - max(0, dx)
        ok[y0:y1, x0:x1] = free[y0:y1, x0:x1] & free[y0 + dy:y1 + dy, x0 + dx:x1 + dx]
        if dx and dy:  # no corner cutting: both side cells free
            ok[y0:y1, x0:x1] &= free[y0:y1, x0 + dx:x1 + dx] & free[y0 + dy:y1 + dy, x0:x1]
        yy, xx = np.nonzero(ok)
        G.add_weighted_edges_from(
            ((x, y), (x + dx, y + dy), cost) for x, y in zip(xx.tolist(), yy.tolist(),
                                                             strict=True))

    def octile(a, b):
        dx, dy = abs(a[0] - b[0]), abs(a[1] - b[1])
        return max(dx, dy) + (math.sqrt(2) - 1) * min(dx, dy)

    def query(s, t):
        try:
            return nx.astar_path(G, tuple(s), tuple(t), heuristic=octile)
        except nx.NetworkXNoPath:
            return None

    return query


def _tuples(path) -> np.ndarray | None:
    """A list of (x, y) node tuples as cells."""
    return None if path is None else np.array(path)


PEERS = {
    "pyastar2d": Peer("pyastar2d", "pyastar2d", "C++ A*; cuts corners, diagonal cost 1",
                      _pyastar2d, _rows_cols),
    "pathfinding": Peer("pathfinding", "pathfinding", "python-pathfinding AStarFinder, "
                        "no corner cutting", _pathfinding, _nodes),
    "networkx": Peer("networkx", "networkx", "networkx astar_path on the move graph "
                     "(graph build not timed)", _networkx, _tuples,
                     # measured: 0.41 GB at 512x512, 2.0 at 1024, 6.1 at 2048, ~25 at 4096
                     max_cells=2048 * 2048, bytes_per_cell=1500),
}


def available(name: str) -> bool:
    """True when the peer's package imports."""
    import importlib.util

    return importlib.util.find_spec(PEERS[name].module) is not None


def skip_reason(name: str, grid: Grid) -> str | None:
    """Why the peer cannot run on ``grid`` (more cells than its memory allows), or None."""
    peer = PEERS[name]
    if peer.max_cells is None or grid.width * grid.height <= peer.max_cells:
        return None
    need = grid.width * grid.height * peer.bytes_per_cell / 1e9
    return (f"{grid.width}x{grid.height} is over its limit of {peer.max_cells:,} cells "
            f"(its graph would need about {need:.0f} GB)")

