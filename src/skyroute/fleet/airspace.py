"""Cruise levels and the 4D reservations that keep released flights apart.

Levels
    ``layers`` (the seed): drone ``i`` cruises at ``base_altitude + i * layer_step``, its
    own slice. ``shared``: ``shared_levels`` levels from ``base_altitude``, one preferred
    per sector of the flight's bearing (the semicircular rule, widened to as many sectors
    as levels), the others tried after it, lowest first (:func:`level_choices`).

Reservations
    Before a flight is released its whole airborne trajectory (climb, cruise, loiters,
    approach) must clear every flight already reserved: :class:`Reservations`. This test
    is deliberately *not* the separation checker's exact geometry (the checker must stay
    an independent witness): it samples both trajectories on one global clock every
    ``dt`` seconds (each flight clamped to its airborne interval) and, per sample, needs
    the horizontal distance to be at least ``sep_horizontal + (u_a + u_b) dt / 2`` **or**
    the vertical distance at least ``sep_vertical + (w_a + w_b) dt / 2``, where ``u`` and
    ``w`` bound each drone's horizontal and vertical speed within half a step of the
    sample. Every instant lies within ``dt / 2`` of a sample, and neither distance can
    shrink faster than those speeds, so a pair that passes at every sample keeps
    separation at every instant in between: the test is sound, at the price of a
    buffer (with ``dt = 1`` s and 50 m/s drones, 100 m horizontally at a sample).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from skyroute.fleet.scenario import Airspace
from skyroute.fleet.trajectory import ARC, Pieces

MODES = ("layers", "shared")
_N, _E, _ALT, _U, _W = range(5)  # sample columns: position, speed bounds


def layer_altitude(airspace: Airspace, drone: int) -> float:
    """The seed's own slice for ``drone`` (0-based): ``base + drone * step``."""
    return airspace.base_altitude + drone * airspace.layer_step


