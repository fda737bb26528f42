"""Fleet runs and sweeps as tasks, on any executor with the same reports.

What a worker gets: a :class:`RunSpec`, the scenario as plain data (``model_dump``) with
the hours, seed, scheduler, airspace and rate. A sweep's worker sends the run's report
back (:func:`simulate_report`); the caller turns the reports into means with 95%
confidence intervals (:func:`sweep_rows`). A fleet run's worker (:func:`fly_fleet`) also
stores the run in ``fleet_runs`` itself, in one transaction under an id the caller chose,
so a run re-run after its worker died replaces itself; it sends back the id and report.
The run of a job failed meanwhile (an orphan of a stalled server) is not stored: the
worker's save raises :class:`~skyroute.jobs.store.JobEndedError`, and a run saved just
before the failure is deleted by it.
``skyroute fleet sweep`` and the runner's ``sweep`` job call the same :func:`sweep`.
"""

from __future__ import annotations

import math
import uuid
from collections.abc import Callable
from dataclasses import dataclass

import sqlalchemy as sa

from skyroute.errors import (
    InputFormatError,
    OptionError,
    SkyrouteError,
    check_choice,
    check_seed,
    real,
)
from skyroute.fleet.airborne import check_flights
from skyroute.fleet.airspace import MODES
from skyroute.fleet.dispatch import SCHEDULERS
from skyroute.fleet.limits import MAX_SEEDS, check_run, check_sweep
from skyroute.fleet.packages import check_hours
from skyroute.fleet.report import report
from skyroute.fleet.scenario import Scenario, parse_scenario, preset
from skyroute.fleet.simulate import check_levels, run
from skyroute.io.fleet_out import events_jsonl, fleet_geojson, packages_csv, tracks_csv
from skyroute.io.geojson import dumps
from skyroute.jobs import store
from skyroute.jobs.executor import TasksLostError

SWEEP_METRICS = ("delivered_per_hour", "served_share", "p95_delivery_s", "max_wait_s",
                 "loiters", "capacity_bound_per_hour")


@dataclass(frozen=True)
class RunSpec:
    """One fleet run for a worker: the scenario as plain data and the run's settings."""

    scenario: dict
    hours: float
    seed: int = 0
    scheduler: str = "seed"
    airspace: str | None = None
    rate_per_hour: float | None = None


def _simulate(spec: RunSpec):
    return run(Scenario.model_validate(spec.scenario), hours=spec.hours, seed=spec.seed,
               scheduler=spec.scheduler, airspace=spec.airspace,
               rate_per_hour=spec.rate_per_hour)


def simulate_report(spec: RunSpec) -> dict:
    """A sweep's task: one run's report (:func:`skyroute.fleet.report.report`)."""
    return report(_simulate(spec))


def mean_ci(values: list[float]) -> tuple[float, float]:
    """Mean and the half-width of its 95% confidence interval (Student's t); None values
    are left out, NaN when nothing (or, for the interval, one value) is left."""
    from scipy.stats import t as student

    x = [v for v in values if v is not None]
    if not x:
        return math.nan, math.nan
    m = sum(x) / len(x)
    if len(x) < 2:
        return m, math.nan
    sd = math.sqrt(sum((v - m) ** 2 for v in x) / (len(x) - 1))
    return m, float(student.ppf(0.975, len(x) - 1)) * sd / math.sqrt(len(x))


def sweep_specs(scenario: Scenario, *, schedulers, airspaces, rates, seeds,
                hours: float) -> tuple[list[tuple], list[RunSpec]]:
    """The settings (scheduler, airspace, rate), rates outermost, and one run per
    setting and seed, settings outermost (the same package streams for each setting)."""
    for sc in schedulers:
        check_choice("scheduler", sc, SCHEDULERS)
    for sp in airspaces:
        check_choice("airspace", sp, MODES)
    data = scenario.model_dump()
    configs = [(sc, sp, r) for r in rates for sc in schedulers for sp in airspaces]
    specs = [RunSpec(data, hours, seed, sc, sp, r) for sc, sp, r in configs for seed in seeds]
    return configs, specs


