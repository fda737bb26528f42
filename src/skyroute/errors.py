"""One exception root for skyroute, and the few children a caller may want to catch.

Every message names the bad value and, where there is a fixed set, the valid choices,
so the CLI can print it as one line.
"""

from __future__ import annotations


class SkyrouteError(Exception):
    """Root of every error skyroute raises on purpose."""


class InputFormatError(SkyrouteError, ValueError):
    """A file (map, scenario, segments, image) could not be read as what it claims to be.

    ``str(err)`` reads ``path:line: message`` (the line is left out when unknown).
    """

    def __init__(self, path: object, message: str, *, line: int | None = None) -> None:
        self.path = str(path)
        self.line = line
        self.reason = message
        where = self.path if line is None else f"{self.path}:{line}"
        super().__init__(f"{where}: {message}")


class QueryError(SkyrouteError, ValueError):
    """A start or goal that cannot be planned from: outside the map or on a blocked cell."""


class OptionError(SkyrouteError, ValueError):
    """An unknown or out-of-range option; the message lists the valid ones."""


def check_choice(name: str, value: object, choices: tuple) -> None:
    """Raise :class:`OptionError` unless ``value`` is one of ``choices``."""
    if value not in choices:
        valid = ", ".join(repr(c) for c in choices)
        raise OptionError(f"{name}={value!r} is not valid; choose one of {valid}")
