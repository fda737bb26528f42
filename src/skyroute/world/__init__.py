"""Maps: the occupancy Grid and the loaders that build one from files and arrays."""

from skyroute.world.grid import Grid
from skyroute.world.load import bundled_maps, load_map

__all__ = ["Grid", "bundled_maps", "load_map"]
