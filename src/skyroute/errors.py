"""One exception root for skyroute, and the few children a caller may want to catch.

Every message names the bad value and, where there is a fixed set, the valid choices,
so the CLI can print it as one line.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Hashable


class SkyrouteError(Exception):
    """Root of every error skyroute raises on purpose.

    ``param`` names the parameter (or a tuple of parameters) at fault, when there is
    one: messages speak of parameters (``safety=-1 must be ...``) and the CLI maps them
    to its flags.
    """

    def __init__(self, *args, param: str | tuple[str, ...] | None = None) -> None:
        super().__init__(*args)
        self.param = param


class InputFormatError(SkyrouteError, ValueError):
    """A file (map, scenario, segments, image) could not be read as what it claims to be.

    ``str(err)`` reads ``path:line: message`` (the line is left out when unknown).
    """

    def __init__(self, path: object, message: str, *, line: int | None = None) -> None:
        self.path = str(path)
        self.line = line
        self.reason = message
        where = self.path if line is None else f"{self.path}:{line}"
        super().__init__(f"{where}: {message}", param=None)


class QueryError(SkyrouteError, ValueError):
    """A start or goal that cannot be planned from: outside the map or on a blocked cell."""


class OptionError(SkyrouteError, ValueError):
    """An unknown or out-of-range option; the message lists the valid ones."""


def check_choice(name: str, value: object, choices: tuple) -> None:
    """Raise :class:`OptionError` unless ``value`` is one of ``choices`` (an array, which
    compares element by element, never is)."""
    try:
        ok = isinstance(value, Hashable) and value in choices
    except (TypeError, ValueError):
        ok = False
    if not ok:
        valid = ", ".join(repr(c) for c in choices)
        raise OptionError(f"{name}={value!r} is not valid; choose one of {valid}", param=name)


def renamed(new: str, value: object, old: str, old_value: object) -> object:
    """The value of a parameter renamed from ``old`` to ``new`` (the old spelling still
    works for one release, with a DeprecationWarning); both given is an OptionError."""
    if old_value is None:
        return value
    if value is not None:
        raise OptionError(f"give {new} (or its old name {old}), not both", param=new)
    warnings.warn(f"{old}= is deprecated; use {new}=", DeprecationWarning, stacklevel=3)
    return old_value


def real(name: str, value: object) -> float:
    """``value`` as a finite float when it is a real number (not a bool, a string or an
    array), else an :class:`OptionError` naming ``name``."""
    import numbers

    if isinstance(value, bool) or not isinstance(value, numbers.Real) \
            or not math.isfinite(value):
        raise OptionError(f"{name}={value!r} must be a finite number", param=name)
    return float(value)
