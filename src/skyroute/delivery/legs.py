"""Leg costs between the places of a site: the fewest step-drone moves from each place to
close to each other one (``plan_moves``), computed once and kept on disk.

The same few places recur every day (home, the shops, the customers' points), so a
table keyed by the zones, the area and the two places is filled on first use and read
back by every later day, process and run. The cache lives in ``$SKYROUTE_CACHE`` (or
``~/.cache/skyroute``) as one small JSON file per site geometry.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import shapely

from skyroute.caches import cache_dir, register
from skyroute.errors import SkyrouteError
from skyroute.files import write_atomic
from skyroute.motion.step_drone import MERGE, STEP, plan_moves
from skyroute.world.world import World

# bump when plan_moves' results may change (2: its default budget became every state of
# a bounded world; a pair past the old 200,000 expansions was kept as -1, no flight)
VERSION = 2


def _world_key(world: World) -> str:
    h = hashlib.sha256()
    for z in world.obstacles:
        h.update(shapely.to_wkb(z))
    if world.boundary is not None:
        h.update(shapely.to_wkb(shapely.Polygon(world.boundary)))
    h.update(f"{STEP!r} {MERGE!r} {VERSION}".encode())
    return h.hexdigest()[:20]


_MEMO: dict[Path, dict] = {}
register(_MEMO.clear)


def _known(path: Path) -> dict:
    """The cached legs, read from disk once per process (and again when it has grown)."""
    try:
        stamp = path.stat().st_mtime_ns
    except OSError:
        return _MEMO.setdefault(path, {})
    memo = _MEMO.get(path)
    if memo is None or memo.get("\0stamp") != stamp:
        try:
            memo = json.loads(path.read_text())
        except (OSError, json.JSONDecodeError):
            memo = {}
        memo["\0stamp"] = stamp
        _MEMO[path] = memo
    return memo


def _pair(a, b) -> str:
    return f"{a[0]!r},{a[1]!r}>{b[0]!r},{b[1]!r}"


def leg_table(world: World, points, *, on_leg=None) -> np.ndarray:
    """(P, P) fewest moves from ``points[i]`` exactly to close to ``points[j]``; -1 where
    no flight exists. ``on_leg`` is called after each leg computed (not cached)."""
    pts = [tuple(map(float, p)) for p in np.asarray(points, dtype=float).reshape(-1, 2)]
    path = cache_dir() / f"legs-{_world_key(world)}.json"
    known = _known(path)
    out = np.zeros((len(pts), len(pts)), dtype=np.int64)
    fresh = 0
    for i, a in enumerate(pts):
        for j, b in enumerate(pts):
            if i == j:
                continue
            k = _pair(a, b)
            if k not in known:
                f = plan_moves(world, a, b)
                known[k] = f.moves if f.status.value == "found" else -1
                fresh += 1
                if on_leg:
                    on_leg()
            out[i, j] = known[k]
    if fresh:
        try:
            write_atomic(path, json.dumps({k: v for k, v in known.items()
                                           if not k.startswith("\0")}, indent=0))
            known["\0stamp"] = path.stat().st_mtime_ns
        except (SkyrouteError, OSError):
            pass  # a read-only home: the table is still right, only not kept
    return out


def missing_legs(world: World, points) -> int:
    """How many legs among ``points`` the cache does not hold yet (for a progress bar)."""
    pts = [tuple(map(float, p)) for p in np.asarray(points, dtype=float).reshape(-1, 2)]
    known = _known(cache_dir() / f"legs-{_world_key(world)}.json")
    return sum(1 for a in pts for b in pts if a != b and _pair(a, b) not in known)
