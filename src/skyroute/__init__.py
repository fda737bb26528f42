"""skyroute: plan where drones and small robots fly or drive.

The public API is small: :func:`load_map` reads a map into a :class:`Grid`, :func:`plan`
searches it and returns a :class:`PlanResult`.

The names are imported on first use (:mod:`skyroute.lazy`): every ``skyroute ...``
command imports this package first, and a grid plan must not pay for shapely, scipy or
pyproj.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from skyroute.blas_probe import defer
from skyroute.lazy import exports
from skyroute.version import __version__ as __version__  # re-exported

defer()  # numba's first kernel load need not import scipy.linalg

if TYPE_CHECKING:  # the real imports, for readers and type checkers
    from skyroute.caches import clear_caches
    from skyroute.errors import InputFormatError, OptionError, QueryError, SkyrouteError
    from skyroute.planner import plan
    from skyroute.result import PlanResult, Status
    from skyroute.search.prepared import PreparedGrid, load_index, prepare
    from skyroute.world.grid import Grid
    from skyroute.world.load import bundled_maps, load_map, load_world
    from skyroute.world.world import World

_HOME = {
    "Grid": "skyroute.world.grid",
    "InputFormatError": "skyroute.errors",
    "OptionError": "skyroute.errors",
    "PlanResult": "skyroute.result",
    "PreparedGrid": "skyroute.search.prepared",
    "QueryError": "skyroute.errors",
    "SkyrouteError": "skyroute.errors",
    "Status": "skyroute.result",
    "World": "skyroute.world.world",
    "bundled_maps": "skyroute.world.load",
    "clear_caches": "skyroute.caches",
    "load_index": "skyroute.search.prepared",
    "load_map": "skyroute.world.load",
    "load_world": "skyroute.world.load",
    "plan": "skyroute.planner",
    "prepare": "skyroute.search.prepared",
}
__all__ = ["Grid", "InputFormatError", "OptionError", "PlanResult", "PreparedGrid",
           "QueryError", "SkyrouteError", "Status", "World", "bundled_maps", "clear_caches",
           "load_index", "load_map", "load_world", "plan", "prepare"]
__getattr__, __dir__ = exports(__name__, _HOME)
