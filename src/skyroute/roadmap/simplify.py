"""Exact path simplification on a World's plane: greedy line-of-sight shortcuts and
random sub-segment shortcuts (as OMPL's path simplifier). Every new segment is checked
with :meth:`World.segments_free`, so a simplified path stays free and is never longer."""

from __future__ import annotations

import numpy as np

from skyroute.world.world import World


def shortcut(world: World, pts: np.ndarray) -> tuple[np.ndarray, int]:
    """Greedy exact line-of-sight shortcutting: from each kept point jump to the farthest
    later point it sees. Returns (points, segment tests)."""
    keep = [0]
    i = 0
    tests = 0
    while i < len(pts) - 1:
        later = np.arange(len(pts) - 1, i, -1)
        free = world.segments_free(np.broadcast_to(pts[i], (len(later), 2)), pts[later])
        tests += len(later)
        i = int(later[np.argmax(free)]) if free.any() else i + 1
        keep.append(i)
    return pts[keep], tests


def smooth(world: World, pts: np.ndarray, rng: np.random.Generator,
           tries: int = 300) -> tuple[np.ndarray, int]:
    """Random sub-segment shortcuts (as OMPL's path simplifier does): pick two points along
    the path by arc length; when the segment between them is free, splice it in. Never
    longer (triangle inequality), every new segment checked. Returns (points, tests)."""
    tests = 0
    for _ in range(tries):
        if len(pts) < 3:
            break
        seg = np.hypot(*np.diff(pts, axis=0).T)
        cum = np.concatenate([[0.0], np.cumsum(seg)])
        a, b = np.sort(rng.uniform(0, cum[-1], size=2))
        i, j = np.searchsorted(cum, [a, b], side="right") - 1
        if i == j:
            continue
        pa = pts[i] + (pts[i + 1] - pts[i]) * ((a - cum[i]) / seg[i])
        pb = pts[j] + (pts[j + 1] - pts[j]) * ((b - cum[j]) / seg[j])
        tests += 1
        if world.segment_free(pa, pb):
            pts = np.vstack([pts[: i + 1], pa, pb, pts[j + 1:]])
    keep = np.r_[True, np.any(np.diff(pts, axis=0) != 0, axis=1)]
    return pts[keep], tests
