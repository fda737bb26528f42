"""Probabilistic roadmap (Kavraki et al. 1996): free samples joined to their k nearest
neighbours when the segment between them is free; k-PRM* (Karaman & Frazzoli 2011) sets
k = ceil(e (1 + 1/d) log n) with d = 2. Built once per world; each query joins start
and goal to their nearest visible samples, runs Dijkstra (scipy) on the roadmap, then
shortcuts the result by the exact segment test: greedy vertex shortcuts, random
sub-segment shortcuts (as OMPL's path simplifier), and greedy again.

Samples are drawn in the world's boundary or, without one, in the obstacles' bounds
grown by :data:`MARGIN` of their size on every side, whose four outer corners are
nodes too (counted among ``samples``, and kept when it is below 4), joined in a ring:
a path may have to go round every obstacle (a no-fly zone between start and goal),
and that way is then always in the roadmap. A world with
neither (no boundary, and no obstacle at the chosen altitude) has an empty roadmap:
every query's path is its straight segment.

Reproducible: the samples come from ``seed``, and each query's random shortcuts from a
generator seeded by ``seed`` and the query's own coordinates, so the same world, query,
options and seed give the same path on every call and in every process. ``expanded``
counts the roadmap nodes Dijkstra settles up to the goal (those no farther than it).
scipy's Dijkstra has no expansion budget, so ``max_expansions`` is refused.
"""

from __future__ import annotations

import math
import time

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra
from scipy.spatial import cKDTree

from skyroute.errors import OptionError, check_seed, flag, whole
from skyroute.result import PlanResult, Status
from skyroute.roadmap.limits import MAX_SAMPLES, MIN_SAMPLES
from skyroute.roadmap.simplify import shortcut, smooth
from skyroute.world.world import World


