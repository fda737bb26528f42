"""How many delivery days one command or job may fly: ``skyroute deliver --from/--to``
and the service's delivery jobs share the limit, so a typo in a year (2999 for 2024)
is refused at once instead of queuing a thousand years of empty days.

>>> import datetime as dt
>>> check_days(dt.date(2024, 1, 1), dt.date(2024, 12, 31), "--from", "--to")
366
"""

from __future__ import annotations

import datetime as dt

from skyroute.errors import OptionError

MAX_DAYS = 3660  # ten years of days (the ILP data holds two)


def check_days(first: dt.date, last: dt.date, first_name: str = "from",
               last_name: str = "to") -> int:
    """The number of days from ``first`` to ``last``, both included; an OptionError
    naming ``last_name`` when it is before ``first`` or the range holds more than
    :data:`MAX_DAYS` days."""
    if last < first:
        raise OptionError(f"{last_name} {last} is before {first_name} {first}",
                          param=last_name)
    days = (last - first).days + 1
    if days > MAX_DAYS:
        raise OptionError(f"{first_name} {first} {last_name} {last} is {days:,} days, over "
                          f"the limit of {MAX_DAYS:,} in one run", param=last_name)
    return days
