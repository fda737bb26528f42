"""Vehicle models: turn a planned path (or a start and a goal) into what a vehicle flies."""

from skyroute.lazy import exports as _exports

__getattr__, __dir__ = _exports(__name__)  # its modules, imported when first asked for
