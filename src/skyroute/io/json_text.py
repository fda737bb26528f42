"""JSON text that every JSON reader accepts: non-finite numbers written as ``null``.

Python's ``json.dumps`` writes an infinite or NaN float as ``Infinity`` or ``NaN``,
which are not JSON (RFC 8259): ``python -m json.tool`` reads them, but jq, browsers'
``JSON.parse`` and most other parsers refuse the whole document. A length of a flight
not found is infinite (``fly --vehicle dubins --json`` printed ``"length": Infinity``);
a mean over nothing is NaN. Every JSON the CLI prints or writes, and the service
serves, goes through :func:`to_json`, so such a value is ``null`` everywhere alike
(as ``cost`` of a path not found already was).
"""

from __future__ import annotations

import json
import math


def finite(obj):
    """``obj`` with every non-finite float in its dicts, lists and tuples replaced by
    None; other values as they are, in new containers (a tuple comes back a list, as
    JSON writes it)."""
    if isinstance(obj, float):  # numpy's float64 too
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: finite(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [finite(v) for v in obj]
    return obj


def to_json(obj, **kwargs) -> str:
    """``json.dumps(obj, **kwargs)`` with non-finite numbers as ``null``
    (``allow_nan=False``: none is ever written as ``Infinity`` or ``NaN``). The
    document is walked (:func:`finite`) only when it holds one: a day's or a fleet's
    GeoJSON of a million coordinates is not walked number by number."""
    try:
        return json.dumps(obj, allow_nan=False, **kwargs)
    except ValueError as exc:
        if "Out of range float" not in str(exc):  # not an infinity or a NaN
            raise
        return json.dumps(finite(obj), allow_nan=False, **kwargs)
