"""One value per single-valued query parameter, for every route.

FastAPI reads a parameter declared as one value (``date``, ``offset``, ``limit``) from
the last of its repeats and drops the others without a word: ``GET
/orders?date=2024-01-03&date=2024-01-04`` answered the orders of the 4th as if the 3rd
had not been asked for. :func:`one_value_each`, a dependency of the whole app, answers
such a request 422 naming the parameter, before the route runs; a parameter declared as
a list (``list[str]``) still takes every repeat. On a route that needs the token the
caller is authenticated first (401 or 403): as a dependency of the app the check runs
before the route's own, and it answered a caller without the token 422 naming the
route's parameter.
"""

from __future__ import annotations

import collections.abc
import types
import typing

from fastapi import Request

from skyroute.service.auth import authenticate, needs_token
from skyroute.service.problems import Problem

_MANY = (list, tuple, set, frozenset, collections.abc.Sequence, collections.abc.Set)


def _takes_many(annotation) -> bool:
    """Whether a parameter of this type reads every repeat (a list, ``list[str] | None``)."""
    origin = typing.get_origin(annotation)
    if origin is typing.Annotated:
        return _takes_many(typing.get_args(annotation)[0])
    if origin in (typing.Union, types.UnionType):
        return any(_takes_many(a) for a in typing.get_args(annotation))
    kind = origin or annotation
    return isinstance(kind, type) and issubclass(kind, _MANY) and \
        not issubclass(kind, (str, bytes))


def single_valued(route) -> tuple[str, ...]:
    """The query parameters ``route`` (a FastAPI route) reads as one value, by the names
    a request gives them (aliases), its dependencies' included."""
    names, todo = [], [route.dependant]
    while todo:
        dependant = todo.pop()
        names += [f.alias for f in dependant.query_params
                  if not _takes_many(f.field_info.annotation)]
        todo += dependant.dependencies
    return tuple(dict.fromkeys(names))


async def one_value_each(request: Request) -> None:
    """A 422 problem naming the first single-valued query parameter given more than
    once (a dependency of the app: it runs before each route's own parameters are
    read), after the token on a route that needs one. (async: a sync dependency would
    cost a trip through the thread pool)"""
    route = request.scope.get("route")
    if not request.scope.get("query_string") or route is None or \
            not hasattr(route, "dependant"):
        return  # most requests (POST /plan, the viewer's files) have no query at all
    query = request.query_params
    for name in single_valued(route):
        values = query.getlist(name)
        if len(values) > 1:
            if needs_token(route):
                await authenticate(request)  # 401 or 403 first: the route's own order
            shown = ", ".join(repr(v) for v in values[:5]) + (", ..." if len(values) > 5
                                                              else "")
            raise Problem(422, f"{name}: given {len(values)} times ({shown}); give it once",
                          field=name)
