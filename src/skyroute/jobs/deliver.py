"""A range of delivery days as tasks, one per day, on any executor with the same rows.

What a worker gets (:class:`DayTask`): where the site is read from (a folder or an HTTP
URL; the worker loads the site once and keeps it), the date, that day's orders and the
method. The worker flies the day and sends the :class:`DayResult` back; it writes
nothing. The caller stores each day as its result arrives (:func:`run_days`), in one
transaction that first deletes whatever an earlier run stored for that date
(:func:`skyroute.delivery.store.store_day`), together with the day's files when it
writes any: they are written to temporary names, the day's rows written, the files
renamed into place, then the rows committed (:func:`skyroute.files.written_together`,
:meth:`~skyroute.files.Together.enter`), so a day is stored with its files or, after an
error, a failed rename or commit, or Ctrl-C, neither is. Workers that stored their days
themselves stored days the caller then never wrote files for (a Ctrl-C, a full disk
while a PNG was written, or another day's error in a range with ``--jobs``). A day run
twice, or re-run on another worker after its worker died, is stored once (its first
result to arrive), and a worker killed halfway leaves the previous state of that day.

A day whose flight fails (an error raised while the worker flies it) comes back as a
:class:`DayFailed`, not as an error of the whole map: the other days are flown and
stored as usual, and :func:`run_days` raises :class:`DaysFailedError` at the end,
naming the failed days. So does a day whose worker process died under it every time it
was tried (:class:`~skyroute.jobs.executor.TasksLostError`: twice on a local pool, the
second time alone; four times on Dask): the out-of-memory killer or a signal ended the
range with a traceback (``BrokenProcessPool``), and the days not yet stored were lost.
A range stopped at its first failed day dropped the days the workers had flown
meanwhile (and, with the days in order, never flew the rest): a month with one bad day
was flown again whole.

The caller fills the leg table first (:func:`skyroute.delivery.days.prepare_legs`);
workers sharing its cache folder only read it, and a worker on another machine fills its
own on first use (the legs are the same, so are the days).
"""

from __future__ import annotations

import datetime as dt
import logging
import traceback
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import sqlalchemy as sa

from skyroute.caches import register
from skyroute.delivery import store
from skyroute.delivery.day import METHODS, DayResult, plan_day
from skyroute.delivery.days import prepare_legs, refuse_foreign
from skyroute.delivery.orders import Order
from skyroute.delivery.site import load_site
from skyroute.delivery.source import DirSource, HttpSource, open_source
from skyroute.errors import OptionError, SkyrouteError, check_choice
from skyroute.files import written_together
from skyroute.jobs.executor import TasksLostError

log = logging.getLogger("skyroute.jobs")


@dataclass(frozen=True)
class DayTask:
    """One day for a worker: site source, date, its orders, method."""

    source: DirSource | HttpSource
    date: dt.date
    orders: tuple[Order, ...]
    method: str = "milp"


_SITES: dict = {}
register(_SITES.clear)


def _site(source):
    if source not in _SITES:
        _SITES[source] = load_site(source)
    return _SITES[source]


@dataclass(frozen=True)
class DayFailed:
    """A day whose flight raised, sent back by its worker in place of its
    :class:`DayResult`. ``error``: one line naming the day (a SkyrouteError's message,
    else the exception's type and message); ``expected``: the error was a SkyrouteError
    (bad input, a flight that failed validation), not a defect; ``traceback``: the
    worker's traceback, for a defect. Text rather than the exception: an exception need
    not survive the trip back (an :class:`~skyroute.errors.InputFormatError` does not
    unpickle, and a local pool reported it as a worker 'terminated abruptly')."""

    date: dt.date
    error: str
    expected: bool
    traceback: str = ""


def _failed(date: dt.date, exc: Exception) -> DayFailed:
    text = " ".join(str(exc).split())
    expected = isinstance(exc, SkyrouteError)
    if not expected:
        text = f"{type(exc).__name__}: {text}" if text else type(exc).__name__
    if not text.startswith(f"{date}:"):  # most of the planner's own errors name it
        text = f"{date}: {text}"
    trace = "" if expected else "".join(traceback.format_exception(exc))
    return DayFailed(date, text, expected, trace)


def _interrupted(exc: BaseException) -> bool:
    """A Ctrl-C or SIGTERM behind ``exc``: one that came while a compiled kernel ran
    surfaces as a SystemError caused by it (see :func:`skyroute.cli.errors.run_cli`).
    It stops the range; it is no day's failure."""
    seen: BaseException | None = exc
    for _ in range(10):
        seen = seen.__cause__ or seen.__context__
        if seen is None:
            return False
        if not isinstance(seen, Exception):  # KeyboardInterrupt, the CLI's Terminated
            return True
    return False


def for_workers(source: DirSource | HttpSource) -> DirSource | HttpSource:
    """``source`` as the workers read it: a folder by its absolute path. A relative
    ``--data`` was read by each Dask worker against its own working folder (a worker
    started elsewhere failed every day with "syn/website/menus/menus.json: no such
    file"). Absolute, not resolved: a shared folder is mounted at the same path on
    every machine, while its symbolic links may lead elsewhere on this one."""
    if isinstance(source, DirSource) and not source.root.is_absolute():
        return DirSource(source.root.absolute())
    return source


