"""``skyroute fleet``: simulate a fleet, write a scenario to edit, sweep settings."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from skyroute.cli.executor_args import (
    DaskAddress,
    Executor,
    executor_kind,
    executor_warnings,
    open_from_flags,
)
from skyroute.cli.parse import parse_items
from skyroute.cli.tables import plain_console, print_table, progress_bar, wide_console
from skyroute.errors import SEED_MAX, OptionError, SkyrouteError, check_choice, real
from skyroute.fleet.limits import MAX_DRONES, MAX_RATE, MAX_SEEDS, check_run, check_sweep
from skyroute.fleet.scenario import PRESETS, Scenario, generate, load_scenario, preset, to_yaml
from skyroute.io.json_text import to_json

fleet_app = typer.Typer(help="Fixed-wing drones carry packages between airports: simulate, "
                             "write scenarios, sweep settings.", no_args_is_help=True)

SCHEDULERS = ("seed", "optimal")
AIRSPACES = ("layers", "shared")
_PRESET_HELP = "One of the seed's set-ups: " + ", ".join(PRESETS) + "."

ScenarioFile = Annotated[Path | None, typer.Argument(
    metavar="[SCENARIO]", help="Scenario file (.yaml, .yml or .toml); see 'fleet scenario'.")]
Preset = Annotated[str | None, typer.Option(help=_PRESET_HELP)]
Airports = Annotated[int | None, typer.Option(help="Generate a scenario with N airports.")]
Drones = Annotated[int | None, typer.Option(help="Number of drones (overrides the scenario's).")]
AreaKm = Annotated[float, typer.Option(help="Side of the square the airports are spread over "
                                            "(generated scenarios).")]
Hours = Annotated[float, typer.Option(help="Simulated hours.")]
Seed = Annotated[int, typer.Option(min=0, max=SEED_MAX, help="Seed of the package stream "
                                   "(and of a generated scenario's layout).")]


def resolve_scenario(path: Path | None, preset_name: str | None, airports: int | None,
                     drones: int | None, area_km: float, seed: int) -> Scenario:
    """The scenario from exactly one of a file, a preset or ``--airports``; ``--drones``
    overrides the drone count of any."""
    given = [x for x in (path, preset_name, airports) if x is not None]
    if len(given) != 1:
        raise OptionError("give exactly one of SCENARIO, --preset or --airports (with "
                          "--drones)")
    if drones is not None and not 1 <= drones <= MAX_DRONES:
        raise OptionError(f"--drones {drones} must be 1 to {MAX_DRONES:,}")
    if path is not None:
        s = load_scenario(path)
    elif preset_name is not None:
        s = preset(preset_name)
    else:
        if drones is None:
            raise OptionError("--airports needs --drones")
        s = generate(airports, drones, area_km=area_km, seed=seed)
    if drones is not None and drones != s.drones:
        s = s.model_copy(update={"drones": drones})  # more drones: higher layers
    from skyroute.fleet.airborne import check_flights

    check_flights(s, scenario_name(path, s))
    return s


def scenario_name(path: Path | None, s: Scenario) -> Path | str:
    """What an error about the scenario names: its file, else its name (a preset's)."""
    return path if path is not None else s.name


def _with_separation(s: Scenario, sep_h: float | None, sep_v: float | None) -> Scenario:
    change = {k: real(k, v, low=0.0, strict=True)
              for k, v in (("sep_horizontal", sep_h), ("sep_vertical", sep_v))
              if v is not None}
    if not change:
        return s
    return s.model_copy(update={"airspace": s.airspace.model_copy(update=change)})



@fleet_app.command("simulate")
def simulate_command(
    scenario: ScenarioFile = None,
    preset_name: Annotated[str | None, typer.Option("--preset", help=_PRESET_HELP)] = None,
    airports: Airports = None,
    drones: Drones = None,
    area_km: AreaKm = 8.0,
    hours: Hours = 4.0,
    rate: Annotated[float | None, typer.Option(
        help="Packages offered per hour (default the scenario's).")] = None,
    seed: Seed = 0,
    scheduler: Annotated[str, typer.Option(help="seed (the KU Leuven rule) or optimal.")] =
        "seed",
    airspace: Annotated[str | None, typer.Option(
        help="layers (each drone its own level) or shared (levels by direction, 4D "
             "reservations); default the scenario's.")] = None,
    sep_horizontal: Annotated[float | None, typer.Option(
        help="Horizontal separation minimum, m (default the scenario's, 50).")] = None,
    sep_vertical: Annotated[float | None, typer.Option(
        help="Vertical separation minimum, m (default the scenario's, 10).")] = None,
    track_step: Annotated[float, typer.Option(help="Seconds between rows of tracks.csv.")] =
        1.0,
    out: Annotated[Path | None, typer.Option(
        help="Folder for report.json, events.jsonl, tracks.csv, packages.csv, "
             "fleet.geojson (and the PNGs with --plot).")] = None,
    plot: Annotated[bool, typer.Option(help="Draw map.png and timeline.png into --out.")] =
        False,
    as_json: Annotated[bool, typer.Option("--json", help="Print the report as JSON.")] = False,
) -> None:
    """Simulate a fleet for some hours; report throughput, delivery times and separation.

    Exits 1 when the independent checker finds a loss of separation or a package is lost.
    """
    from skyroute.fleet.report import report
    from skyroute.fleet.simulate import check_levels, run

    check_choice("scheduler", scheduler, SCHEDULERS)
    if airspace is not None:
        check_choice("airspace", airspace, AIRSPACES)
    hours = real("hours", hours, low=0.0, strict=True)
    rate = None if rate is None else real("rate_per_hour", rate, low=0.0)
    track_step = real("track_step", track_step, low=0.0, strict=True)
    if plot and out is None:
        raise OptionError("--plot needs --out DIR (the folder for map.png and timeline.png)")
    s = _with_separation(resolve_scenario(scenario, preset_name, airports, drones, area_km,
                                          seed), sep_horizontal, sep_vertical)
    # the packages (rate x hours; a package CSV's rows are counted as it is read) and
    # the tracks.csv rows, within the limits, before any work
    check_run(drones=s.drones, hours=hours, rate_given=rate is not None,
              rate_per_hour=rate if rate is not None or s.packages.csv is not None
              else s.packages.rate_per_hour,
              track_step=track_step if out is not None else None)
    # every level's take-off roll on every runway, before the bar
    check_levels(s, airspace, where=scenario_name(scenario, s))
    if out is not None:  # a bad --out fails before the run, not after it with some files
        from skyroute.io.fleet_out import check_run_outputs

        check_run_outputs(out, plot=plot)
    err = plain_console(stderr=True)
    files: list[Path] = []
    with progress_bar(err) as progress:
        task = progress.add_task("simulated seconds", total=round(hours * 3600))
        sim = run(s, hours=hours, seed=seed, scheduler=scheduler, airspace=airspace,
                  rate_per_hour=rate, base=scenario.parent if scenario else None,
                  progress=lambda t: progress.update(task, completed=round(t)))
        # the later phases have no count: a moving bar, not a full one at 0:00:00
        progress.remove_task(task)
        phase = progress.add_task("separation check", total=None)
        rep = report(sim)
        if out is not None:
            from skyroute.io.fleet_out import write_run

            progress.update(phase, description=f"writing {out}" + (" and the maps"
                                                                  if plot else ""))
            files = write_run(sim, rep, out, track_step=track_step, plot=plot)
    if as_json:
        typer.echo(to_json(rep))
    else:
        print_table(plain_console(), _report_table(rep, files))
    if rep["conflicts"] or rep["lost"]:
        plain_console(stderr=True).print(f"skyroute: {rep['conflicts']} loss(es) of "
                                         f"separation, {rep['lost']} lost package(s)")
        raise typer.Exit(1)


def _fmt(x, spec: str = ".1f", unit: str = "") -> str:
    return "-" if x is None else f"{x:{spec}}{unit}"


def _report_table(rep: dict, files: list[Path]) -> Table:
    st = rep["settings"]
    t = Table(title=f"fleet {st['scenario']}: {st['drones']} drones, {st['airports']} "
                    f"airports, {st['hours']:g} h, {st['scheduler']} + {st['airspace']}, "
                    f"seed {st['seed']}", show_header=False)
    t.add_column(style="bold")
    t.add_column(overflow="fold")  # a long file path folds; numbers stay whole
    rows = [
        ("offered", f"{rep['offered']:,} ({rep['offered_per_hour']:,.1f}/h after the "
                    f"{st['warmup_s'] / 60:g} min warm-up)"),
        ("delivered", f"{rep['delivered']:,} ({rep['delivered_per_hour']:,.1f}/h, served "
                      f"{_fmt(rep['served_share'], '.1%')})"),
        ("capacity bound", _fmt(rep["capacity_bound_per_hour"], ",.1f", "/h")
         + f" (mean cycle {_fmt(rep['mean_cycle_s'], ',.0f', ' s')}, drones busy "
           f"{_fmt(rep['busy_share'], '.1%')})"),
        ("delivery time p50 / p95", f"{_fmt(rep['p50_delivery_s'], ',.0f', ' s')} / "
                                    f"{_fmt(rep['p95_delivery_s'], ',.0f', ' s')}"),
        ("longest wait", _fmt(rep["max_wait_s"], ",.0f", " s")),
        ("loiter circles", f"{rep['loiters']:,} ({rep['loiter_s']:,.0f} s)"),
        ("flights", f"{rep['flights']:,} ({rep['reposition_flights']:,} empty "
                    "repositioning)"),
        ("conflicts", f"{rep['conflicts']:,}"),
        # each least distance is taken while the other is under its minimum
        ("closest pair", f"{_fmt(rep['min_horizontal_m'], ',.1f', ' m')} horizontally within "
                         f"{st['sep_vertical']:g} m vertically; "
                         f"{_fmt(rep['min_vertical_m'], ',.1f', ' m')} vertically within "
                         f"{st['sep_horizontal']:g} m horizontally"),
        ("lost packages", f"{rep['lost']:,}"),
        ("wall time", f"{rep['wall_seconds']:,.2f} s "
                      f"({_fmt(rep['sim_seconds_per_wall_second'], ',.0f')} simulated s/s)"),
    ]
    rows += [("file", str(p)) for p in files]
    for k, v in rows:
        t.add_row(k, v)
    return t


@fleet_app.command("scenario")
def scenario_command(
    airports: Annotated[int, typer.Option(help="Number of airports (>= 2).")],
    drones: Annotated[int, typer.Option(help="Number of drones (>= 1).")],
    area_km: AreaKm = 8.0,
    seed: Seed = 0,
    rate: Annotated[float | None, typer.Option(
        help="Packages offered per hour (default 20 per airport).")] = None,
) -> None:
    """Print a valid scenario as YAML, every field with its default, ready to edit."""
    typer.echo(to_yaml(generate(airports, drones, area_km=area_km, seed=seed,
                                rate_per_hour=rate)), nl=False)


def parse_seeds(text: str) -> list[int]:
    """``"0-29"``, ``"1,4,7"`` or a mix -> the seeds, in order, no repeats."""
    out: list[int] = []
    for part in parse_items(text, "--seeds"):
        try:
            if "-" in part[1:]:
                a, b = part.split("-", 1) if not part.startswith("-") else (part, "")
                lo, hi = int(a), int(b)
                if hi < lo:
                    raise ValueError
            else:
                lo = hi = int(part)
        except ValueError:
            raise OptionError(f"--seeds {text!r}: expected seeds like 0-29 or 1,4,7") from None
        if hi - lo >= MAX_SEEDS:  # before the list is made: 0-999999999 filled memory
            raise OptionError(f"--seeds {text!r}: {part} is {hi - lo + 1:,} seeds, over the "
                              f"limit of {MAX_SEEDS:,}")
        out += range(lo, hi + 1)
    if not out:
        raise OptionError(f"--seeds {text!r}: no seed given")
    bad = next((x for x in out if not 0 <= x <= SEED_MAX), None)
    if bad is not None:  # --seed's range and words (click's), for each seed of --seeds
        raise OptionError(f"--seeds {text!r}: {bad} is not in the range 0<=x<={SEED_MAX}")
    seeds = list(dict.fromkeys(out))
    if len(seeds) > MAX_SEEDS:
        raise OptionError(f"--seeds {text!r}: {len(seeds):,} seeds, over the limit of "
                          f"{MAX_SEEDS:,}")
    return seeds


def _choices(text: str, option: str, valid: tuple[str, ...]) -> list[str]:
    items = parse_items(text, option)
    for x in items:
        if x not in valid:
            raise OptionError(f"{option} {x!r} is not valid; choose from "
                              + ", ".join(valid))
    if not items:
        raise OptionError(f"{option}: give at least one of " + ", ".join(valid))
    return list(dict.fromkeys(items))


def _rates(text: str | None) -> list[float | None]:
    if text is None:
        return [None]
    items = parse_items(text, "--rates")  # an OptionError, itself a ValueError
    try:
        rates = [float(p) for p in items]
    except ValueError:
        raise OptionError(f"--rates {text!r}: expected numbers like 30,60,90") from None
    if not rates or not all(math.isfinite(r) and r >= 0 for r in rates):
        raise OptionError(f"--rates {text!r}: expected numbers >= 0 like 30,60,90")
    if max(rates) > MAX_RATE:
        raise OptionError(f"--rates {text!r}: {max(rates):g} is over the limit of "
                          f"{MAX_RATE:,g} packages per hour")
    return rates


@fleet_app.command("sweep")
def sweep_command(
    scenario: ScenarioFile = None,
    preset_name: Annotated[str | None, typer.Option("--preset", help=_PRESET_HELP)] = None,
    airports: Airports = None,
    drones: Drones = None,
    area_km: AreaKm = 8.0,
    scheduler: Annotated[str, typer.Option(help="Comma-separated: seed,optimal.")] =
        "seed,optimal",
    airspace: Annotated[str, typer.Option(help="Comma-separated: layers,shared.")] =
        "layers,shared",
    rates: Annotated[str | None, typer.Option(
        help="Comma-separated packages per hour (default the scenario's).")] = None,
    seeds: Annotated[str, typer.Option(help="Seeds, like 0-29 or 1,4,7.")] = "0-9",
    hours: Hours = 4.0,
    jobs: Annotated[int, typer.Option(help="Worker processes.")] = 1,
    executor: Executor = None,
    dask: DaskAddress = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print the rows as JSON.")] = False,
) -> None:
    """Run every scheduler x airspace x rate on every seed (the same package streams for
    each setting); one table of means with 95% confidence intervals."""
    from skyroute.fleet.simulate import check_levels
    from skyroute.jobs.fleet import RunsLostError, sweep

    scheds = _choices(scheduler, "--scheduler", SCHEDULERS)
    spaces = _choices(airspace, "--airspace", AIRSPACES)
    rate_list = _rates(rates)
    seed_list = parse_seeds(seeds)
    hours = real("hours", hours, low=0.0, strict=True)
    runs = check_sweep(schedulers=len(scheds), airspaces=len(spaces), rates=len(rate_list),
                       seeds=len(seed_list), fewer="--seeds, --rates, --scheduler or "
                       "--airspace")
    executor_kind(executor, dask, jobs)
    s = resolve_scenario(scenario, preset_name, airports, drones, area_km, 0)
    if scenario is not None and s.packages.csv is not None:
        raise OptionError("sweep runs Poisson streams; this scenario names a package CSV")
    for mode in spaces:  # every level's take-off roll on every runway
        check_levels(s, mode, where=scenario_name(scenario, s))
    for r in rate_list:  # each run's packages (rate x hours) within the limit
        check_run(drones=s.drones, hours=hours, rate_given=r is not None, rate_name="rates",
                  rate_per_hour=s.packages.rate_per_hour if r is None else r)
    err = plain_console(stderr=True)
    lost: list[dict] = []  # runs whose worker died each time: said after the rows
    with progress_bar(err) as progress:
        task = progress.add_task("runs", total=runs)
        with open_from_flags(executor, dask, jobs, runs) as ex, \
                executor_warnings(progress.console):  # e.g. a worker process died
            try:
                rows = sweep(s, schedulers=scheds, airspaces=spaces, rates=rate_list,
                             seeds=seed_list, hours=hours, executor=ex,
                             on_result=lambda _i, _rep: progress.advance(task))
            except RunsLostError as exc:
                rows, lost = exc.rows, exc.lost
    if as_json:
        doc = {"scenario": s.name, "hours": hours, "seeds": seed_list, "rows": rows}
        typer.echo(to_json({**doc, "lost": lost} if lost else doc))  # NaN: null
    elif rows:
        print_table(wide_console(), _sweep_table(s, hours, seed_list, rows),
                    optional=_SWEEP_OPTIONAL)
    if lost:
        _say_lost(lost, runs)
    if any(r["conflicts"] or r["lost"] for r in rows):
        raise typer.Exit(1)


def _say_lost(lost: list[dict], runs: int) -> None:
    """The runs lost (their worker process died each time they were tried), after the
    rows of the others: one line each on stderr, then how many, and exit 2 (as
    ``deliver`` says its lost days)."""
    for x in lost:
        typer.echo(f"skyroute: error: {x['error']}", err=True)
    n, rest = len(lost), runs - len(lost)
    raise SkyrouteError(f"all {runs:,} runs were lost; there are no rows" if not rest else
                        f"{n:,} of the {runs:,} runs {'was' if n == 1 else 'were'} lost; "
                        f"the rows are over the other {rest:,} (a row's runs count "
                        "them)")


# Units under the names, so a header is no wider than its numbers; the last ones give way
# first on a narrow terminal (print_table's optional columns).
_SWEEP_COLUMNS = ("scheduler", "airspace", "offered\n/h", "delivered\n/h", "served\n%",
                  "p95\ns", "max wait\ns", "loiters", "capacity\n/h", "conflicts", "lost")
_SWEEP_OPTIONAL = ("max wait\ns", "capacity\n/h", "loiters")


def _sweep_table(s: Scenario, hours: float, seeds: list[int], rows: list[dict]) -> Table:
    t = Table(title=f"fleet sweep {s.name}: {s.drones} drones, {len(s.airports)} airports, "
                    f"{hours:g} h x {len(seeds)} seeds (mean ±95% CI)")
    # a row over fewer runs than seeds (runs lost: their worker died) says so
    short = any(r["runs"] < len(seeds) for r in rows)
    columns = (*_SWEEP_COLUMNS[:2], "runs", *_SWEEP_COLUMNS[2:]) if short else _SWEEP_COLUMNS
    for col in columns:
        # a cell wraps before its "±" on a narrow terminal (print_table keeps words whole)
        t.add_column(col, justify="left" if col in ("scheduler", "airspace") else "right")

    def pm(r, m, spec, scale=1.0):
        v, ci = r[m], r[m + "_ci95"]
        if v is None or (isinstance(v, float) and math.isnan(v)):
            return "-"
        text = f"{v * scale:{spec}}"
        return text if ci is None or math.isnan(ci) else f"{text} ±{ci * scale:{spec}}"

    for r in rows:
        runs = (f"{r['runs']:,}",) if short else ()
        t.add_row(r["scheduler"], r["airspace"], *runs, _fmt(r["rate_per_hour"], ",.0f"),
                  pm(r, "delivered_per_hour", ",.1f"), pm(r, "served_share", ".1f", 100.0),
                  pm(r, "p95_delivery_s", ",.0f"), pm(r, "max_wait_s", ",.0f"),
                  pm(r, "loiters", ",.0f"), pm(r, "capacity_bound_per_hour", ",.1f"),
                  f"{r['conflicts']:,}", f"{r['lost']:,}")
    return t
