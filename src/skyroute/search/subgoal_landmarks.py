"""Landmark distances over a subgoal graph: a sharper heuristic for prepared queries.

The octile distance is a weak guess on mazes and room maps, where the path winds far
from the straight line. For a landmark L, the triangle inequality gives
``d(v, t) >= |d(L, v) - d(L, t)|`` (grid distances are symmetric, and the subgoal graph's
distances equal them), so the largest of these bounds and the octile distance is an
admissible and consistent heuristic (Goldberg & Harrelson's ALT). The landmarks are chosen
farthest first (each the subgoal farthest from those already chosen, within the largest
free region), and their distances come from scipy's Dijkstra over the graph at build time.
"""

from __future__ import annotations

import numpy as np

MOST_LANDMARKS = 64


def landmark_count(m: int) -> int:
    """Landmarks for a graph of m subgoals: one per 128 subgoals, at least 8 and at most
    64 (dense graphs gain most; on small maps the per-query setup would dominate)."""
    return min(m, max(8, min(MOST_LANDMARKS, m // 128)))


def edge_lengths(cells: np.ndarray, offs: np.ndarray, nbr: np.ndarray, Wp: int) -> np.ndarray:
    """Octile length of every CSR edge (from the cells' padded flat indices)."""
    src = np.repeat(cells, np.diff(offs))
    dst = cells[nbr]
    dx = np.abs(src % Wp - dst % Wp)
    dy = np.abs(src // Wp - dst // Wp)
    return np.maximum(dx, dy) + (np.sqrt(2.0) - 1.0) * np.minimum(dx, dy)


def landmark_distances(cells: np.ndarray, offs: np.ndarray, nbr: np.ndarray,
                       region: np.ndarray, Wp: int, count: int | None = None) -> np.ndarray:
    """(m, count) float32 graph distances from ``count`` landmarks (default
    :func:`landmark_count`) to every subgoal, inf where unreachable. ``region`` is
    each subgoal's free-region label: the landmarks go to the largest region."""
    # imported here: answering from a saved index needs no scipy
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import dijkstra

    m = cells.size
    count = landmark_count(m) if count is None else min(count, m)
    out = np.empty((m, count), np.float32)
    if count == 0:
        return out
    graph = csr_matrix((edge_lengths(cells, offs, nbr, Wp), nbr, offs), shape=(m, m))
    largest = np.argmax(np.bincount(region - region.min()))
    first = int(np.flatnonzero(region - region.min() == largest)[0])
    nearest = dijkstra(graph, indices=first)  # per subgoal: distance to the nearest landmark
    for j in range(count):
        landmark = int(np.argmax(np.where(np.isfinite(nearest), nearest, -1.0)))
        out[:, j] = dijkstra(graph, indices=landmark)
        nearest = np.minimum(nearest, out[:, j])
    return out