class PRM:
    """A roadmap over a world's free space (see module docstring)."""

    def __init__(self, world: World, *, samples: int = 1000, neighbours: int = 10,
                 prm_star: bool = False, seed: int = 0) -> None:
        samples, neighbours, prm_star, seed = prm_options(samples, neighbours, prm_star, seed)
        self.seed = seed
        rng = np.random.default_rng(self.seed)
        t0 = time.perf_counter()
        self.world = world.merged()
        if world.boundary is None and len(self.world.obstacles) == 0:
            # nothing in the way (say every obstacle below a high altitude) and no extent
            # to sample: the roadmap is empty, and each query its straight segment
            self.points, self.edges = np.empty((0, 2)), np.empty((0, 2), np.intp)
            self.k, self.tree, self.edge_checks = 0, None, 0
            self.build_seconds = time.perf_counter() - t0
            return
        box = self.world.bounds
        ring = np.empty((0, 2))
        if world.boundary is None:
            # the free space goes on round the obstacles, and a path may have to go round
            # them all (a no-fly zone, or a row of them, between start and goal): sample
            # a margin too, and keep its outer corners, joined in a ring, as nodes
            x0, y0, x1, y1 = box
            grow = MARGIN * max(x1 - x0, y1 - y0)
            box = (x0 - grow, y0 - grow, x1 + grow, y1 + grow)
            ring = np.array([box[:2], (box[2], box[1]), box[2:], (box[0], box[3])])
        pts = np.vstack([ring, _free_samples(self.world, box, samples, rng)])
        if len(pts) < 2:
            raise OptionError(f"PRM drew {len(pts)} free point(s) from the world's extent "
                              "and needs at least 2: its free space is empty or too thin "
                              "to sample", param="samples")
        # the ring's corners are always kept (with samples < 4 the ring's edges named
        # nodes past the cut: IndexError)
        self.points = pts[:max(samples, len(ring))]
        n = len(self.points)
        self.k = math.ceil(math.e * 1.5 * math.log(n)) if prm_star else neighbours
        self.tree = cKDTree(self.points)
        _, nb = self.tree.query(self.points, k=min(self.k + 1, n))
        i = np.r_[np.repeat(np.arange(n), nb.shape[1] - 1), np.arange(len(ring))]
        j = np.r_[nb[:, 1:].ravel(), np.roll(np.arange(len(ring)), -1)]
        a, b = np.minimum(i, j), np.maximum(i, j)
        pairs = np.unique(np.c_[a, b], axis=0)
        free = self.world.segments_free(self.points[pairs[:, 0]], self.points[pairs[:, 1]])
        self.edges = pairs[free]
        self.edge_checks = len(pairs)
        self.build_seconds = time.perf_counter() - t0

    def plan(self, start, goal, *, max_expansions: int | None = None) -> PlanResult:
        """Shortest roadmap path from plane point ``start`` to ``goal``, shortcut (the
        plane is the world's; :func:`skyroute.plan` converts from and to its frame)."""
        if max_expansions is not None:
            raise OptionError("max_expansions: PRM searches its roadmap with scipy's "
                              "Dijkstra, which has no expansion budget; bound the work with "
                              "samples instead", param="max_expansions")
        w = self.world
        s = w.check_plane_point(start, "start")
        t = w.check_plane_point(goal, "goal")
        t0 = time.perf_counter()
        n = len(self.points)
        pts = np.vstack([self.points, s, t])
        rows, cols = [self.edges[:, 0]], [self.edges[:, 1]]
        checks = 0
        for node, p in ((n, s), (n + 1, t)) if n else ():
            _, nb = self.tree.query(p, k=min(self.k, n))
            nb = np.atleast_1d(nb)
            ok = w.segments_free(np.broadcast_to(p, (len(nb), 2)), self.points[nb])
            checks += len(nb)
            rows.append(np.full(int(ok.sum()), node))
            cols.append(nb[ok])
        direct = w.segment_free(s, t)
        checks += 1
        if direct:
            rows.append(np.array([n]))
            cols.append(np.array([n + 1]))
        r, c = np.concatenate(rows), np.concatenate(cols)
        lengths = np.hypot(*(pts[r] - pts[c]).T)
        graph = coo_matrix((lengths + 1e-300, (r, c)), shape=(n + 2, n + 2)).tocsr()
        dist, pred = dijkstra(graph, directed=False, indices=n, return_predecessors=True)
        settled = int(np.count_nonzero(np.isfinite(dist) & (dist <= dist[n + 1])))
        # the same keys whatever the status: a caller tabling runs reads every one
        extra = {"samples": n, "edges": len(self.edges), "k": self.k,
                 "raw_cost": float(dist[n + 1]), "build_seconds": self.build_seconds}
        if not np.isfinite(dist[n + 1]):
            return PlanResult(Status.NO_PATH, np.empty((0, 2)), math.inf, settled, 0, checks,
                              time.perf_counter() - t0, "prm", extra)
        path = [n + 1]
        while path[-1] != n:
            path.append(int(pred[path[-1]]))
        raw = pts[path[::-1]]
        short, tests = shortcut(w, raw)
        short, more = smooth(w, short, self._query_rng(s, t))
        short, again = shortcut(w, short)
        tests += more + again
        cost = float(np.hypot(*np.diff(short, axis=0).T).sum())
        return PlanResult(Status.FOUND, short, cost, settled, 0, checks + tests,
                          time.perf_counter() - t0, "prm", extra)

    def _query_rng(self, s: np.ndarray, t: np.ndarray) -> np.random.Generator:
        """The shortcuts' generator for one query: from the seed and the query's bits."""
        bits = np.concatenate([s, t]).astype(np.float64).view(np.uint64)
        return np.random.default_rng(np.random.SeedSequence([self.seed, *bits.tolist()]))

    def edge_segments(self) -> np.ndarray:
        """(E, 2, 2) plane segments of the roadmap's edges (for plots)."""
        return self.points[self.edges]


MARGIN = 0.1  # of the obstacles' extent: sampled round them in a world with no boundary


def prm_options(samples, neighbours, prm_star, seed) -> tuple[int, int, bool, int]:
    """The options checked and as plain Python values (numpy integers are integers), or
    an OptionError naming the first bad one."""
    return (whole("samples", samples, low=MIN_SAMPLES, high=MAX_SAMPLES),
            whole("neighbours", neighbours, low=1), flag("prm_star", prm_star),
            check_seed(seed))


def _free_samples(world: World, box: tuple, samples: int, rng) -> np.ndarray:
    """Up to ``samples`` uniform free points of ``box`` (xmin, ymin, xmax, ymax), drawn in
    at most 100 batches of ``2 * samples``."""
    xmin, ymin, xmax, ymax = box
    pts = np.empty((0, 2))
    for _ in range(100):
        batch = rng.uniform([xmin, ymin], [xmax, ymax], size=(2 * samples, 2))
        pts = np.vstack([pts, batch[world.is_free(batch)]])
        if len(pts) >= samples:
            break
    return pts