def sweep_rows(configs: list[tuple], n_seeds: int, reports: list[dict | None]) -> list[dict]:
    """One row per setting: runs, total conflicts and lost packages, and the mean and
    ``_ci95`` half-width of each of :data:`SWEEP_METRICS` (NaN where undefined). A
    report None (a run lost: its worker died) is left out, so ``runs`` counts those
    that finished; a setting none of whose runs finished has no row."""
    rows = []
    for k, (sc, sp, _) in enumerate(configs):
        reps = [x for x in reports[k * n_seeds:(k + 1) * n_seeds] if x is not None]
        if not reps:
            continue
        row = {"scheduler": sc, "airspace": sp,
               "rate_per_hour": reps[0]["settings"]["rate_per_hour"], "runs": len(reps),
               "conflicts": sum(x["conflicts"] for x in reps),
               "lost": sum(x["lost"] for x in reps)}
        for m in SWEEP_METRICS:
            row[m], row[m + "_ci95"] = mean_ci([x[m] for x in reps])
        rows.append(row)
    return rows


class RunsLostError(SkyrouteError):
    """Runs of a sweep whose worker process died under them every time they were tried
    (:class:`~skyroute.jobs.executor.TasksLostError`); every other run finished.
    ``rows``: :func:`sweep_rows` over the runs that finished (``runs`` counts them; a
    setting without any has no row); ``lost``: one dict per lost run, in sweep order,
    with its ``scheduler``, ``airspace``, ``rate_per_hour`` (as in the rows), ``seed``
    and ``error`` (one line naming the run, :func:`lost_line`); ``runs``: how
    many runs the sweep had. The message is one line: how many were lost, and the first."""

    def __init__(self, rows: list[dict], lost: list[dict], runs: int) -> None:
        self.rows, self.lost, self.runs = rows, lost, runs
        n = len(lost)
        super().__init__(f"{n:,} of the {runs:,} runs {'was' if n == 1 else 'were'} lost "
                         f"and left out of the rows: {lost[0]['error']}"
                         + (f"; and {n - 1:,} more" if n > 1 else ""))

    def job_result(self) -> dict:
        """What a failed sweep job keeps as its result: the rows that finished and the
        lost runs."""
        return {"rows": self.rows, "lost": self.lost}


def lost_line(spec: RunSpec, why: str) -> str:
    """A lost run named by its setting and seed: ``scheduler seed, airspace shared, rate
    60/h, seed 3: its worker process died (...)`` (the rate only when the sweep gives
    rates)."""
    rate = "" if spec.rate_per_hour is None else f", rate {spec.rate_per_hour:g}/h"
    return (f"scheduler {spec.scheduler}, airspace {spec.airspace}{rate}, "
            f"seed {spec.seed}: {why}")


def sweep(scenario: Scenario, *, schedulers=SCHEDULERS, airspaces=MODES,
          rates=(None,), seeds=range(10), hours: float, executor,
          on_result: Callable[[int, dict], None] | None = None) -> list[dict]:
    """Every scheduler x airspace x rate on every seed, one task per run on ``executor``
    (``rates`` None: the scenario's); the rows of :func:`sweep_rows`.

    A run whose worker died every time it was tried does not end the sweep: the others
    run, then :class:`RunsLostError` is raised with the rows of those that finished
    and the lost runs."""
    if scenario.packages.csv is not None:
        raise OptionError("a sweep runs Poisson streams; this scenario names a package CSV",
                          param="scenario")
    seeds = list(seeds)
    check_sweep(schedulers=len(schedulers), airspaces=len(airspaces), rates=len(rates),
                seeds=len(seeds))
    configs, specs = sweep_specs(scenario, schedulers=schedulers, airspaces=airspaces,
                                 rates=rates, seeds=seeds, hours=hours)
    try:
        reports = executor.map(simulate_report, specs, on_result=on_result)
    except TasksLostError as exc:
        lost = [{"scheduler": specs[i].scheduler, "airspace": specs[i].airspace,
                 "rate_per_hour": (scenario.packages.rate_per_hour
                                   if specs[i].rate_per_hour is None
                                   else specs[i].rate_per_hour), "seed": specs[i].seed,
                 "error": lost_line(specs[i], why)} for i, why in exc.lost.items()]
        raise RunsLostError(sweep_rows(configs, len(seeds), exc.results), lost,
                            len(specs)) from None
    return sweep_rows(configs, len(seeds), reports)


@dataclass(frozen=True)
class FleetTask:
    """A fleet run for a worker to simulate and store under ``run_id``."""

    url: str
    run_id: str
    job_id: str | None
    spec: RunSpec
    track_step: float = 1.0


