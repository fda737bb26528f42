"""The prepared index's file: an ``.npz`` of the index arrays with a format version, the
map's shape and a hash of its blocked cells. Before any array reaches a compiled query
(which does not check its indices) :func:`read_index` checks the metadata, every
array's dtype and dimensions, the sizes that tie them together and the range of every
index they hold; ``load_index`` then checks what the map determines against it (region
labels: -1 exactly on blocked cells, one label across every free edge; clearances:
recomputed). Distances and predecessor chains are trusted as written:
load only indexes that skyroute wrote (as with a pickle, a file crafted to pass these
checks could still give wrong answers or worse)."""

from __future__ import annotations

import hashlib
import zipfile
from pathlib import Path

import numpy as np

from skyroute.errors import InputFormatError
from skyroute.files import open_atomic

FORMAT_VERSION = 3
CH_ARRAYS = ("ch_offs", "ch_nbr", "ch_len", "ch_mid", "ch_core", "ch_dist", "ch_pred")
INDEX_ARRAYS = {"subgoal": ("cells", "clr", "offs", "nbr", "label", "lmd", "dist", "pred",
                            *CH_ARRAYS),
                "jump": ("label", "piv")}
# each array's dtype and number of dimensions as prepare() makes them
ARRAY_TYPES = {"cells": ("i4", 1), "clr": ("i4", 2), "offs": ("i8", 1), "nbr": ("i4", 1),
               "label": ("i4", 1), "lmd": ("f4", 2), "dist": ("f8", 2), "pred": ("i2", 2),
               "ch_offs": ("i8", 1), "ch_nbr": ("i4", 1), "ch_len": ("f8", 1),
               "ch_mid": ("i4", 1), "ch_core": ("i4", 1), "ch_dist": ("f8", 2),
               "ch_pred": ("i2", 2), "piv": ("f8", 2)}


def grid_digest(blocked: np.ndarray) -> str:
    """sha256 of a blocked array's shape and packed bits: names the map an index is for."""
    h = hashlib.sha256(f"{blocked.shape[0]}x{blocked.shape[1]}:".encode())
    h.update(np.packbits(np.ascontiguousarray(blocked, dtype=bool)).tobytes())
    return h.hexdigest()


def write_index(path: Path, method: str, blocked: np.ndarray, arrays: dict) -> None:
    """Write ``method``'s arrays for the (H, W) ``blocked`` map to ``path``, whole or not
    at all."""
    meta = {"version": np.int64(FORMAT_VERSION), "method": np.array(method),
            "shape": np.array(blocked.shape, np.int64),
            "digest": np.array(grid_digest(blocked))}
    with open_atomic(path) as f:  # a bad folder is one line, never half a file
        np.savez(f, **meta, **{k: arrays[k] for k in INDEX_ARRAYS[method]})


def read_index(path: Path, blocked: np.ndarray, name: str) -> tuple[str, dict]:
    """(method, arrays) of the index at ``path`` for the (H, W) ``blocked`` map called
    ``name``; an unreadable, outdated, malformed or foreign file is an InputFormatError
    naming it."""
    not_index = "not a skyroute index (an .npz file written by 'skyroute prepare')"
    try:
        z, data = np.load(path, allow_pickle=False), None
        if isinstance(z, np.lib.npyio.NpzFile):  # not a plain .npy array
            with z:
                data = {k: z[k] for k in z.files}
    except FileNotFoundError:
        raise InputFormatError(path, "no such index file") from None
    except IsADirectoryError:
        raise InputFormatError(path, "a folder, not an index file") from None
    except (OSError, ValueError, EOFError, zipfile.BadZipFile):  # truncated, not a zip
        raise InputFormatError(path, not_index) from None
    if data is None:
        raise InputFormatError(path, not_index)
    if "method" not in data:  # another program's .npz: say what it holds instead
        held = ", ".join(sorted(data)[:5]) + (", ..." if len(data) > 5 else "")
        raise InputFormatError(path, "not a skyroute index: it has no 'method' entry "
                               f"(its arrays: {held or 'none'})")
    method = _scalar(path, data, "method", str)
    if method not in INDEX_ARRAYS:
        raise InputFormatError(path, f"not a skyroute index: method {method!r}")
    missing = [k for k in ("version", "shape", "digest", *INDEX_ARRAYS[method])
               if k not in data]
    if missing:
        raise InputFormatError(path, f"not a skyroute index: missing {', '.join(missing)}")
    version = _scalar(path, data, "version", int)
    if version != FORMAT_VERSION:
        raise InputFormatError(path, f"index format {version}, this skyroute reads "
                               f"{FORMAT_VERSION}; rebuild it with 'skyroute prepare'")
    shape = data["shape"]
    if shape.shape != (2,) or shape.dtype.kind not in "iu":
        raise InputFormatError(path, "not a skyroute index: 'shape' is not two integers")
    h, w = (int(v) for v in shape)
    if (h, w) != blocked.shape:
        raise InputFormatError(path, f"index is for a {w}x{h} map, {name} is "
                               f"{blocked.shape[1]}x{blocked.shape[0]} (another map, or "
                               "another --safety or --resolution); rebuild it with "
                               "'skyroute prepare'")
    if _scalar(path, data, "digest", str) != grid_digest(blocked):
        raise InputFormatError(path, f"index does not match {name}'s blocked cells "
                               "(stale, another map, or another --safety or --resolution); "
                               "rebuild it with 'skyroute prepare'")
    arrays = {k: data[k] for k in INDEX_ARRAYS[method]}
    problem = _malformed(arrays, (h + 2) * (w + 2))
    if problem:
        raise InputFormatError(path, f"not a skyroute index: {problem}; rebuild it with "
                               "'skyroute prepare'")
    return method, arrays


