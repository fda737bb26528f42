"""Shared test fixtures: where the outside reference data lives."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "data"
MOVINGAI = SHARED / "movingai"


def movingai_pairs() -> list[tuple[Path, Path]]:
    """The 18 (map, scen) pairs of ../shared/data/movingai (see its SOURCES.md)."""
    if not MOVINGAI.is_dir():
        if os.environ.get("CI"):
            raise RuntimeError(f"CI needs the reference data at {MOVINGAI}")
        return []
    from skyroute.bench.grid import find_pairs

    return find_pairs(MOVINGAI)


needs_shared = pytest.mark.skipif(not MOVINGAI.is_dir() and not os.environ.get("CI"),
                                  reason=f"reference data not found at {MOVINGAI}")


@pytest.fixture(scope="session", autouse=True)
def leg_cache(tmp_path_factory):
    """Delivery leg tables go to one temporary cache for the whole run, not ~/.cache."""
    path = tmp_path_factory.mktemp("skyroute-cache")
    old = os.environ.get("SKYROUTE_CACHE")
    os.environ["SKYROUTE_CACHE"] = str(path)
    yield path
    if old is None:
        os.environ.pop("SKYROUTE_CACHE", None)
    else:
        os.environ["SKYROUTE_CACHE"] = old
