"""One exception root for skyroute, and the few children a caller may want to catch.

Every message names the bad value and, where there is a fixed set, the valid choices,
so the CLI can print it as one line.
"""

from __future__ import annotations

import math
import numbers
import warnings
from collections.abc import Hashable


class SkyrouteError(Exception):
    """Root of every error skyroute raises on purpose.

    ``param`` names the parameter (or a tuple of parameters) at fault, when there is
    one: messages speak of parameters (``safety=-1 must be ...``) and the CLI maps them
    to its flags.
    """

    def __init__(self, *args, param: str | tuple[str, ...] | None = None) -> None:
        super().__init__(*args)
        self.param = param

    def __reduce__(self):
        """Pickled as its message and attributes, rebuilt without calling ``__init__``:
        Python's default calls ``type(err)(*err.args)``, which fails for every child
        whose constructor takes other arguments than the message (``DaysFailedError(stored,
        failed, days)``: "missing 2 required positional arguments"), and a process pool
        or a Dask worker pickles the errors its tasks raise (a local pool reported such
        an error as its worker 'terminated abruptly'). So every child round-trips, with
        ``param`` and whatever else it keeps (``date``, ``failed``, ...)."""
        return _rebuilt, (type(self), self.args, self.__dict__)


def _rebuilt(cls: type, args: tuple, state: dict) -> SkyrouteError:
    """A :class:`SkyrouteError` (or child) unpickled: ``args`` as given (the message),
    ``state`` its attributes; ``__init__`` is not called (see ``__reduce__``)."""
    err = cls.__new__(cls, *args)
    err.args = args
    err.__dict__.update(state)
    return err


class InputFormatError(SkyrouteError, ValueError):
    """A file (map, scenario, segments, image) could not be read as what it claims to be.

    ``str(err)`` reads ``path:line: message`` (the line is left out when unknown).
    """

    def __init__(self, path: object, message: str, *, line: int | None = None) -> None:
        self.path = str(path)
        self.line = line
        self.reason = message
        where = self.path if line is None else f"{self.path}:{line}"
        super().__init__(f"{where}: {message}", param=None)


CITY = "a colliders.csv city (line 1 'lat0 ..., lon0 ...'), not wall segments x1,y1,x2,y2"


class CityNotWallsError(InputFormatError):
    """A ``colliders.csv`` city (line 1 ``lat0 ..., lon0 ...``) read as a walls map: a
    city is a continuous world of boxes (:func:`skyroute.load_world`), not walls to
    rasterise. It read "expected 4 columns x1,y1,x2,y2, got 2", which named no way on.
    (Here, not in :mod:`skyroute.world.segments`, so that ``skyroute plan`` can catch it
    without importing shapely.)"""


class GridNotWorldError(InputFormatError):
    """A grid map (a MovingAI ``.map``, a ``.csv`` of wall segments, an image, a ``.npy``
    array, a bundled map's name) read as a continuous world: plan on it as a grid
    (:func:`skyroute.load_map`). It read "unknown world type '.map'", or "expected 'lat0
    <deg>, lon0 <deg>', got 'x1,y1,x2,y2'", which named no way on, while a city given to
    the grid loader is told where it belongs (:class:`CityNotWallsError`). ``what`` says
    what the file is, for the CLI to name the command that plans on it."""

    def __init__(self, path: object, what: str, *, line: int | None = None) -> None:
        super().__init__(path, f"{what}: load it with skyroute.load_map", line=line)
        self.what = what


class QueryError(SkyrouteError, ValueError):
    """A start or goal that cannot be planned from: outside the map or on a blocked cell."""


class OptionError(SkyrouteError, ValueError):
    """An unknown or out-of-range option; the message lists the valid ones."""


class KeywordError(OptionError, TypeError):
    """A keyword argument the function does not take (a misspelt option): the message
    names it, the closest valid keyword and the valid ones (see
    :mod:`skyroute.keywords`). A TypeError too, as Python's own error for an unexpected
    keyword is, so a caller's ``except TypeError`` still catches it."""


