"""``skyroute fly``: turn a start and a goal into what a vehicle can fly."""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.table import Table

from skyroute.cli import world_args as wa
from skyroute.cli.parse import check_outputs
from skyroute.cli.status import delayed_status
from skyroute.cli.tables import plain_console, print_table
from skyroute.errors import OptionError, check_choice, real
from skyroute.files import read_text, write_atomic, written_together
from skyroute.io.geojson import dumps
from skyroute.io.json_text import to_json
from skyroute.planner import plan
from skyroute.result import PlanResult, Status
from skyroute.world.world import AXES

VEHICLES = ("step", "dubins", "lattice", "field")
PLANNERS = {"step": ("moves", "follow"), "dubins": ("hybrid", "waypoints")}  # default first
# The vehicles that use each vehicle option (by parameter name); the other options apply
# to every vehicle. An option given for a vehicle not listed is an error, never silently
# ignored (_check_vehicle_options), and its --help starts with the vehicles listed here.
TAKEN_BY = {
    "planner": ("step", "dubins"),
    "radius": ("dubins",),
    "start_heading": ("dubins", "lattice"),
    "goal_heading": ("dubins",),
    "approach": ("dubins",),
    "reverse": ("dubins",),
    "max_expansions": ("dubins",),
    "targets": ("dubins",),
    "headings": ("lattice",),
    "speed": ("lattice",),
    "turn_rate": ("lattice",),
    "resolution": ("lattice",),
    "step": ("dubins", "field"),
    "escape": ("field",),
    "sensor_range": ("field",),
    "sensor_rays": ("field",),
    "field_mode": ("field",),
    "max_turn": ("field",),
}
# Options a vehicle takes but one of its modes does not (mode: the dubins vehicle's
# --planner, or "targets" with --targets; the field's --field-mode): also errors when
# given (_check_mode_options).
UNUSED_IN_MODE = {
    ("dubins", "targets"): ("planner", "goal_heading", "approach", "reverse"),
    ("dubins", "waypoints"): ("approach", "reverse", "max_expansions"),
    ("field", "step"): ("max_turn",),
}
MODE_FLAG = {"targets": "--targets", "waypoints": "--planner waypoints",
             "step": "--field-mode step"}
EXIT_NOT_REACHED = 1
# The distance options' defaults, in metres (speed in metres per second): a value given
# is in the world's plane units (degrees in the degrees frame), a default is taken into
# them (World.metres_in_plane), so the defaults fit a world in every frame.
DEFAULT_METRES = {"radius": 10.0, "step": 1.0, "sensor_range": 6.0, "speed": 1.0}


def _for(option: str, text: str) -> str:
    """``option``'s help led by the vehicles that take it: ``"dubins: turning radius."``;
    a distance option's (DEFAULT_METRES) followed by its units and default."""
    if option in DEFAULT_METRES:
        per, unit = (" per second", "m/s") if option == "speed" else ("", "m")
        text += (f" Plane units{per} (degrees in the degrees frame); default "
                 f"{DEFAULT_METRES[option]:g} {unit} (its equivalent in degrees in the "
                 "degrees frame).")
    return f"{', '.join(TAKEN_BY[option])}: {text}"