def fly_day(task: DayTask) -> DayResult | DayFailed:
    """The worker's task: fly the day and return it (the caller stores it), or the
    :class:`DayFailed` saying why it could not be flown."""
    try:
        return plan_day(_site(task.source), task.date, list(task.orders),
                        method=task.method)
    except Exception as exc:
        if _interrupted(exc):
            raise
        return _failed(task.date, exc)


class DaysFailedError(SkyrouteError):
    """Some days of :func:`run_days` failed; the others were stored. ``stored``: their
    results in date order; ``failed``: the :class:`DayFailed` days in date order;
    ``days``: how many days were run. The message is one line: a lone day's error, or
    how many failed, that the others are stored, and the first errors."""

    SHOWN = 3  # errors in the message; the rest are counted

    def __init__(self, stored: list[DayResult], failed: list[DayFailed], days: int) -> None:
        self.stored, self.failed, self.days = stored, failed, days
        if days == 1:
            text = failed[0].error
        else:
            n, rest = len(failed), days - len(failed)
            text = ((f"all {days:,} days failed and none was stored: " if not rest else
                     f"{n:,} of the {days:,} days failed and {'was' if n == 1 else 'were'} "
                     f"not stored (the other {rest:,} {'is' if rest == 1 else 'are'}): ")
                    + "; ".join(f.error for f in failed[:self.SHOWN])
                    + (f"; and {n - self.SHOWN:,} more" if n > self.SHOWN else ""))
        super().__init__(text)


def days_between(engine: sa.Engine, first: dt.date, last: dt.date) -> dict[dt.date, list]:
    """Every date from ``first`` to ``last`` with its stored orders (a date without any
    is an empty day, still flown and stored)."""
    by_date = store.orders_between(engine, first, last)
    for k in range((last - first).days + 1):
        by_date.setdefault(first + dt.timedelta(k), [])
    return dict(sorted(by_date.items()))


def run_days(engine: sa.Engine, source, by_date: dict[dt.date, list], *, executor,
             method: str = "milp", replace: bool = False,
             files: Callable[[DayResult], object] | None = None,
             on_day: Callable[[DayResult], None] | None = None,
             on_failed: Callable[[DayFailed], None] | None = None) -> list[DayResult]:
    """Fly every day of ``by_date`` as one task each on ``executor`` and store each as
    its result arrives; results in date order. A day whose every order is invalid does
    not replace a stored flight that delivered unless ``replace``
    (:class:`~skyroute.delivery.store.DayKeptError`).

    ``files(result)``: writes the day's files through :func:`skyroute.files.open_atomic`
    (:func:`skyroute.io.day_out.write_outputs`); they are written to temporary names,
    the day's rows written, the files renamed into place and the rows committed last
    (one :func:`~skyroute.files.written_together` block), so an error or Ctrl-C in
    either, a rename that fails or a commit that fails, leaves the day's rows and files
    as they were. ``on_day(result)`` is called once the day is stored and its files are
    in place.

    A day whose flight fails (:class:`DayFailed`, passed to ``on_failed`` as it
    arrives; also a day whose worker died under it every time it was tried, see
    :class:`~skyroute.jobs.executor.TasksLostError`, passed at the end) is neither
    stored nor given files, and the run goes on: every other day is
    flown and stored, then :class:`DaysFailedError` is raised with the stored days'
    results and the failed days, each in date order. An error in the caller (storing a
    day, writing its files, a day kept, the executor's own) or a Ctrl-C stops the run:
    it has stored the days that arrived before it, each with its files, and no other."""
    check_choice("method", method, METHODS)
    source = for_workers(source)
    tasks = [DayTask(source, d, tuple(orders), method) for d, orders in sorted(by_date.items())]
    failed: list[DayFailed] = []

    def arrived(_i: int, result: DayResult | DayFailed) -> None:
        if isinstance(result, DayFailed):
            failed.append(result)
            if on_failed is not None:
                on_failed(result)
            return
        # the rows are committed after the files are renamed into place, before their
        # earlier versions are dropped: a failed rename rolls the rows back, a failed
        # commit puts the files back (the rows were committed first: a failed rename
        # left the new flight stored beside the earlier run's files)
        with written_together() as together:
            if files is not None:
                files(result)  # staged first: the day's lock is not held while plotting
            conn = together.enter(store.writing(engine))
            store.store_day(conn, result, replace=replace)
        if on_day is not None:
            on_day(result)

    try:
        results = executor.map(fly_day, tasks, on_result=arrived)
    except TasksLostError as exc:  # a worker died under these days, every time tried
        results = exc.results
        for i, why in exc.lost.items():
            arrived(i, DayFailed(tasks[i].date, f"{tasks[i].date}: {why}", expected=True))
    stored = [r for r in results if r is not None and not isinstance(r, DayFailed)]
    if failed:
        raise DaysFailedError(stored, sorted(failed, key=lambda f: f.date), len(tasks))
    return stored


