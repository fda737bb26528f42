"""Parse the CLI's small value formats, with errors that name the option."""

from __future__ import annotations

import datetime as dt
import re

from skyroute.errors import OptionError


def parse_cell(text: str, option: str) -> tuple[int, int]:
    """``"X,Y"`` -> (x, y) integers."""
    parts = text.replace(" ", "").split(",")
    try:
        if len(parts) != 2:
            raise ValueError
        return int(parts[0]), int(parts[1])
    except ValueError:
        raise OptionError(f"{option} {text!r} must be two integers X,Y (column,row)") from None


_DAY = re.compile(r"[0-9]{4}-[0-9]{2}-[0-9]{2}")  # ASCII digits: \d takes "٢٠٢٤" too


def parse_date(text: str, option: str) -> dt.date:
    """``YYYY-MM-DD`` -> a date, that form only, as the service's dates: Python 3.11's
    ``date.fromisoformat`` also takes ``20240103`` and the week date ``2024-W01-3``. A
    day the calendar lacks (2024-02-30, 2024-13-01) says so; it was "expected a date
    YYYY-MM-DD", which it is."""
    if not _DAY.fullmatch(text):
        raise OptionError(f"{option} {text!r}: expected a date YYYY-MM-DD")
    try:
        return dt.date.fromisoformat(text)
    except ValueError as exc:
        raise OptionError(f"{option} {text!r}: no such day ({exc})") from None


def parse_items(text: str, option: str) -> list[str]:
    """``"a, b"`` -> ["a", "b"]: a comma-separated option's items, each stripped; an empty
    one (``20,,60``, a trailing comma) is an OptionError naming the option and the item,
    where it was passed over: ``--rates 20,,60`` swept two rates, not the three meant."""
    items = [p.strip() for p in text.split(",")]
    for k, item in enumerate(items):
        if not item and text.strip():
            raise OptionError(f"{option} {text!r}: item {k + 1} is empty (a stray comma?)")
    return [p for p in items if p]


def parse_list(text: str | None) -> list[str]:
    """``"a,b"`` -> ["a", "b"]; empty or None -> []."""
    return [p.strip() for p in (text or "").split(",") if p.strip()]


def check_outputs(**files) -> None:
    """Every file a command writes (``option=path``, ``None`` for not asked; ``plot`` a
    PNG), checked before its work: a path that cannot be written, or a picture not named
    ``.png``, is one line naming the option. Checking them all first means that exit 2
    leaves none written: ``plan --geojson p.geojson --plot /proc/p.png`` wrote the
    GeoJSON and then failed on the picture; ``--plot p.jpg`` wrote PNG bytes into a
    ``.jpg``."""
    from skyroute.errors import SkyrouteError
    from skyroute.files import check_writable

    for name, path in files.items():
        if path is None:
            continue
        flag = "--" + name.replace("_", "-")
        if name == "plot" and path.suffix.lower() != ".png":
            raise OptionError(f"{flag} {path}: pictures are PNG files; name it .png", param=name)
        try:
            check_writable(path)
        except SkyrouteError as exc:
            raise OptionError(f"{flag} {exc}", param=name) from None