class WorldNotGridError(InputFormatError):
    """A continuous world's file (GeoJSON zones) read as a grid map: plan in it as a world
    (:func:`skyroute.load_world`). It read "unknown map type '.geojson'", which named no
    way on. ``what`` says what the file is, for the CLI to name the command that plans in
    it (as :class:`CityNotWallsError` does for a colliders city)."""

    def __init__(self, path: object, what: str, *, line: int | None = None) -> None:
        super().__init__(path, f"{what}: load it with skyroute.load_world", line=line)
        self.what = what


def check_instance(name: str, value: object, cls: type, what: str) -> None:
    """Raise :class:`OptionError` unless ``value`` is a ``cls`` (``what`` names it for the
    message): a wrong object passed where a Grid or World belongs is named, not met later
    as an AttributeError deep inside a planner."""
    if not isinstance(value, cls):
        raise OptionError(f"{name} must be {what}, got {type(value).__name__}", param=name)


class StoreBusyError(SkyrouteError):
    """The store is locked by another writer for longer than its busy timeout (SQLite's
    "database is locked"): nothing was written, and the same write may succeed later.
    Not the caller's input: the service answers it 503 with ``Retry-After``."""


class StoreSchemaError(SkyrouteError):
    """The store lacks skyroute's tables (never initialised, an older schema, or its
    tables dropped or its file replaced under a running server); the message names the
    store's URL (password hidden) and says to run ``skyroute db init``. Not the caller's
    input: the service answers it 503, the URL kept in its log."""


def check_choice(name: str, value: object, choices: tuple) -> None:
    """Raise :class:`OptionError` unless ``value`` is one of ``choices`` (an array, which
    compares element by element, never is)."""
    try:
        ok = isinstance(value, Hashable) and value in choices
    except (TypeError, ValueError):
        ok = False
    if not ok:
        valid = ", ".join(repr(c) for c in choices)
        raise OptionError(f"{name}={value!r} is not valid; choose one of {valid}", param=name)


def renamed(new: str, value: object, old: str, old_value: object) -> object:
    """The value of a parameter renamed from ``old`` to ``new`` (the old spelling still
    works for one release, with a DeprecationWarning); both given is an OptionError."""
    if old_value is None:
        return value
    if value is not None:
        raise OptionError(f"give {new} (or its old name {old}), not both", param=new)
    warnings.warn(f"{old}= is deprecated; use {new}=", DeprecationWarning, stacklevel=3)
    return old_value


def real(name: str, value: object, *, low: float | None = None, strict: bool = False,
         high: float | None = None, need: str | None = None) -> float:
    """``value`` as a finite float when it is a real number (a Python or numpy number, or
    a 0-d numeric array; not a bool, a string or a longer array) within ``low`` (``>``
    when ``strict``, else ``>=``) and ``high``, else an :class:`OptionError` naming
    ``name`` (``need``: what the message says it must be, when not the default). NaN and
    the infinities are refused as not finite, with the range beside it (``sensor_range=inf
    must be a finite number > 0``), not as out of range."""
    x = _scalar(value)
    if _is_bool(x) or not isinstance(x, numbers.Real):
        raise OptionError(f"{name}={value!r} must be {need or 'a finite number'}",
                          param=name)
    try:
        x = float(x)
    except OverflowError:  # an int or a Fraction beyond a float's range (10**400)
        x = math.inf
    if not math.isfinite(x):
        raise OptionError(f"{name}={_shown(value)} must be "
                          f"{_finite(need, low, strict, high)}", param=name)
    if (low is not None and (x <= low if strict else x < low)) or \
            (high is not None and x > high):
        need = need or f"a number {_range(low, strict, high)}"
        raise OptionError(f"{name}={_shown(value)} must be {need}", param=name)
    return x


def whole(name: str, value: object, *, low: int | None = None,
          high: int | None = None, need: str | None = None) -> int:
    """``value`` as an int when it is an integer (a Python or numpy integer, or a 0-d
    integer array; not a bool, a float or a string) within [``low``, ``high``], else an
    :class:`OptionError` naming ``name`` (``need`` as for :func:`real`)."""
    x = _scalar(value)
    if _is_bool(x) or not isinstance(x, numbers.Integral) or \
            (low is not None and x < low) or (high is not None and x > high):
        need = need or f"an integer {_range(low, False, high)}".rstrip()
        raise OptionError(f"{name}={_shown(value)} must be {need}", param=name)
    return int(x)


