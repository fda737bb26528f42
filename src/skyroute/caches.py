"""Module-level caches (search spaces, rasters, roadmaps, leg tables, reflected tables)
register how to clear themselves here; :func:`clear_caches` empties them all. Each cache
is keyed by everything that changes its value (most by the Grid or World itself, held
weakly, so it goes with the object)."""

from __future__ import annotations

from collections.abc import Callable

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