def fly_command(
    ctx: typer.Context,
    world_file: wa.WorldFile,
    start: wa.StartPoint,
    goal: Annotated[str | None, typer.Option(
        "--goal", help="Same form as --start; required unless --targets is given.")] = None,
    vehicle: Annotated[str, typer.Option(
        help="step, dubins, lattice or field. An option whose help starts with vehicle "
             "names is for those vehicles alone: given with another, it is an error.")] = \
        "step",
    frame: wa.Frame = None,
    altitude: wa.Altitude = None,
    safety: wa.Safety = 0.0,
    boundary: wa.Boundary = None,
    planner: Annotated[str | None, typer.Option(help=_for(
        "planner", "for step, moves (fewest moves, A*; the default) or follow (round a "
                   "Theta* path); for dubins, hybrid (Hybrid A* among the obstacles; the "
                   "default) or waypoints (Dubins curves through the exact route's "
                   "corners, which may cut them: reports free)."))] = None,
    radius: Annotated[float | None, typer.Option(help=_for(
        "radius", "turning radius."))] = None,
    start_heading: Annotated[float | None, typer.Option(help=_for(
        "start_heading", "start heading, degrees in the frame's convention (clockwise from "
                         "north in lonlat and ned; anticlockwise from east in enu and "
                         "degrees); or give it as --start A,B,HEADING. dubins: free when "
                         "left out, but 0 with --targets; lattice: 0."))] = None,
    goal_heading: Annotated[float | None, typer.Option(help=_for(
        "goal_heading", "heading at the goal (degrees), or --goal A,B,HEADING; free when "
                        "left out."))] = None,
    approach: Annotated[float | None, typer.Option(help=_for(
        "approach", "the goal is a runway threshold with its heading; end with a straight "
                    "final approach this long along it."))] = None,
    reverse: Annotated[bool, typer.Option(
        "--reverse", help=_for("reverse", "the vehicle may also drive backwards (a "
                                          "car)."))] = False,
    max_expansions: Annotated[int | None, typer.Option(help=_for(
        "max_expansions", "Hybrid A*'s expansion budget (status budget_exhausted); default: "
        "enough to finish the search, capped at 10,000,000 (5,000,000 with --reverse) to "
        "protect memory."))] = None,
    targets: Annotated[Path | None, typer.Option(help=_for(
        "targets", "visit these targets (a .csv or .json of A,B points in --frame) in the "
                   "shortest order from START; GOAL is not used."))] = None,
    headings: Annotated[int, typer.Option(help=_for("headings", "8 or 16 headings."))] = 8,
    speed: Annotated[float | None, typer.Option(help=_for(
        "speed", "speed."))] = None,
    turn_rate: Annotated[float, typer.Option(help=_for(
        "turn_rate", "degrees per second."))] = 90.0,
    resolution: Annotated[float | None, typer.Option(help=_for(
        "resolution", "cell size."))] = None,
    step: Annotated[float | None, typer.Option(help=_for(
        "step", "sampling step (dubins), or move length, escape cell and goal tolerance "
                "(field)."))] = None,
    escape: Annotated[bool, typer.Option(help=_for(
        "escape", "follow a navigation function whenever the field cannot move on "
                  "(a local minimum, a blocked move)."))] = True,
    sensor_range: Annotated[float | None, typer.Option(help=_for(
        "sensor_range", "sensor range."))] = None,
    sensor_rays: Annotated[int, typer.Option(help=_for(
        "sensor_rays", "sensor rays (density)."))] = 36,
    field_mode: Annotated[str, typer.Option(help=_for(
        "field_mode", "step (jump along the force) or arc (turn-limited arcs, slower in "
                      "turns)."))] = "step",
    max_turn: Annotated[float, typer.Option(help=_for(
        "max_turn", "in arc mode, the largest heading change per move, degrees."))] = 45.0,
    out: Annotated[Path | None, typer.Option(help="Write moves or samples (.json, .csv, "
                                             ".geojson).")] = None,
    plot: Annotated[Path | None, typer.Option(help="Write a PNG map of the flight.")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Fly from START to GOAL (or round --targets) with a vehicle model; exit 1 when the
    goal is not reached.

    Points, headings and written trajectories are in --frame (headings in degrees); the
    step drone flies the ILP rules on the lon/lat plane whatever the frame, and writes
    its moves as ILP rows (from_lon, from_lat, angle, to_lon, to_lat).
    """
    check_choice("vehicle", vehicle, VEHICLES)
    _check_vehicle_options(ctx, vehicle)
    if vehicle in PLANNERS:
        planner = planner or PLANNERS[vehicle][0]
        check_choice("planner", planner, PLANNERS[vehicle])
    check_choice("field_mode", field_mode, ("step", "arc"))
    mode = "targets" if vehicle == "dubins" and targets is not None else \
        field_mode if vehicle == "field" else planner
    _check_mode_options(ctx, vehicle, mode)
    if out is not None and out.suffix.lower() not in (".json", ".csv", ".geojson"):
        raise OptionError(f"--out {out}: the suffix must be .json, .csv or .geojson")
    check_outputs(out=out, plot=plot)
    if radius is not None:  # checked before a long load; the others by the vehicles
        real("radius", radius, low=0.0, strict=True)
    # degrees here; the library's check speaks radians
    real("max_turn", max_turn, low=0.0, strict=True, high=180.0, need="in (0, 180] degrees")
    if goal is None and targets is None:
        raise OptionError("give --goal A,B (or --targets FILE with --vehicle dubins)")
    frame = wa.frame_of(frame)
    *a, h0 = wa.parse_pose(start, "--start", wa.point_names(frame))
    # With --targets the goal is not used; when given it is still checked as a point.
    *b, h1 = wa.parse_pose(goal, "--goal", wa.point_names(frame)) if goal is not None \
        else (math.nan, math.nan, None)
    _check_typed_heading(h0, start, "start", vehicle)
    _check_typed_heading(h1, goal, "goal", vehicle)
    h0 = _one_heading(h0, start_heading, "start")
    h1 = _one_heading(h1, goal_heading, "goal")
    with delayed_status("planning"):  # a first Dubins flight compiles for 10-20 s
        loaded = {"altitude": altitude, "safety": safety, "boundary": boundary, "frame": frame}
        world = wa.load_world_file(world_file, **loaded)
        # one error, in the user's frame, for every vehicle
        wa.check_points(world_file, world, {"start": a} if targets is not None else
                        {"start": a, "goal": b}, **loaded)
        radius, step, sensor_range, speed = (
            world.metres_in_plane(DEFAULT_METRES[name], near=a) if value is None else value
            for name, value in (("radius", radius), ("step", step),
                                ("sensor_range", sensor_range), ("speed", speed)))
        if vehicle == "step":
            world, a, b = world.in_frame("degrees"), world.to_lonlat(a)[0], world.to_lonlat(b)[0]
            doc, rows, xy = _fly_step(world, a, b, planner)
        elif vehicle == "dubins" and targets is not None:
            visits = _read_targets(targets)
            wa.check_points(world_file, world, {f"{targets.name}: target {i + 1}": p
                                                for i, p in enumerate(visits)}, **loaded)
            doc, rows, xy = _fly_tour(world, a, h0, visits, radius, step, max_expansions)
        elif vehicle == "dubins" and planner == "hybrid":
            doc, rows, xy = _fly_hybrid(world, a, b, h0, h1, radius, step, reverse,
                                        max_expansions, approach)
        elif vehicle == "dubins":
            doc, rows, xy = _fly_dubins(world, a, b, radius, h0, h1, step)
        elif vehicle == "lattice":
            doc, rows, xy = _fly_lattice(world, a, b, headings, speed, math.radians(turn_rate),
                                         h0 or 0.0, resolution)
        else:
            doc, rows, xy = _fly_field(world, a, b, step, escape, sensor_range, sensor_rays,
                                       field_mode, math.radians(max_turn))
    with written_together():  # both files or neither (a Ctrl-C while plotting)
        if out is not None and doc["reached"]:
            write_atomic(out, _render(out, rows, doc["columns"], world.to_lonlat(xy)))
        if plot is not None and doc["reached"]:
            from skyroute.io.world_out import obstacles_label, plot_world_path

            # The title shows the length the table and --json report (a Dubins path's
            # exact arcs); only a vehicle without one is measured along the drawn polyline,
            # which cuts the arcs between samples and comes out shorter.
            length = doc["metrics"].get("length")
            if length is None:
                plane = world.to_plane(xy)
                length = float(np.hypot(*np.diff(plane, axis=0).T).sum()) if len(xy) > 1 else 0.0
            shown = PlanResult(Status.FOUND, np.asarray(xy), length, algorithm=vehicle)
            # --safety is in the units of the frame loaded (metres after 'step' moved to degrees)
            # The goal as typed, where the start is: the step drone stops within a step
            # of it, a lattice at the centre of its nearest free cell, a field within a
            # tolerance (the goal was drawn where the vehicle stopped, and named so).
            # A tour has no goal: its targets are drawn instead.
            tour = targets is not None
            plot_world_path(world, shown, a, None if tour else b, plot,
                            obstacles=obstacles_label(altitude, safety, frame),
                            targets=visits if tour else None)
    if as_json:
        typer.echo(to_json({k: v for k, v in doc.items() if k != "columns"}))
    else:
        unit = "deg" if world.plane == "degrees" else "m"
        print_table(plain_console(), metrics_table(f"{world.name}: {vehicle}", doc, unit))
    if not doc["reached"]:
        raise typer.Exit(EXIT_NOT_REACHED)


# A metric's label in the table where it is not its --json key with spaces for the
# underscores ("escape_moves": "escape moves"): the step drone's length is in degrees,
# which its value says ("0.004650 deg"), as the other vehicles' "length" says metres.
LABELS = {"length_deg": "length"}


def metric_label(name: str) -> str:
    """A metric's label in the human table, as the other tables write theirs ("max
    frontier", "search time"); ``--json`` keeps the key (``escape_moves``)."""
    return LABELS.get(name, name.replace("_", " "))


def metrics_table(title: str, doc: dict, plane_unit: str) -> Table:
    """The table ``fly`` prints: each metric by its label (:func:`metric_label`) and
    value (:func:`_shown`), then whether the goal was reached. A metric a flight not
    found has no value for (its length and bounds are infinite, ``null`` in ``--json``;
    a tour's order is empty) is left out, as ``plan-world`` leaves out a cost it did not
    find: the table read "length inf m" and an empty "order" row."""
    table = Table(title=title, show_header=False)
    for k, v in doc["metrics"].items():
        if k != "reached" and not _no_value(v):
            table.add_row(metric_label(k), _shown(k, v, plane_unit))
    table.add_row("reached", str(doc["reached"]))
    return table


# The unit of each metric in the table ("plane": metres, or degrees in the degrees frame
# and for the step drone); --json keeps the bare numbers.
METRIC_UNITS = {"length": "plane", "bound": "plane", "greedy_bound": "plane",
                "length_deg": "deg", "time": "s", "seconds": "s", "smoothness": "rad/move"}
# Decimals by unit, as the other tables have them: lengths as plan-world's cost (6),
# seconds to the millisecond, smoothness to 1e-4 rad
DECIMALS = {"m": 6, "deg": 6, "s": 3, "rad/move": 4}


def _no_value(value) -> bool:
    """True for a metric with nothing to show: a float that is not finite, or ''."""
    return value == "" or (isinstance(value, float) and not math.isfinite(value))


def _shown(name: str, value, plane_unit: str) -> str:
    """A metric as the table shows it: floats with their unit, to a fixed number of
    decimals a unit (DECIMALS) and thousands separators, as plan-world's "cost
    1,221.383540 m" (6 significant digits made 1234567.8 m "1.23457e+06 m" and gave a
    length 2 decimals beside plan-world's 6); counts with thousands separators."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return str(value)
    if isinstance(value, int):
        return f"{value:,}"
    unit = METRIC_UNITS.get(name)
    unit = plane_unit if unit == "plane" else unit
    if unit is None:
        return f"{value:,.6g}"
    return f"{value:,.{DECIMALS[unit]}f} {unit}"


def _check_vehicle_options(ctx: typer.Context, vehicle: str) -> None:
    """An OptionError naming every option given on the command line (not left at its
    default) that ``vehicle`` does not use, with the vehicles that do (TAKEN_BY)."""
    stray = [f"{flag} (for {' and '.join(TAKEN_BY[name])})"
             for name, flag in _given(ctx, TAKEN_BY) if vehicle not in TAKEN_BY[name]]
    if stray:
        raise OptionError(f"--vehicle {vehicle} does not use {' or '.join(stray)}")


def _check_mode_options(ctx: typer.Context, vehicle: str, mode: str | None) -> None:
    """An OptionError naming every option given on the command line that ``vehicle``
    takes but ignores in ``mode`` (UNUSED_IN_MODE)."""
    unused = UNUSED_IN_MODE.get((vehicle, mode), ())
    stray = [flag for name, flag in _given(ctx, unused)]
    if stray:
        raise OptionError(f"{MODE_FLAG[mode]} does not use {' or '.join(stray)}")


def _given(ctx: typer.Context, names) -> list[tuple[str, str]]:
    """(name, flag as typed) of each parameter in ``names`` given on the command line,
    not left at its default."""
    given = []
    for param in ctx.command.params:
        if param.name not in names:
            continue
        # by name: Typer's vendored click has its own ParameterSource enum
        source = ctx.get_parameter_source(param.name)
        if source is None or source.name in ("DEFAULT", "DEFAULT_MAP"):
            continue
        value = ctx.params.get(param.name)
        flag = param.secondary_opts[0] if value is False and param.secondary_opts \
            else param.opts[0]  # --no-escape as typed
        given.append((param.name, flag))
    return given


def _check_typed_heading(heading: float | None, text: str, what: str, vehicle: str) -> None:
    """An OptionError when ``--start``/``--goal`` carries a heading ``vehicle`` does not
    use (the heading options' TAKEN_BY)."""
    takers = TAKEN_BY[f"{what}_heading"]
    if heading is not None and vehicle not in takers:
        raise OptionError(f"--{what} {text!r}: --vehicle {vehicle} does not use a {what} "
                          f"heading (for {' and '.join(takers)})")


def _one_heading(typed: float | None, option: float | None, what: str) -> float | None:
    """A heading (radians) from ``--start A,B,HEADING`` or ``--start-heading`` (degrees)."""
    if typed is not None and option is not None:
        raise OptionError(f"give the {what} heading once: in --{what} A,B,HEADING or "
                          f"--{what}-heading")
    if option is not None:  # --start A,B,HEADING is checked as it is parsed
        option = real(f"{what}_heading", option)
    deg = typed if typed is not None else option
    return None if deg is None else math.radians(deg)


def _read_targets(path: Path) -> np.ndarray:
    """(N, 2) target points from a .csv (A,B per line, an optional header) or a .json
    list of [A, B]; errors name the file and line."""
    from skyroute.errors import InputFormatError

    text = read_text(path)  # Excel's "CSV UTF-8" starts with a byte-order mark
    if path.suffix.lower() == ".json":
        try:
            pts = np.asarray(json.loads(text), dtype=float)
        except (json.JSONDecodeError, TypeError, ValueError):
            raise InputFormatError(path, "expected a JSON list of [a, b] points") from None
        if pts.ndim != 2 or pts.shape[1] != 2 or not np.isfinite(pts).all():
            raise InputFormatError(path, "expected a JSON list of [a, b] points")
    else:
        rows = []
        for n, line in enumerate(text.splitlines(), start=1):
            parts = line.replace(" ", "").split(",")
            if not line.strip() or (n == 1 and not _numbers(parts)):
                continue
            if len(parts) != 2 or not _numbers(parts):
                raise InputFormatError(path, f"expected two numbers A,B, got {line[:60]!r}",
                                       line=n)
            rows.append([float(p) for p in parts])
        pts = np.array(rows).reshape(-1, 2)
    if len(pts) == 0:
        raise InputFormatError(path, "no targets")
    return pts


def _numbers(parts: list[str]) -> bool:
    try:
        return all(math.isfinite(float(p)) for p in parts)
    except ValueError:
        return False


def _fly_hybrid(world, s, t, h0, h1, radius, step, reverse, max_expansions, approach):
    from skyroute.motion.hybrid import plan as hybrid_plan

    if approach is not None and h1 is None:
        raise OptionError("--approach: give the runway heading as --goal A,B,HEADING")
    start = (*s, h0) if h0 is not None else tuple(s)
    goal = (*t, h1) if h1 is not None else tuple(t)
    res = hybrid_plan(world, start, goal, radius, reverse=reverse,
                      max_expansions=max_expansions, approach=approach)
    metrics = {"status": res.status.value, "length": res.length, "expanded": res.expanded,
               "seconds": res.seconds}
    if res.status is Status.BUDGET_EXHAUSTED:
        metrics["why"] = _budget_why(res, max_expansions)
    if not res.found:
        return ({"reached": False, "metrics": metrics, "columns": []}, [], np.array([s]))
    poses = res.sample(step)
    metrics.update(pieces=len(res.segments), moves=len(poses) - 1,
                   smoothness=_smoothness(world.heading_to_plane(poses[:, 2])))
    rows = np.c_[poses[:, :2], np.degrees(poses[:, 2])].tolist()
    return ({"reached": True, "trajectory": rows, "metrics": metrics,
             "columns": _pose_columns(world)}, rows, poses[:, :2])


def _budget_why(res, max_expansions: int | None) -> str:
    """A Hybrid A* search out of budget, in flags: how far it went and what to change."""
    which = "the default --max-expansions" if max_expansions is None else "--max-expansions"
    return (f"Hybrid A* stopped after {res.extra['budget']:,} expansions ({which}); the "
            f"world is {res.extra['radii_across']:,.0f} turning radii across (--radius "
            f"{res.radius:g}): raise --max-expansions or --radius")


def _fly_tour(world, s, h0, pts, radius, step, max_expansions):
    from skyroute.motion.tour import tour

    res = tour((*s, h0 or 0.0), pts, radius, world=world, max_expansions=max_expansions)
    metrics = {"status": res.status.value, "length": res.length, "method": res.method,
               "order": " ".join(str(k + 1) for k in res.order),
               "greedy_bound": res.greedy_bound, "bound": res.bound,
               "seconds": res.seconds}
    if not res.found:
        return ({"reached": False, "metrics": metrics, "columns": []}, [], np.array([s]))
    poses = res.sample(step)
    rows = np.c_[poses[:, :2], np.degrees(poses[:, 2])].tolist()
    return ({"reached": True, "trajectory": rows, "metrics": metrics,
             "columns": _pose_columns(world)}, rows, poses[:, :2])


def _pose_rows(world, xy: np.ndarray, plane_headings: np.ndarray) -> list[list[float]]:
    """[[a, b, heading_deg], ...]: points in the world's frame, headings in degrees in its
    convention."""
    deg = np.degrees(world.heading_from_plane(plane_headings))
    return np.c_[xy, deg].tolist()


def _pose_columns(world) -> list[str]:
    return [*AXES[world.frame], "heading_deg"]


def _fly_step(world, s, t, planner):
    from skyroute.motion.step_drone import STEP, follow, plan_moves

    if planner == "moves":
        flight = plan_moves(world, s, t)
    else:
        route = plan(world, s, t, algorithm="theta")
        flight = follow(world, route.path if route.found else np.array([s, t]))
    reached = bool(flight.moves and math.dist(flight.end, t) < STEP) or \
        math.dist(s, t) < STEP
    rows = flight.rows()
    xy = np.vstack([s, flight.to]) if flight.moves else np.array([s])
    metrics = {"moves": flight.moves, "length_deg": float(flight.moves * STEP),
               "expanded": flight.expanded, "seconds": flight.seconds,
               "status": flight.status.value}
    return ({"reached": reached, "moves": rows, "metrics": metrics,
             "columns": ["from_lon", "from_lat", "angle", "to_lon", "to_lat"]}, rows, xy)


def _smoothness(plane_headings: np.ndarray) -> float:
    """Mean absolute heading change per sample step (radians)."""
    if len(plane_headings) < 2:
        return 0.0
    d = np.abs((np.diff(plane_headings) + math.pi) % (2 * math.pi) - math.pi)
    return float(d.mean())


def _fly_dubins(world, s, t, radius, h0, h1, step):
    from skyroute.motion.dubins import through

    route = plan(world, s, t)
    if not route.found:  # the exact route's status, as the other vehicles report theirs
        return _not_reached(route.status), [], np.array([s])
    corners = world.to_plane(route.path)
    if len(corners) == 1:  # start == goal: still one Dubins path, between the two headings
        corners = np.repeat(corners, 2, axis=0)
    legs = through(corners, radius,  # a heading left out: the best
                   start_heading=None if h0 is None else float(world.heading_to_plane(h0)),
                   end_heading=None if h1 is None else float(world.heading_to_plane(h1)))
    poses = np.vstack([leg.sample(step) for leg in legs])
    free = bool(world.segments_free(poses[:-1, :2], poses[1:, :2]).all())
    length = float(sum(leg.length for leg in legs))
    metrics = {"length": length, "moves": len(poses) - 1,
               "smoothness": _smoothness(poses[:, 2]), "free": free,
               "words": " ".join(leg.word for leg in legs)}
    xy = world.from_plane(poses[:, :2])
    rows = _pose_rows(world, xy, poses[:, 2])
    return ({"reached": True, "trajectory": rows, "metrics": metrics,
             "columns": _pose_columns(world)}, rows, xy)


def _fly_lattice(world, s, t, headings, speed, rate, h0, resolution):
    from skyroute.motion.turn_lattice import plan_turns_world

    res = plan_turns_world(world, s, t, resolution=resolution, headings=headings,
                           speed=speed, turn_rate=rate, start_heading=h0)
    if not res.found:
        return _not_reached(res.status, expanded=res.expanded), [], np.array([s])
    plane_h = world.heading_to_plane(res.headings)
    metrics = {"time": res.time, "length": res.distance, "moves": len(res.path) - 1,
               "smoothness": _smoothness(plane_h), "expanded": res.expanded,
               "status": res.status.value}
    rows = _pose_rows(world, res.path, plane_h)
    return ({"reached": True, "trajectory": rows, "metrics": metrics,
             "columns": _pose_columns(world)}, rows, res.path)


def _fly_field(world, s, t, step, escape, sensor_range, sensor_rays, mode, max_turn):
    from skyroute.motion.potential import run_field

    run = run_field(world, s, t, step=step, escape=escape, sensor_range=sensor_range,
                    sensor_rays=sensor_rays, tolerance=step, mode=mode, max_turn=max_turn)
    xy = run.path if run.trace is None else run.trace
    rows = np.asarray(xy).tolist()
    return ({"reached": run.reached, "trajectory": rows, "metrics": run.metrics(),
             "columns": list(AXES[world.frame])}, rows, xy)


def _not_reached(status: Status, **metrics) -> dict:
    """A flight not found: its ``status`` (no_path, budget_exhausted) among the metrics,
    as every vehicle reports it. It was a ``why`` alone ("no lattice route: no_path"),
    with no ``status`` in ``--json`` or the table."""
    return {"reached": False, "metrics": {"status": status.value, **metrics}, "columns": []}


def _render(path: Path, rows, columns, lonlat) -> str:
    suffix = path.suffix.lower()
    if suffix == ".json":
        return to_json(rows)
    if suffix == ".csv":
        buf = io.StringIO()
        w = csv.writer(buf)
        w.writerow(columns)
        w.writerows(rows)
        return buf.getvalue()
    return dumps({"type": "FeatureCollection", "features": [{
        "type": "Feature", "properties": {},
        "geometry": {"type": "LineString", "coordinates": np.asarray(lonlat).tolist()}}]})
