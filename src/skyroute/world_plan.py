"""Deprecated: :mod:`skyroute.roadmap.world_plan`, :mod:`skyroute.roadmap.raster` and
:mod:`skyroute.roadmap.simplify` hold what was here (kept for one release)."""

import warnings

from skyroute.roadmap.raster import default_resolution  # noqa: F401
from skyroute.roadmap.simplify import shortcut, smooth  # noqa: F401
from skyroute.roadmap.world_plan import (  # noqa: F401
    WORLD_ALGORITHMS,
    plan_world,
    roadmap_edges,
)

warnings.warn("skyroute.world_plan is deprecated; use skyroute.roadmap.world_plan",
              DeprecationWarning, stacklevel=2)
