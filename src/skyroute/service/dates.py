"""``IsoDate``: a day as the API takes it, ``YYYY-MM-DD`` only.

Pydantic's lax dates also take numbers (``0`` is 1970-01-01, ``1704240000`` a Unix
time) and other spellings; the schema promises ``format: date``, so anything else is a
422 naming the field.
"""

from __future__ import annotations

import datetime as dt
import re
from typing import Annotated

from pydantic import BeforeValidator

_ISO = re.compile(r"[0-9]{4}-[0-9]{2}-[0-9]{2}")


def _iso(value: object) -> object:
    if isinstance(value, dt.date) and not isinstance(value, dt.datetime):
        return value
    if isinstance(value, str) and _ISO.fullmatch(value):
        return value  # pydantic checks the day itself (2024-02-30 is refused)
    raise ValueError(f"{value!r} is not a date as YYYY-MM-DD")


IsoDate = Annotated[dt.date, BeforeValidator(_iso)]
