"""Occupancy grids from numpy arrays and images (dark pixels are blocked)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from skyroute.errors import InputFormatError, OptionError
from skyroute.world.grid import (
    MAX_CELLS,
    NAN_HINT,
    Grid,
    check_file_cells,
    nan_cell,
    occupancy_values,
)

NPY_MAGIC = b"\x93NUMPY"


def from_array(array: np.ndarray, *, resolution: float = 1.0,
               origin: tuple[float, float] = (0.0, 0.0), name: str = "array") -> Grid:
    """A Grid from a 2-D array indexed [row, column]; non-zero / True means blocked. NaN,
    which says neither, is an OptionError naming its cell (``bool(nan)`` is True)."""
    a = occupancy_values(array, "array")
    if (cell := nan_cell(a)) is not None:
        raise OptionError(f"array has NaN at cell {cell} (x, y); {NAN_HINT}", param="array")
    return Grid(a != 0, resolution, origin, name=name)


def read_image(path: str | Path, *, resolution: float = 1.0, threshold: int = 128) -> Grid:
    """A Grid from an image: a pixel darker than ``threshold`` (0-255 grey) is blocked.

    Transparent pixels count as free. Row 0 is the top of the image. 16-bit grey images
    are scaled to 0-255 first (Pillow's RGBA conversion would clip them at 255, so
    nearly every pixel would read as bright); floating-point images are refused.
    """
    import warnings

    from PIL import Image, UnidentifiedImageError

    path = Path(path)
    try:
        with warnings.catch_warnings():  # Pillow's DecompressionBombWarning: refused below
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            img = Image.open(path)
    except Image.DecompressionBombError as exc:  # its header's size, over 2 x Pillow's limit
        raise InputFormatError(path, f"{exc} (a grid may have at most {MAX_CELLS:,} "
                               "cells, 8192 x 8192)") from None
    except (OSError, UnidentifiedImageError) as exc:
        raise InputFormatError(path, f"cannot read as an image: {exc}") from None
    try:
        with img:
            # the header's size, before a pixel is decoded: a small PNG can claim 10**10
            check_file_cells(path, *img.size, what="the image")
            if img.mode.startswith("I"):  # 16-bit grey ("I;16", or "I" holding it)
                return Grid(_sixteen_bit(path, np.asarray(img)) < threshold, resolution,
                            name=path.name)
            if img.mode == "F":
                raise InputFormatError(path, "a floating-point image: save it as 8- or "
                                       "16-bit grey, or as a .npy array")
            blocked = _dark(img, threshold)
    except (OSError, UnidentifiedImageError) as exc:
        raise InputFormatError(path, f"cannot read as an image: {exc}") from None
    return Grid(blocked, resolution, name=path.name)


def _dark(img, threshold: float, band: int = 256) -> np.ndarray:
    """Opaque pixels of a Pillow image whose grey (ITU-R 601 luma) is below
    ``threshold``, converted to RGBA a band of rows at a time: the whole image as RGBA
    and then float32 grey took 20 bytes a pixel (1.4 GB for an 8192 x 8192 PNG)."""
    weights = np.array([0.299, 0.587, 0.114], np.float32)
    width, height = img.size
    blocked = np.empty((height, width), dtype=bool)
    for r in range(0, height, band):
        part = np.asarray(img.crop((0, r, width, min(height, r + band))).convert("RGBA"))
        blocked[r:r + band] = ((part[..., :3].astype(np.float32) @ weights < threshold)
                               & (part[..., 3] >= 128))
    return blocked


def _sixteen_bit(path: Path, pixels: np.ndarray) -> np.ndarray:
    """16-bit grey pixels on the 0-255 scale (65535 -> 255)."""
    if pixels.ndim != 2 or pixels.min(initial=0) < 0 or pixels.max(initial=0) > 65535:
        raise InputFormatError(path, "an integer image beyond 16-bit grey: save it as 8- "
                               "or 16-bit grey, or as a .npy array")
    return pixels.astype(np.float32) / 257.0


def read_npy(path: str | Path, *, resolution: float = 1.0) -> Grid:
    """A Grid from a ``.npy`` file holding a 2-D array (non-zero = blocked; NaN, which
    says neither, is refused naming its cell)."""
    path = Path(path)
    try:
        with path.open("rb") as fh:
            if fh.read(6) != NPY_MAGIC:  # np.load would try it as a pickle or a .npz
                raise InputFormatError(path, "not a .npy file (numpy.save writes one; it "
                                       "starts with \\x93NUMPY)")
            fh.seek(0)
            _check_npy_shape(path, fh)
            fh.seek(0)
            arr = np.load(fh, allow_pickle=False)
    except InputFormatError:
        raise
    except (OSError, ValueError) as exc:
        raise InputFormatError(path, f"cannot read as a .npy array: {exc}") from None
    if arr.ndim != 2 or 0 in arr.shape:
        raise InputFormatError(path, f"expected a non-empty 2-D array, got shape {arr.shape}")
    if arr.dtype.kind not in "biuf":
        raise InputFormatError(path, f"expected an array of numbers or booleans, got dtype "
                               f"{arr.dtype}")
    if (cell := nan_cell(arr)) is not None:
        raise InputFormatError(path, f"NaN at cell {cell} (x, y); {NAN_HINT}")
    return from_array(arr, resolution=resolution, name=path.name)


def _check_npy_shape(path: Path, fh) -> None:
    """Refuse a .npy file whose header's shape is not 2-D or passes MAX_CELLS, before
    np.load allocates it: a 200-byte file claiming (10**6, 10**6) was numpy's
    MemoryError. (Format 3.0's header is laid out as 2.0's, UTF-8 in place of latin-1.)"""
    from numpy.lib import format as npy

    major, _ = npy.read_magic(fh)
    read = npy.read_array_header_1_0 if major == 1 else npy.read_array_header_2_0
    shape = read(fh)[0]
    if len(shape) != 2 or 0 in shape:
        raise InputFormatError(path, f"expected a non-empty 2-D array, got shape {shape}")
    check_file_cells(path, shape[1], shape[0], what="the array")
