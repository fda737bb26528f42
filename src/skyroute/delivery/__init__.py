"""Delivery days: the lunch drone (ILP 2021 rules) from orders to a stored, validated flight."""

from skyroute.lazy import exports as _exports

__getattr__, __dir__ = _exports(__name__)  # its modules, imported when first asked for
