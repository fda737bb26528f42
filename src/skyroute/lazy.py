"""Public names of a package imported on first use (PEP 562).

A package ``__init__`` that imported every public name would make each command pay for
all of them: ``skyroute plan`` on a grid would load shapely, scipy and pyproj for the
World it never reads. :func:`exports` gives such a package a ``__getattr__`` that
imports a name from the module holding it when it is first asked for, and its modules
the same way: ``import skyroute; skyroute.motion.hybrid.plan(...)`` works as the docs
write it, where Python alone raised AttributeError until ``skyroute.motion.hybrid`` was
imported by name.
"""

from __future__ import annotations

import pkgutil
import sys
from collections.abc import Callable
from importlib import import_module


def exports(package: str, home: dict[str, str] | None = None) -> tuple[Callable, Callable]:
    """``(__getattr__, __dir__)`` for ``package``; ``home`` maps each public name to the
    module that defines it. The package's own modules and subpackages are imported when
    first asked for as attributes. ``dir()`` lists the public names (``__all__``, else
    ``home``) and the modules, not what the ``__init__`` imported for itself."""
    home = home or {}

    def modules() -> set[str]:
        path = getattr(sys.modules[package], "__path__", ())
        return {m.name for m in pkgutil.iter_modules(path) if not m.name.startswith("_")}

    def __getattr__(name: str):  # noqa: N807  (the module hook's own name)
        if name in home:
            value = getattr(import_module(home[name]), name)
        elif not name.startswith("_") and name in modules():
            value = import_module(f"{package}.{name}")
        else:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        setattr(sys.modules[package], name, value)  # later lookups skip the hook
        return value

    def __dir__() -> list[str]:  # noqa: N807
        mod = sys.modules[package]
        public = getattr(mod, "__all__", home)
        dunders = {n for n in vars(mod) if n.startswith("__") and n.endswith("__")}
        return sorted({*public, *modules(), *dunders})

    return __getattr__, __dir__
