"""Occupancy grids from numpy arrays and images (dark pixels are blocked)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from skyroute.errors import InputFormatError
from skyroute.world.grid import Grid


def from_array(array: np.ndarray, *, resolution: float = 1.0,
               origin: tuple[float, float] = (0.0, 0.0), name: str = "array") -> Grid:
    """A Grid from a 2-D array indexed [row, column]; non-zero / True means blocked."""
    a = np.asarray(array)
    return Grid(a != 0, resolution, origin, name=name)


def read_image(path: str | Path, *, resolution: float = 1.0, threshold: int = 128) -> Grid:
    """A Grid from an image: a pixel darker than ``threshold`` (0-255 grey) is blocked.

    Transparent pixels count as free. Row 0 is the top of the image.
    """
    from PIL import Image, UnidentifiedImageError

    path = Path(path)
    try:
        with Image.open(path) as img:
            rgba = np.asarray(img.convert("RGBA"))
    except (OSError, UnidentifiedImageError) as exc:
        raise InputFormatError(path, f"cannot read as an image: {exc}") from None
    grey = rgba[..., :3].astype(np.float32) @ np.array([0.299, 0.587, 0.114], np.float32)
    blocked = (grey < threshold) & (rgba[..., 3] >= 128)
    return Grid(blocked, resolution, name=path.name)


def read_npy(path: str | Path, *, resolution: float = 1.0) -> Grid:
    """A Grid from a ``.npy`` file holding a 2-D array (non-zero = blocked)."""
    path = Path(path)
    try:
        arr = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise InputFormatError(path, f"cannot read as a .npy array: {exc}") from None
    if arr.ndim != 2 or 0 in arr.shape:
        raise InputFormatError(path, f"expected a non-empty 2-D array, got shape {arr.shape}")
    return from_array(arr, resolution=resolution, name=path.name)