def fly_fleet(task: FleetTask) -> dict:
    """The worker's task: simulate, report, store the run (report, events.jsonl,
    tracks.csv, packages.csv, fleet.geojson) in one transaction; ``{"id", "report"}``."""
    sim = _simulate(task.spec)
    rep = report(sim)
    s = task.spec
    params = {"scenario": s.scenario, "hours": s.hours, "seed": s.seed,
              "scheduler": s.scheduler, "airspace": sim.airspace,
              "rate_per_hour": s.rate_per_hour, "track_step": task.track_step}
    store.save_fleet_run(store.engine_for(task.url), run_id=task.run_id, job_id=task.job_id,
                         scenario=sim.scenario.name, params=params, report=rep,
                         events_jsonl=events_jsonl(sim),
                         tracks_csv=tracks_csv(sim, task.track_step),
                         packages_csv=packages_csv(sim),
                         fleet_geojson=dumps(fleet_geojson(sim)))
    return {"id": task.run_id, "report": rep}


# -- the runner's "fleet" and "sweep" jobs -------------------------------------------------

def _rate(key: str, value) -> float:
    """A rate in packages per hour (the bound is :func:`check_run`'s)."""
    return real(key, value, low=0.0, need="a number >= 0")


def _scenario(params: dict) -> tuple[Scenario, dict]:
    given = [k for k in ("preset", "scenario") if params.get(k) is not None]
    if len(given) != 1:
        raise OptionError("give exactly one of preset (a name) or scenario (its fields)",
                          param="scenario")
    if given[0] == "preset":
        s = preset(params["preset"])
        kept = {"preset": params["preset"]}
    else:
        try:
            s = parse_scenario(params["scenario"], "scenario")
            check_flights(s, "scenario")
        except InputFormatError as exc:  # "scenario: airports[1].north: ..."
            raise OptionError(str(exc), param="scenario") from None
        kept = {"scenario": s.model_dump()}
    if s.packages.csv is not None:
        raise OptionError("scenario.packages.csv: a job runs Poisson streams; leave the "
                          "package CSV out", param="scenario")
    return s, kept


def _where(kept: dict) -> str:
    """What an error about the job's scenario names (as :func:`_scenario`'s do):
    ``scenario`` for one given by its fields, else the preset's name."""
    return "scenario" if "scenario" in kept else kept["preset"]


def _list(params: dict, key: str, default: tuple, valid: tuple) -> list:
    v = params.get(key, list(default))
    if not isinstance(v, list | tuple) or not v:
        raise OptionError(f"{key}={v!r} must be a non-empty list", param=key)
    for x in v:
        check_choice(key, x, valid)
    return list(dict.fromkeys(v))


def check_fleet_params(params: dict) -> dict:
    """The ``fleet`` job's parameters checked and completed: ``preset`` (a name) or
    ``scenario`` (its fields, as in a scenario file), ``hours`` (default 1), ``seed``
    (0), ``scheduler`` (``seed``), ``airspace`` (the scenario's), ``rate_per_hour``
    (the scenario's), ``track_step`` (1 s). Errors name the field."""
    _known(params, {"preset", "scenario", "hours", "seed", "scheduler", "airspace",
                    "rate_per_hour", "track_step"}, "fleet")
    s, out = _scenario(params)
    out["hours"] = check_hours(params.get("hours", 1.0))  # as simulate reads it
    out["seed"] = check_seed(params.get("seed", 0))
    out["scheduler"] = params.get("scheduler", "seed")
    check_choice("scheduler", out["scheduler"], SCHEDULERS)
    out["airspace"] = params.get("airspace", s.airspace.mode)
    check_choice("airspace", out["airspace"], MODES)
    check_levels(s, out["airspace"], where=_where(out))
    rate = params.get("rate_per_hour")
    out["rate_per_hour"] = None if rate is None else _rate("rate_per_hour", rate)
    out["track_step"] = real("track_step", params.get("track_step", 1.0), low=0.0,
                             strict=True)
    rate = out["rate_per_hour"]
    check_run(drones=s.drones, hours=out["hours"], track_step=out["track_step"],
              rate_per_hour=s.packages.rate_per_hour if rate is None else rate,
              rate_given=rate is not None)
    return out


