"""Reading points from callers: any array-like of numbers becomes a float (N, 2) array,
and anything else a QueryError that names the argument."""

from __future__ import annotations

import numpy as np

from skyroute.errors import QueryError


def as_points(points, what: str, *, dims: int = 2) -> np.ndarray:
    """``points`` ((dims,) or (N, dims) numbers) as a float (N, dims) array.

    >>> as_points((1, 2), "start").tolist()
    [[1.0, 2.0]]
    >>> as_points([[1, 2, 0]], "goal")
    Traceback (most recent call last):
      ...
    skyroute.errors.QueryError: goal must be (a, b) numbers or an (N, 2) array, got shape (1, 3)
    """
    try:
        p = np.asarray(points, dtype=float)
    except (TypeError, ValueError):
        raise QueryError(f"{what} must be numbers, got {points!r}") from None
    if p.ndim == 1:
        p = p[None, :]
    if p.ndim != 2 or p.shape[1] != dims:
        names = "(a, b)" if dims == 2 else f"{dims}"
        raise QueryError(f"{what} must be {names} numbers or an (N, {dims}) array, "
                         f"got shape {np.shape(points)}")
    if not np.all(np.isfinite(p)):
        raise QueryError(f"{what} must be finite numbers, got {p.tolist()}")
    return p