def flag(name: str, value: object) -> bool:
    """``value`` as a bool when it is True or False (numpy's too), else an OptionError."""
    if not _is_bool(value):
        raise OptionError(f"{name}={value!r} must be True or False", param=name)
    return bool(value)


SEED_MAX = 2**32 - 1
"""The largest seed. numba's generator (Hybrid A*'s shortcutting) and numpy's legacy one
take 32 bits, so a larger seed would give a smaller one's stream (2**32 flew as 0): every
``seed`` in skyroute, Python, CLI and service alike, is one integer from 0 to this."""


def check_seed(value: object, name: str = "seed") -> int:
    """``value`` as a seed: an integer from 0 to :data:`SEED_MAX`, else an
    :class:`OptionError` naming ``name`` (``seed=4294967296 must be an integer from 0 to
    4,294,967,295``), the same message wherever a seed is read."""
    return whole(name, value, low=0, high=SEED_MAX)


NO_BUDGET = 2**63 - 1  # max_expansions=None with no cap (an int64 for the kernels)


def budget(value: object, name: str = "max_expansions") -> int:
    """An expansion budget: an integer >= 0 (one above an int64 is no budget), or None,
    which for every planner means enough to finish the search. A search whose states are
    finite and bounded by its input (a grid's cells, a turn lattice's states, a roadmap's
    nodes) needs no cap: None is :data:`NO_BUDGET`, as here. A planner whose states could
    fill the memory caps it and names the cap (the step drone's
    ``step_drone.default_budget``, Hybrid A*'s ``hybrid.MAX_NODES``)."""
    if value is None:
        return NO_BUDGET
    return min(whole(name, value, low=0), NO_BUDGET)


def _scalar(value: object) -> object:
    """A 0-d numpy array's element (``np.array(2.0)`` reads as 2.0); anything else as is.
    (numpy is not imported here: ``skyroute --version`` reads this module.)"""
    if type(value).__name__ == "ndarray" and getattr(value, "ndim", None) == 0 \
            and value.dtype.kind in "biuf":
        return value[()]
    return value


def _shown(value: object) -> str:
    """``repr(value)``, but an integer of more than 30 digits as its number of digits:
    10**400 reads ``<an integer of 401 digits>`` (and Python refuses the repr of one of
    more than 4,300 digits)."""
    if not isinstance(value, int) or abs(value) < 10**30:
        return repr(value)
    digits = int(math.log10(abs(value)))  # a float's estimate, made exact below
    while 10**digits > abs(value):
        digits -= 1
    while 10 ** (digits + 1) <= abs(value):
        digits += 1
    return f"<{'a negative' if value < 0 else 'an'} integer of {digits + 1:,} digits>"


def _is_bool(value: object) -> bool:
    """True for Python's and numpy's booleans (numbers.Integral holds Python's only)."""
    return isinstance(value, bool) or type(value).__name__ in ("bool_", "bool")


def _finite(need: str | None, low, strict: bool, high) -> str:
    """'a finite number' with the range a real number must also be in: ``need`` when
    given ('> 0', 'a number >= 1', 'positive', 'in (0, pi] radians'), else the bounds."""
    if need is None:
        return f"a finite number {_range(low, strict, high)}".rstrip()
    for lead in ("a finite number", "a number"):
        if need.startswith(lead):
            return "a finite number" + need[len(lead):]
    if need[0] in "<>=" or need.startswith(("in ", "from ")):
        return f"a finite number {need}"
    if need.isalpha():  # 'positive'
        return f"a finite {need} number"
    return f"a finite number ({need})"


def _range(low, strict: bool, high) -> str:
    """'>= 1', '> 0', 'from 2 to 10,000,000', '<= 5' (integers with thousands commas)."""
    lo, hi = (None if v is None else f"{v:,}" if isinstance(v, int) else f"{v:g}"
              for v in (low, high))
    if lo is not None and hi is not None:
        return f"from {lo} to {hi}" if not strict else f"> {lo} and <= {hi}"
    if lo is not None:
        return f"{'>' if strict else '>='} {lo}"
    return "" if hi is None else f"<= {hi}"
