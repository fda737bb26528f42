"""A visibility graph kept on disk, one ``.npz`` file per world geometry, so that a city's
graph is built once and read back by every later process.

The key hashes everything the graph depends on: every obstacle's exact coordinates (so
the altitude and the safety margin, which change them, are in it), the boundary, the
obstacles' names (errors name the merged obstacles) and :data:`VERSION`. The file
repeats its key and version; a file that does not match, or cannot be read, is ignored
(and the caller rebuilds and overwrites it). Files are written whole or not at all
(:func:`skyroute.files.write_atomic`) and hold plain arrays only (no pickle).
"""

from __future__ import annotations

import hashlib
import io
import zipfile
from pathlib import Path

import numpy as np
import shapely

from skyroute.caches import cache_dir
from skyroute.errors import SkyrouteError
from skyroute.files import write_atomic
from skyroute.world.world import World

VERSION = 2  # bump when the build's results may change (2: boundary corners)
ARRAYS = ("corners", "prev", "next", "indptr", "indices", "weights", "labels", "names")


def graph_key(world: World) -> str:
    """A hex digest of the world's geometry and names (see the module's docstring)."""
    h = hashlib.sha256(f"visibility {VERSION}\0".encode())
    if len(world.obstacles):
        h.update(b"".join(shapely.to_wkb(world.obstacles, byte_order=1)))
    if world.boundary is not None:
        h.update(b"\0boundary" + shapely.to_wkb(shapely.Polygon(world.boundary), byte_order=1))
    h.update("\0".join(world.names).encode())
    return h.hexdigest()[:24]


def graph_path(key: str) -> Path:
    return cache_dir() / f"visibility-{key}.npz"


def save_graph(key: str, polygons: np.ndarray, arrays: dict[str, np.ndarray]) -> bool:
    """Write the merged ``polygons`` (WKB) and the graph's ``arrays``; False when the
    cache folder cannot be written (the graph is still right, only not kept)."""
    wkb = shapely.to_wkb(polygons, byte_order=1)
    sizes = np.array([len(b) for b in wkb], dtype=np.int64)
    buf = io.BytesIO()
    np.savez(buf, key=np.array(key), version=np.array(VERSION),
             wkb=np.frombuffer(b"".join(wkb), dtype=np.uint8), wkb_sizes=sizes,
             **{k: arrays[k] for k in ARRAYS})
    try:
        write_atomic(graph_path(key), buf.getvalue())
    except (SkyrouteError, OSError):
        return False
    return True


def load_graph(key: str) -> tuple[np.ndarray, dict[str, np.ndarray]] | None:
    """(merged polygons, arrays) from the cache file for ``key``; None when there is no
    such file or it is stale (another key or version) or damaged."""
    path = graph_path(key)
    try:
        with np.load(path, allow_pickle=False) as f:
            if str(f["key"]) != key or int(f["version"]) != VERSION:
                return None
            arrays = {k: f[k] for k in ARRAYS}
            raw, sizes = f["wkb"].tobytes(), f["wkb_sizes"]
    except (OSError, KeyError, ValueError, EOFError, zipfile.BadZipFile):
        return None
    ends = np.cumsum(sizes)
    if len(ends) and ends[-1] != len(raw):
        return None
    try:
        polygons = shapely.from_wkb([raw[e - s:e] for s, e in zip(sizes, ends, strict=True)])
    except shapely.errors.GEOSException:
        return None
    return np.asarray(polygons, dtype=object), arrays