def _scalar(path: Path, data: dict, key: str, kind: type):
    """``data[key]`` as one ``kind`` (int or str); an InputFormatError otherwise."""
    value = data[key]
    if value.shape != () or value.dtype.kind not in ("iu" if kind is int else "U"):
        what = "integer" if kind is int else "string"
        raise InputFormatError(path, f"not a skyroute index: '{key}' is not one {what}")
    return kind(value)


def _malformed(arrays: dict, padded: int) -> str:
    """What is wrong with an index's arrays for a map of ``padded`` cells ("" if nothing):
    each array's dtype and dimensions, and the sizes that tie them together."""
    for k, a in arrays.items():
        dtype, ndim = ARRAY_TYPES[k]
        if a.dtype != np.dtype(dtype) or a.ndim != ndim:
            return f"'{k}' is a {a.ndim}-D {a.dtype} array, not {ndim}-D {np.dtype(dtype)}"
    if arrays["label"].shape != (padded,):
        return "'label' does not cover the map"
    if "piv" in arrays:
        return "" if arrays["piv"].shape[0] == padded else "'piv' does not cover the map"
    m = arrays["cells"].size
    offs, ch_offs, ch = arrays["offs"], arrays["ch_offs"], arrays["ch_dist"]
    sizes_ok = (arrays["clr"].shape == (padded, 8) and offs.size == m + 1
                and arrays["lmd"].shape[0] == m
                and arrays["dist"].shape in ((m, m), (0, 0))
                and arrays["pred"].shape == arrays["dist"].shape
                and ch_offs.size in (0, m + 1)  # a hierarchy has every per-node array
                and arrays["ch_core"].size == (m if ch_offs.size else 0)
                and arrays["ch_nbr"].size == arrays["ch_len"].size
                == arrays["ch_mid"].size
                and ch.shape[0] == ch.shape[1] and arrays["ch_pred"].shape == ch.shape)
    if not sizes_ok:
        return "its arrays' sizes do not fit together"
    k = ch.shape[0]
    in_range = (_within(arrays["cells"], 0, padded) and _within(arrays["nbr"], 0, m)
                and _within(arrays["pred"], -1, m) and _within(arrays["ch_nbr"], 0, m)
                and _within(arrays["ch_mid"], -1, m) and _within(arrays["ch_core"], -1, k)
                and _within(arrays["ch_pred"], -1, k)
                and _offsets(offs, arrays["nbr"].size)
                and (not ch_offs.size or _offsets(ch_offs, arrays["ch_nbr"].size)))
    return "" if in_range else "its graph's indices are out of range"


def _within(a: np.ndarray, lo: int, hi: int) -> bool:
    """Every value of ``a`` in [lo, hi)."""
    return not a.size or (int(a.min()) >= lo and int(a.max()) < hi)


def _offsets(offs: np.ndarray, total: int) -> bool:
    """CSR offsets: from 0, never falling, ending at ``total``."""
    return offs[0] == 0 and offs[-1] == total and bool(np.all(np.diff(offs) >= 0))