def level_choices(airspace: Airspace, bearing_deg: float) -> list[float]:
    """Shared-mode cruise altitudes to try for a flight on compass ``bearing_deg``: the
    level of its sector first, then the others, lowest first."""
    n = airspace.shared_levels
    sector = int((bearing_deg % 360.0) // (360.0 / n)) % n
    order = [sector] + [k for k in range(n) if k != sector]
    return [airspace.base_altitude + k * airspace.layer_step for k in order]


def samples(pieces: Pieces, dt: float) -> tuple[int, np.ndarray]:
    """``(k0, S)``: one drone's airborne trajectory sampled at times ``k * dt`` for
    ``k = k0 .. k0 + len(S) - 1``, covering every instant of it within ``dt / 2``;
    ``S`` columns north, east, alt (clamped to the airborne interval) and the largest
    horizontal and vertical speed within half a step of the sample."""
    order = np.argsort(pieces.t0, kind="stable")
    t0, t1 = pieces.t0[order], pieces.t1[order]
    start, end = float(t0[0]), float(t1[-1])
    k0 = math.floor(start / dt + 0.5)
    k1 = math.floor(end / dt + 0.5)
    ks = np.arange(k0, k1 + 1)
    t = np.clip(ks * dt, start, end)
    row = order[np.clip(np.searchsorted(t0, t, side="right") - 1, 0, len(order) - 1)]
    S = np.empty((len(ks), 5))
    S[:, :3] = pieces.at(row, t)
    S[:, _U:] = 0.0
    arc = pieces.kind[order] == ARC
    u = np.where(arc, pieces.radius[order] * np.abs(pieces.rate[order]),
                 np.hypot(pieces.v_north[order], pieces.v_east[order]))
    w = np.abs(pieces.v_alt[order])
    half = dt / 2
    for a, b, ui, wi in zip(t0, t1, u, w, strict=True):
        lo = max(math.ceil((a - half) / dt) - k0, 0)
        hi = min(math.floor((b + half) / dt) - k0, len(ks) - 1)
        if hi >= lo:
            np.maximum(S[lo:hi + 1, _U], ui, out=S[lo:hi + 1, _U])
            np.maximum(S[lo:hi + 1, _W], wi, out=S[lo:hi + 1, _W])
    return k0, S


class Reservations:
    """The sampled airborne trajectories of released flights (see the module docstring).

    ``clear(drone, k0, S)`` is True when a flight sampled as ``(k0, S)`` keeps separation
    from every reserved flight of the other drones; ``add`` reserves it; ``forget(t)``
    drops flights that ended before ``t``.
    """

    def __init__(self, *, sep_horizontal: float, sep_vertical: float, dt: float = 1.0,
                 speed_bound: float, climb_bound: float) -> None:
        self.sh, self.sv, self.dt = float(sep_horizontal), float(sep_vertical), float(dt)
        # the widest a bounding box must grow to meet any sample test
        self._pad_h = self.sh + speed_bound * self.dt + 1e-6
        self._pad_v = self.sv + climb_bound * self.dt
        self._buf = np.empty((4096, 5))
        self._used = 0
        self._meta = np.empty((64, 4), dtype=np.int64)  # k0, k1, offset, drone
        self._box = np.empty((64, 6))  # n, e, alt minima then maxima
        self._n = 0

    def __len__(self) -> int:
        return self._n

    def clear(self, drone: int, k0: int, S: np.ndarray) -> bool:
        """True when the flight ``(k0, S)`` of ``drone`` clashes with no reservation."""
        n = self._n
        if n == 0:
            return True
        meta, box = self._meta[:n], self._box[:n]
        k1 = k0 + len(S) - 1
        lo, hi = S[:, :3].min(axis=0), S[:, :3].max(axis=0)
        near = ((meta[:, 0] <= k1) & (meta[:, 1] >= k0) & (meta[:, 3] != drone)
                & (box[:, 0] <= hi[0] + self._pad_h) & (box[:, 3] >= lo[0] - self._pad_h)
                & (box[:, 1] <= hi[1] + self._pad_h) & (box[:, 4] >= lo[1] - self._pad_h)
                & (box[:, 2] <= hi[2] + self._pad_v) & (box[:, 5] >= lo[2] - self._pad_v))
        idx = np.flatnonzero(near)
        if len(idx) == 0:
            return True
        return not _clash(S, k0, meta, idx, self._buf, self.sh, self.sv, self.dt)

    def add(self, drone: int, k0: int, S: np.ndarray) -> None:
        """Reserve the flight ``(k0, S)`` of ``drone``."""
        m = len(S)
        while self._used + m > len(self._buf):
            self._buf = np.concatenate([self._buf, np.empty_like(self._buf)])
        if self._n == len(self._meta):
            self._meta = np.concatenate([self._meta, np.empty_like(self._meta)])
            self._box = np.concatenate([self._box, np.empty_like(self._box)])
        self._buf[self._used:self._used + m] = S
        self._meta[self._n] = (k0, k0 + m - 1, self._used, drone)
        self._box[self._n, :3] = S[:, :3].min(axis=0)
        self._box[self._n, 3:] = S[:, :3].max(axis=0)
        self._used += m
        self._n += 1

    def forget(self, before: float) -> None:
        """Drop the flights whose last sample is before time ``before`` (compacting)."""
        n = self._n
        keep = np.flatnonzero(self._meta[:n, 1] * self.dt < before)
        if len(keep) == 0:
            return
        keep = np.flatnonzero(self._meta[:n, 1] * self.dt >= before)
        meta = self._meta[keep].copy()
        parts = [self._buf[o:o + k1 - k0 + 1] for k0, k1, o, _ in meta]
        buf = np.concatenate(parts) if parts else np.empty((0, 5))
        meta[:, 2] = np.concatenate([[0], np.cumsum([len(p) for p in parts])[:-1]]) \
            if parts else meta[:, 2]
        self._buf = np.empty((max(4096, 2 * len(buf)), 5))
        self._buf[:len(buf)] = buf
        self._used = len(buf)
        self._box[:len(keep)] = self._box[keep]
        self._meta[:len(keep)] = meta
        self._n = len(keep)


@numba.njit(cache=True)
def _clash(S, k0, meta, idx, buf, sh, sv, dt):
    """True when some sample of ``S`` (from clock step ``k0``) fails the test against a
    sample of one of the reserved flights ``idx`` at the same step."""
    half = 0.5 * dt
    m = S.shape[0]
    for f in idx:
        fk0 = meta[f, 0]
        off = meta[f, 2]
        a = max(k0, fk0)
        b = min(k0 + m - 1, meta[f, 1])
        for k in range(a, b + 1):
            i = k - k0
            j = off + k - fk0
            dv = abs(S[i, 2] - buf[j, 2])
            if dv >= sv + (S[i, 4] + buf[j, 4]) * half:
                continue
            dn = S[i, 0] - buf[j, 0]
            de = S[i, 1] - buf[j, 1]
            need = sh + (S[i, 3] + buf[j, 3]) * half + 1e-6
            if dn * dn + de * de >= need * need:
                continue
            return True
    return False