def summarise(results: list[DayResult]) -> dict:
    """Mean and minimum money % over the days with orders, and per month."""
    pcts = [(r.date, r.money_pct) for r in results if r.money_pct is not None]
    if not pcts:
        return {"days": len(results), "days_with_orders": 0}
    months: dict[str, list[float]] = {}
    for d, p in pcts:
        months.setdefault(f"{d:%Y-%m}", []).append(p)
    worst = min(pcts, key=lambda x: x[1])
    return {"days": len(results), "days_with_orders": len(pcts),
            "mean_pct": sum(p for _, p in pcts) / len(pcts), "min_pct": worst[1],
            "min_date": worst[0].isoformat(),
            "months": {m: {"mean_pct": sum(v) / len(v), "min_pct": min(v), "days": len(v)}
                       for m, v in sorted(months.items())},
            "moves_max": max(r.flight.moves for r in results),
            "seconds_per_day_mean": sum(r.seconds for r in results) / len(results),
            "seconds_per_day_max": max(r.seconds for r in results)}


# -- the runner's "deliver" job ------------------------------------------------------------

def _date(params: dict, key: str) -> dt.date:
    text = params.get(key)
    try:
        return dt.date.fromisoformat(text)
    except (TypeError, ValueError):
        raise OptionError(f"{key}={text!r}: expected a date YYYY-MM-DD", param=key) from None


def check_params(params: dict) -> dict:
    """The ``deliver`` job's parameters checked and completed: ``{"date": D}`` or
    ``{"from": D, "to": D}`` (ISO dates), exactly one of ``data`` (a folder in the ILP
    layout) or ``source`` (an HTTP URL) naming the site, ``method`` (``milp``
    default, or ``greedy``) and ``replace`` (false default: a day whose every order is
    invalid keeps a stored flight that delivered and fails the job, as ``skyroute
    deliver`` without ``--replace``). The orders must be in the store already
    (``skyroute db import``). Errors name the field."""
    if not isinstance(params, dict):
        raise OptionError("params must be a mapping", param="params")
    known = {"date", "from", "to", "data", "source", "method", "replace"}
    unknown = sorted(set(params) - known)
    if unknown:
        raise OptionError(f"{unknown[0]}: unknown parameter of a deliver job; valid: "
                          + ", ".join(sorted(known)), param=unknown[0])
    if "date" in params:
        if "from" in params or "to" in params:
            raise OptionError("give date, or from and to, not both", param="date")
        first = last = _date(params, "date")
    else:
        first, last = _date(params, "from"), _date(params, "to")
        if last < first:
            raise OptionError(f"to={last} is before from={first}", param="to")
    method = params.get("method", "milp")
    check_choice("method", method, METHODS)
    replace = params.get("replace", False)
    if not isinstance(replace, bool):
        raise OptionError(f"replace={replace!r}: expected true or false", param="replace")
    data, source = params.get("data"), params.get("source")
    open_source(None if data is None else Path(data), source)  # validates the one given
    out = {"from": first.isoformat(), "to": last.isoformat(), "method": method,
           "replace": replace}
    out.update({"data": str(data)} if data is not None else {"source": source})
    return out


def deliver_job(engine: sa.Engine, job_id: str, params: dict, *, executor,
                progress: Callable[[float], None]) -> dict:
    """Fly ``params``' days (see :func:`check_params`) on ``executor``; the summary of
    :func:`summarise` with ``from`` and ``to``. ``progress`` gets the share of days
    done (stored or failed). Days that fail are :class:`DaysFailedError` once the
    others are stored: the job fails with one line naming them, and a defect's
    traceback goes to the ``skyroute.jobs`` logger."""
    p = check_params(params)
    data = p.get("data")
    src = open_source(None if data is None else Path(data), p.get("source"))
    first, last = dt.date.fromisoformat(p["from"]), dt.date.fromisoformat(p["to"])
    by_date = days_between(engine, first, last)
    site = load_site(src)
    refuse_foreign(site, by_date, stored_in=str(engine.url),
                   option="data folder (or source)",
                   param="data" if data is not None else "source")
    prepare_legs(site, [o for v in by_date.values() for o in v])
    done = 0

    def on_day(_r: DayResult | DayFailed) -> None:
        nonlocal done
        done += 1
        progress(done / len(by_date))

    try:
        results = run_days(engine, src, by_date, executor=executor, method=p["method"],
                           replace=p["replace"], on_day=on_day, on_failed=on_day)
    except store.DayKeptError as exc:  # the job's way to say what the CLI's --replace does
        raise SkyrouteError(f"{exc}; replace=true stores the day as flown now",
                            param="replace") from None
    except DaysFailedError as exc:
        for f in exc.failed:
            if not f.expected:  # the job's error is one line: the rest goes to the log
                log.error("job %s: %s\n%s", job_id, f.error, f.traceback.rstrip())
        raise
    return {"from": p["from"], "to": p["to"], **summarise(results)}
