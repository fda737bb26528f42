"""The fleet: drones flying between airports, their trajectories and their separation."""

from skyroute.lazy import exports as _exports

__getattr__, __dir__ = _exports(__name__)  # its modules, imported when first asked for
