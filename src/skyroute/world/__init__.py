"""Maps: the occupancy Grid and the loaders that build one from files and arrays.

The names are imported on first use (:mod:`skyroute.lazy`): a grid search imports
``skyroute.world.grid`` without paying for shapely (``World``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from skyroute.lazy import exports

if TYPE_CHECKING:
    from skyroute.world.grid import Grid
    from skyroute.world.load import bundled_maps, load_map, load_world
    from skyroute.world.world import World

_HOME = {"Grid": "skyroute.world.grid", "World": "skyroute.world.world",
         "bundled_maps": "skyroute.world.load", "load_map": "skyroute.world.load",
         "load_world": "skyroute.world.load"}
__all__ = ["Grid", "World", "bundled_maps", "load_map", "load_world"]
__getattr__, __dir__ = exports(__name__, _HOME)
