"""skyroute: plan where drones and small robots fly or drive.

The public API is small: :func:`load_map` reads a map into a :class:`Grid`, :func:`plan`
searches it and returns a :class:`PlanResult`.
"""

from skyroute.caches import clear_caches
from skyroute.errors import InputFormatError, OptionError, QueryError, SkyrouteError
from skyroute.planner import plan
from skyroute.result import PlanResult, Status
from skyroute.search.prepared import PreparedGrid, load_index, prepare
from skyroute.world.grid import Grid
from skyroute.world.load import bundled_maps, load_map, load_world
from skyroute.world.world import World

__version__ = "0.1.0"

__all__ = [
           "Grid",
           "InputFormatError",
           "OptionError",
           "PlanResult",
           "PreparedGrid",
           "QueryError",
           "SkyrouteError",
           "Status",
           "World",
           "bundled_maps",
           "clear_caches",
           "load_index",
           "load_map",
           "load_world",
           "plan",
           "prepare",
]
