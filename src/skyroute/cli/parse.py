"""Parse the CLI's small value formats, with errors that name the option."""

from __future__ import annotations

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


def parse_list(text: str | None) -> list[str]:
    """``"a,b"`` -> ["a", "b"]; empty or None -> []."""
    return [p.strip() for p in (text or "").split(",") if p.strip()]
