"""One JSON encoder for everything the CLI prints or writes and the service serves:
non-finite numbers are null, never ``Infinity`` or ``NaN`` (no JSON: RFC 8259)."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from skyroute.io.json_text import finite, to_json

SRC = Path(__file__).resolve().parents[2] / "src" / "skyroute"


def _strict(text: str):
    """JSON as jq and JSON.parse read it: Infinity and NaN refused."""
    def refuse(name):
        raise ValueError(f"{name} is not JSON")
    return json.loads(text, parse_constant=refuse)


def _same(a, b) -> bool:
    """``b`` is ``a`` written as JSON with non-finite numbers as None."""
    if isinstance(a, float):
        return b is None if not math.isfinite(a) else b == a
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, list | tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return a == b


docs = st.recursive(
    st.none() | st.booleans() | st.integers() | st.text(max_size=5)
    | st.floats(allow_nan=True, allow_infinity=True),
    lambda kids: st.lists(kids, max_size=4) | st.tuples(kids, kids)
    | st.dictionaries(st.text(max_size=5), kids, max_size=4),
    max_leaves=20)


@given(doc=docs)
def test_any_document_is_strict_json_with_non_finite_numbers_null(doc):
    text = to_json(doc)
    back = _strict(text)
    assert _same(doc, back)
    json.dumps(back, allow_nan=False)  # nothing left that strict JSON refuses
    assert to_json(doc, indent=1) == json.dumps(finite(doc), indent=1, allow_nan=False)


def test_numpy_infinities_and_a_flight_not_found():
    doc = {"status": "no_path", "length": np.float64(np.inf), "mean": [np.nan, 1.5],
           "pose": (0.0, -math.inf)}
    assert to_json(doc) == ('{"status": "no_path", "length": null, "mean": [null, 1.5], '
                            '"pose": [0.0, null]}')


def test_every_json_writer_of_the_cli_io_and_service_uses_the_encoder():
    """No `json.dumps(` in cli/, io/ and service/ but the encoder's own: a writer that
    called it directly printed `"length": Infinity` (fly --vehicle dubins --json)."""
    direct = [f"{p.relative_to(SRC)}:{n}"
              for part in ("cli", "io", "service") for p in sorted((SRC / part).rglob("*.py"))
              for n, line in enumerate(p.read_text().splitlines(), 1)
              if re.search(r"\bjson\.dumps?\(", line) and p.name != "json_text.py"]
    assert direct == []
