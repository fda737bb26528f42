"""Request rules of the form "give exactly one of ...", stated in the OpenAPI schema.

A request model checks such a rule in a pydantic validator (with a message naming the
fields); :func:`exactly_one` states the same rule in the model's JSON Schema
(``model_config = ConfigDict(json_schema_extra=exactly_one(...))``), so a client
generated from ``/openapi.json`` knows it too. tests/service/test_alternatives.py checks
that schema and validator accept the same bodies.

A field counts as given when it is present and not null, as the validators read it
(an optional field defaults to None, so ``"map": null`` is the same as no ``map``).
"""

from __future__ import annotations


def exactly_one(*alternatives: str | tuple[str, ...],
                among: tuple[str, ...] | None = None) -> dict:
    """``{"oneOf": [...]}``: one branch per alternative, in which its fields are given
    and the other fields of ``among`` are not (default: every field of every
    alternative). A field of an alternative left out of ``among`` (``world_format``,
    which goes with ``world_text``) is required in its branch and free in the others.

    >>> first, second = exactly_one("preset", "scenario")["oneOf"]
    >>> first["required"], first["properties"]
    (['preset'], {'preset': {'not': {'type': 'null'}}, 'scenario': {'type': 'null'}})
    """
    groups = [(a,) if isinstance(a, str) else tuple(a) for a in alternatives]
    if len(groups) < 2 or not all(groups):
        raise ValueError(f"exactly_one needs two or more alternatives, got {alternatives!r}")
    if among is None:
        among = tuple(f for g in groups for f in g)
    branches = []
    for group in groups:
        props = {f: {"not": {"type": "null"}} for f in group}  # present, not null
        props.update({f: {"type": "null"} for f in among if f not in group})  # or absent
        branches.append({"required": list(group), "properties": props})
    return {"oneOf": branches}
