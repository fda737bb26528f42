"""Synthetic cities in the colliders.csv format, for examples and tests that must not
depend on course data: square blocks of random box buildings between straight streets.

Street centrelines lie on multiples of ``block + street`` metres north and east of home,
so home (0, 0) is always a street crossing.
"""

from __future__ import annotations

import numpy as np

from skyroute.errors import OptionError
from skyroute.geo import Home

DEFAULT_HOME = Home(-3.186874, 55.944494)  # Appleton Tower, Edinburgh
# blocks along a side: 100 x 100 blocks are about 35,000 buildings over 6 km (the FCND
# city has 3,845); 10**9 built text until memory ran out
MAX_BLOCKS = 100


def synth_city(rng: np.random.Generator, *, blocks: int = 6, block: float = 40.0,
               street: float = 20.0, home: Home = DEFAULT_HOME) -> str:
    """Text of a colliders.csv city of ``blocks`` x ``blocks`` blocks around home
    (``blocks`` 1 to :data:`MAX_BLOCKS`)."""
    if isinstance(blocks, bool) or not isinstance(blocks, int | np.integer) \
            or not 1 <= blocks <= MAX_BLOCKS:
        raise OptionError(f"blocks={blocks!r} must be a whole number from 1 to {MAX_BLOCKS}",
                          param="blocks")
    pitch = block + street
    lines = [f"lat0 {home.lat:.6f}, lon0 {home.lon:.6f}",
             "posX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ"]
    half = blocks // 2
    for i in range(-half, blocks - half):
        for j in range(-half, blocks - half):
            # block spans [c + street/2, c + pitch - street/2] on both axes
            n0, e0 = i * pitch + street / 2, j * pitch + street / 2
            for _ in range(int(rng.integers(2, 6))):
                hn, he = rng.uniform(4, block / 4, size=2)
                cn = rng.uniform(n0 + hn, n0 + block - hn)
                ce = rng.uniform(e0 + he, e0 + block - he)
                hu = rng.uniform(5, 60)
                lines.append(f"{cn:.4f},{ce:.4f},{hu:.4f},{hn:.4f},{he:.4f},{hu:.4f}")
    return "\n".join(lines) + "\n"
