"""Outputs: JSON and GeoJSON files, PNG plots; every file is written whole or not at all."""

from skyroute.lazy import exports as _exports

__getattr__, __dir__ = _exports(__name__)  # its modules, imported when first asked for