def check_sweep_params(params: dict) -> dict:
    """The ``sweep`` job's parameters: ``preset`` or ``scenario``, ``schedulers`` and
    ``airspaces`` (lists, default both), ``rates`` (packages per hour, default the
    scenario's), ``seeds`` (default 0..9), ``hours`` (default 1)."""
    _known(params, {"preset", "scenario", "schedulers", "airspaces", "rates", "seeds",
                    "hours"}, "sweep")
    s, out = _scenario(params)
    out["schedulers"] = _list(params, "schedulers", SCHEDULERS, SCHEDULERS)
    out["airspaces"] = _list(params, "airspaces", MODES, MODES)
    for mode in out["airspaces"]:
        check_levels(s, mode, where=_where(out))
    rates = params.get("rates")
    if rates is not None:
        if not isinstance(rates, list | tuple) or not rates:
            raise OptionError(f"rates={rates!r} must be a non-empty list", param="rates")
        rates = [_rate("rates", r) for r in rates]
    out["rates"] = rates
    seeds = params.get("seeds", list(range(10)))
    if not isinstance(seeds, list | tuple) or not seeds:
        raise OptionError(f"seeds={seeds!r} must be a non-empty list", param="seeds")
    if len(seeds) > MAX_SEEDS:
        raise OptionError(f"seeds: {len(seeds):,} seeds is over the limit of {MAX_SEEDS:,}",
                          param="seeds")
    out["seeds"] = list(dict.fromkeys(check_seed(x, "seeds") for x in seeds))
    out["hours"] = check_hours(params.get("hours", 1.0))  # as simulate reads it
    check_sweep(schedulers=len(out["schedulers"]), airspaces=len(out["airspaces"]),
                rates=len(rates or [None]), seeds=len(out["seeds"]))
    for rate in rates or [s.packages.rate_per_hour]:
        check_run(drones=s.drones, hours=out["hours"], rate_per_hour=rate,
                  rate_given=rates is not None, rate_name="rates")
    return out


def _known(params, keys: set[str], kind: str) -> None:
    if not isinstance(params, dict):
        raise OptionError("params must be a mapping", param="params")
    unknown = sorted(set(params) - keys)
    if unknown:
        raise OptionError(f"{unknown[0]}: unknown parameter of a {kind} job; valid: "
                          + ", ".join(sorted(keys)), param=unknown[0])


def _resolve(p: dict) -> Scenario:
    return preset(p["preset"]) if "preset" in p else Scenario.model_validate(p["scenario"])


def fleet_job(engine: sa.Engine, job_id: str, params: dict, *, executor,
              progress: Callable[[float], None]) -> dict:
    """One fleet run as one task (see :func:`check_fleet_params`), stored in
    ``fleet_runs`` with this job's id; ``{"fleet_run": id, "report": {...}}``."""
    p = check_fleet_params(params)
    spec = RunSpec(_resolve(p).model_dump(), p["hours"], p["seed"], p["scheduler"],
                   p["airspace"], p["rate_per_hour"])
    task = FleetTask(store.worker_url(engine), str(uuid.uuid4()), job_id, spec, p["track_step"])
    try:
        (out,) = executor.map(fly_fleet, [task])
    except TasksLostError as exc:  # "1 of the 1 tasks was lost: task 0: ..."
        raise SkyrouteError(f"the fleet run was lost: {exc.lost[0]}") from None
    progress(1.0)
    return {"fleet_run": out["id"], "report": out["report"]}


def sweep_job(engine: sa.Engine, job_id: str, params: dict, *, executor,
              progress: Callable[[float], None]) -> dict:
    """A sweep (see :func:`check_sweep_params`), one task per run; ``{"rows": [...]}``
    as :func:`sweep` gives them (NaN stored as null). Nothing per run is stored. Runs
    lost (:class:`RunsLostError`) fail the job once the others have run, keeping
    ``{"rows", "lost"}`` as its result."""
    p = check_sweep_params(params)
    rates = p["rates"] or [None]
    total = len(p["schedulers"]) * len(p["airspaces"]) * len(rates) * len(p["seeds"])
    done = 0

    def on_result(_i: int, _rep: dict) -> None:
        nonlocal done
        done += 1
        progress(done / total)

    try:
        rows = sweep(_resolve(p), schedulers=p["schedulers"], airspaces=p["airspaces"],
                     rates=rates, seeds=p["seeds"], hours=p["hours"], executor=executor,
                     on_result=on_result)
    except RunsLostError:  # every run has ended, finished or lost: the job fails with
        progress(1.0)  # the rows that finished (RunsLostError.job_result)
        raise
    return {"rows": rows}
