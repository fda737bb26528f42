"""Reading points from callers: any array-like of numbers becomes a float (N, 2) array,
and anything else a QueryError that names the argument; places on Earth and points of a
local plane are checked against the ranges where the conversions hold."""

from __future__ import annotations

import numpy as np

from skyroute.errors import QueryError

# A local plane (metres around a home) reaches at most this far in either axis: a
# quarter of the way round the Earth, far beyond where a tangent plane means anything,
# and small enough that buffering, rasterising and lon/lat conversions stay finite.
MAX_METRES = 1e7
# A lon/lat world reaches at most this far (metres, straight through the Earth) from its
# home: its GeoJSON zones and boundary box, a --boundary box, and a start or goal when it
# has no boundary. A (lat, lon) written for (lon, lat) lands thousands of km away; and the
# tangent plane at home is off by 0.1 % at 500 km, 0.4 % at 1,000.
MAX_REACH = 1_000_000
# A place on Earth: (lon, lat) degrees within these, either side of 0.
MAX_LON = 180.0
MAX_LAT = 90.0


def _floats(points, what: str) -> np.ndarray:
    """``points`` as a float array, or a QueryError naming ``what``."""
    try:
        return np.asarray(points, dtype=float)
    except (TypeError, ValueError):
        raise QueryError(f"{what} must be numbers, got {points!r}", param=what) from None


def as_points(points, what: str, *, dims: int = 2) -> np.ndarray:
    """``points`` ((dims,) or (N, dims) numbers) as a float (N, dims) array.

    >>> as_points((1, 2), "start").tolist()
    [[1.0, 2.0]]
    >>> as_points([[1, 2, 0]], "goal")
    Traceback (most recent call last):
      ...
    skyroute.errors.QueryError: goal must be (a, b) numbers or an (N, 2) array, got shape (1, 3)
    """
    p = _floats(points, what)
    if p.ndim == 1:
        p = p[None, :]
    if p.ndim != 2 or p.shape[1] != dims:
        names = "(a, b)" if dims == 2 else f"{dims}"
        raise QueryError(f"{what} must be {names} numbers or an (N, {dims}) array, "
                         f"got shape {np.shape(points)}", param=what)
    if not np.all(np.isfinite(p)):
        raise QueryError(f"{what} must be finite numbers, got {p.tolist()}", param=what)
    return p


def plane_points(points, what: str = "points") -> np.ndarray:
    """``points`` ((2,) or (N, 2) numbers, or none) as a float (N, 2) array for a
    vectorised query, else a QueryError naming ``what`` (an (N, 3) array was read as
    3N/2 points). Not checked for finiteness: a query of NaN is simply not free.

    >>> plane_points([[1, 2, 3], [4, 5, 6]], "points")
    Traceback (most recent call last):
      ...
    skyroute.errors.QueryError: points must be (a, b) numbers or an (N, 2) array, got shape (2, 3)
    """
    p = _floats(points, what)
    if p.ndim == 2 and p.shape[1] == 2:
        return p
    if p.shape == (2,):
        return p[None, :]
    if p.size == 0:
        return p.reshape(0, 2)
    raise QueryError(f"{what} must be (a, b) numbers or an (N, 2) array, got shape {p.shape}",
                     param=what)


def check_places(p: np.ndarray, what: str) -> np.ndarray:
    """``p`` when every row is a (lon, lat) on Earth, else a QueryError naming ``what``."""
    bad = (np.abs(p[:, 0]) > MAX_LON) | (np.abs(p[:, 1]) > MAX_LAT)
    if bad.any():
        q = p[np.argmax(bad)]
        raise QueryError(f"{what} ({q[0]:.7g}, {q[1]:.7g}) is not a place: expected "
                         f"(lon, lat) degrees, lon in [-{MAX_LON:g}, {MAX_LON:g}], lat in "
                         f"[-{MAX_LAT:g}, {MAX_LAT:g}]", param=what)
    return p


def check_metres(p: np.ndarray, what: str) -> np.ndarray:
    """``p`` when every coordinate of a local plane lies within :data:`MAX_METRES` of
    home, else a QueryError naming ``what``."""
    bad = np.abs(p).max(axis=1) > MAX_METRES if len(p) else np.zeros(0, bool)
    if bad.any():
        q = p[np.argmax(bad)]
        raise QueryError(f"{what} ({q[0]:.7g}, {q[1]:.7g}) lies more than {MAX_METRES:.0e} m "
                         "from home: not a point of this world's local plane", param=what)
    return p
