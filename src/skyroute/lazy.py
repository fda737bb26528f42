"""Public names of a package imported on first use (PEP 562).

A package ``__init__`` that imported every public name would make each command pay for
all of them: ``skyroute plan`` on a grid would load shapely, scipy and pyproj for the
World it never reads. :func:`exports` gives such a package a ``__getattr__`` that
imports a name from the module holding it when it is first asked for.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from importlib import import_module


def exports(package: str, home: dict[str, str]) -> tuple[Callable, Callable]:
    """``(__getattr__, __dir__)`` for ``package``; ``home`` maps each public name to the
    module that defines it."""

    def __getattr__(name: str):  # noqa: N807  (the module hook's own name)
        if name not in home:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(import_module(home[name]), name)
        setattr(sys.modules[package], name, value)  # later lookups skip the hook
        return value

    def __dir__() -> list[str]:  # noqa: N807
        return sorted({*vars(sys.modules[package]), *home})

    return __getattr__, __dir__
