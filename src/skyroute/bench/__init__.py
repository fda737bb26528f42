"""Benchmarks: skyroute's planners against peer libraries on the same queries."""

from skyroute.lazy import exports as _exports

__getattr__, __dir__ = _exports(__name__)  # its modules, imported when first asked for
