"""Misspelt keywords named as such: ``skyroute.plan(grid, s, t, algoritm="jps")`` raises
a :class:`~skyroute.errors.KeywordError` (an OptionError and a TypeError) naming
``algoritm``, the closest valid keyword (``algorithm``) and the valid ones, where
Python's own TypeError named none of them.

A public function opts in with :func:`strict_keywords` and a last ``**misspelt``
parameter that its first line refuses::

    @strict_keywords
    def plan(grid, start, goal, *, algorithm=None, **misspelt):
        if misspelt:
            raise unknown_keywords(plan, misspelt)

No wrapper: a wrapper's extra Python call would cost a 32x32 query more than the search
itself takes; the catch-all costs a call the empty dict Python makes for it, and only
the error path reads a signature or runs :mod:`difflib`. The decorator hides the
catch-all from ``inspect.signature`` and ``help()``, which show the real options.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Iterable, Sequence
from typing import TypeVar

from skyroute.errors import KeywordError

F = TypeVar("F", bound=Callable)
_NAMED = (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)


def strict_keywords(func: F) -> F:
    """``func`` itself, its signature shown without its last ``**misspelt`` catch-all
    (which ``func`` refuses with :func:`unknown_keywords`). A function without one is a
    TypeError here, when its module is imported."""
    sig = inspect.signature(func)
    params = list(sig.parameters.values())
    if not params or params[-1].kind is not inspect.Parameter.VAR_KEYWORD:
        raise TypeError(f"{func.__qualname__} needs a last **misspelt parameter for "
                        "@strict_keywords")
    func.__signature__ = sig.replace(parameters=params[:-1])
    return func


def unknown_keywords(func: Callable, given: Iterable[str],
                     valid: Sequence[str] | None = None) -> KeywordError:
    """The error for the keywords ``given`` that ``func`` does not take: each named with
    the closest of ``valid`` (default: the keywords of ``func``'s signature), then the
    valid ones, in one line::

        plan() got an unknown keyword algoritm (did you mean algorithm?); its keywords
        are grid, start, goal, algorithm, ...
    """
    import difflib  # the error path only

    if valid is None:
        valid = [p.name for p in inspect.signature(func).parameters.values()
                 if p.kind in _NAMED]
    names = [str(n) for n in given]
    shown = []
    for name in names:
        close = difflib.get_close_matches(name, valid, n=1) or \
            difflib.get_close_matches(name.lower(), valid, n=1)
        shown.append(f"{name} (did you mean {close[0]}?)" if close else name)
    what = "an unknown keyword" if len(names) == 1 else "unknown keywords"
    return KeywordError(f"{func.__qualname__}() got {what} {', '.join(shown)}; its keywords "
                        f"are {', '.join(valid)}",
                        param=names[0] if len(names) == 1 else tuple(names))
