"""Module-level caches (search spaces, rasters, roadmaps, leg tables, reflected tables)
register how to clear themselves here; :func:`clear_caches` empties them all. Each cache
is keyed by everything that changes its value (most by the Grid or World itself, held
weakly or by id with a finalizer, so it goes with the object). Caches kept on disk
(delivery leg tables, city visibility graphs) live in :func:`cache_dir`."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

_CLEARERS: list[Callable[[], None]] = []


def register(clear: Callable[[], None]) -> Callable[[], None]:
    """Remember ``clear`` (a cache's ``clear`` method) for :func:`clear_caches`."""
    _CLEARERS.append(clear)
    return clear


def clear_caches() -> None:
    """Empty every cache skyroute keeps between calls (memory is freed, later calls
    rebuild what they need)."""
    for clear in _CLEARERS:
        clear()


def cache_dir() -> Path:
    """Where on-disk caches live: ``$SKYROUTE_CACHE``, else ``~/.cache/skyroute``."""
    return Path(os.environ.get("SKYROUTE_CACHE", Path.home() / ".cache" / "skyroute"))
