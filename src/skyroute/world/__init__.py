"""Maps: the occupancy Grid and the loaders that build one from files and arrays."""

from skyroute.world.grid import Grid
from skyroute.world.load import bundled_maps, load_map, load_world
from skyroute.world.world import World

__all__ = ["Grid", "World", "bundled_maps", "load_map", "load_world"]
