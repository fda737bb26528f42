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
from rich.console import Console
from rich.table import Table

from skyroute.cli.world_cmd import _check_in_user_frame, _to_world, parse_pair
from skyroute.errors import OptionError, check_choice
from skyroute.io.files import write_atomic
from skyroute.io.geojson import dumps
from skyroute.io.world_out import path_lonlat
from skyroute.planner import plan
from skyroute.world.load import load_world

VEHICLES = ("step", "dubins", "lattice", "field")
EXIT_NOT_REACHED = 1


def fly_command(
    world_file: Annotated[Path, typer.Argument(metavar="WORLD", help=(
        "A colliders.csv city or a GeoJSON file of zones, as for plan-world."))],
    start: Annotated[str, typer.Option(help="LON,LAT or NORTH,EAST (--frame local).")],
    goal: Annotated[str, typer.Option(help="Same form as --start.")],
    vehicle: Annotated[str, typer.Option(help="step, dubins, lattice or field.")] = "step",
    frame: Annotated[str, typer.Option(help="lonlat, local or degrees.")] = "degrees",
    altitude: Annotated[float | None, typer.Option(help="Altitude filter (m).")] = None,
    safety: Annotated[float, typer.Option(help="Grow obstacles by this distance.")] = 0.0,
    boundary: Annotated[str | None, typer.Option(help="GeoJSON file or a lon/lat bbox.")] =
        None,
    planner: Annotated[str, typer.Option(
        help="step drone: moves (fewest moves, A*) or follow (round a Theta* path).")] =
        "moves",
    radius: Annotated[float, typer.Option(help="dubins: turning radius.")] = 10.0,
    start_heading: Annotated[float, typer.Option(
        help="dubins / lattice: start heading in degrees from the x axis (east).")] = 0.0,
    goal_heading: Annotated[float | None, typer.Option(
        help="dubins: heading at the goal (degrees); free when left out.")] = None,
    headings: Annotated[int, typer.Option(help="lattice: 8 or 16 headings.")] = 8,
    speed: Annotated[float, typer.Option(help="lattice: cells per second.")] = 1.0,
    turn_rate: Annotated[float, typer.Option(help="lattice: degrees per second.")] = 90.0,
    resolution: Annotated[float | None, typer.Option(help="lattice: cell size.")] = None,
    step: Annotated[float, typer.Option(help="dubins: sampling step; field: move length.")] =
        1.0,
    escape: Annotated[bool, typer.Option(
        help="field: follow a navigation function out of local minima.")] = True,
    sensor_range: Annotated[float, typer.Option(help="field: sensor range.")] = 6.0,
    sensor_rays: Annotated[int, typer.Option(help="field: sensor rays (density).")] = 36,
    field_mode: Annotated[str, typer.Option(
        help="field: step (jump along the force) or arc (turn-limited arcs, slower in "
             "turns).")] = "step",
    max_turn: Annotated[float, typer.Option(
        help="field arc mode: largest heading change per move, degrees.")] = 45.0,
    out: Annotated[Path | None, typer.Option(help="Write moves or samples (.json, .csv, "
                                             ".geojson).")] = None,
    plot: Annotated[Path | None, typer.Option(help="Write a PNG map of the flight.")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Fly from START to GOAL with a vehicle model; exit 1 when the goal is not reached."""
    check_choice("vehicle", vehicle, VEHICLES)
    check_choice("planner", planner, ("moves", "follow"))
    if out is not None and out.suffix.lower() not in (".json", ".csv", ".geojson"):
        raise OptionError(f"--out {out}: the suffix must be .json, .csv or .geojson")
    names = "NORTH,EAST" if frame == "local" else "LON,LAT"
    a, b = parse_pair(start, "--start", names), parse_pair(goal, "--goal", names)
    world = load_world(world_file, altitude=altitude, safety=safety, boundary=boundary,
                       frame=frame)
    s, t = (_to_world(world, p, frame) for p in (a, b))
    _check_in_user_frame(world, s, a, "start", frame)
    _check_in_user_frame(world, t, b, "goal", frame)
    if vehicle == "step":
        doc, rows, xy = _fly_step(world, s, t, planner)
    elif vehicle == "dubins":
        doc, rows, xy = _fly_dubins(world, s, t, radius, math.radians(start_heading),
                                    None if goal_heading is None else
                                    math.radians(goal_heading), step)
    elif vehicle == "lattice":
        doc, rows, xy = _fly_lattice(world, s, t, headings, speed, math.radians(turn_rate),
                                     math.radians(start_heading), resolution)
    else:
        doc, rows, xy = _fly_field(world, s, t, step, escape, sensor_range, sensor_rays,
                                   field_mode, math.radians(max_turn))
    if out is not None and doc["reached"]:
        write_atomic(out, _render(out, rows, doc["columns"], path_lonlat(world, xy)))
    if plot is not None and doc["reached"]:
        from skyroute.io.world_out import plot_world_path
        from skyroute.result import PlanResult, Status

        length = float(np.hypot(*np.diff(xy, axis=0).T).sum()) if len(xy) > 1 else 0.0
        shown = PlanResult(Status.FOUND, np.asarray(xy), length, algorithm=vehicle)
        plot_world_path(world, shown, s, t, plot)
    if as_json:
        typer.echo(json.dumps({k: v for k, v in doc.items() if k != "columns"}))
    else:
        table = Table(title=f"{world.name}: {vehicle}", show_header=False)
        for k, v in doc["metrics"].items():
            if k != "reached":
                table.add_row(k, f"{v:.6g}" if isinstance(v, float) else str(v))
        table.add_row("reached", str(doc["reached"]))
        Console().print(table)
    if not doc["reached"]:
        raise typer.Exit(EXIT_NOT_REACHED)


def _fly_step(world, s, t, planner):
    from skyroute.motion.step_drone import follow, plan_moves

    if planner == "moves":
        flight = plan_moves(world, s, t)
    else:
        route = plan(world, s, t, algorithm="theta")
        flight = follow(world, route.path if route.found else np.array([s, t]))
    reached = bool(flight.moves and math.dist(flight.end, t) < 0.00015) or \
        math.dist(s, t) < 0.00015
    rows = flight.rows()
    xy = np.vstack([s, flight.to]) if flight.moves else np.array([s])
    metrics = {"moves": flight.moves, "length_deg": float(flight.moves * 0.00015),
               "expanded": flight.expanded, "seconds": flight.seconds,
               "status": flight.status.value}
    return ({"reached": reached, "moves": rows, "metrics": metrics,
             "columns": ["from_lon", "from_lat", "angle", "to_lon", "to_lat"]}, rows, xy)


def _smoothness(poses: np.ndarray) -> float:
    """Mean absolute heading change per sample step (radians)."""
    if len(poses) < 2:
        return 0.0
    d = np.abs((np.diff(poses[:, 2]) + math.pi) % (2 * math.pi) - math.pi)
    return float(d.mean())


def _fly_dubins(world, s, t, radius, h0, h1, step):
    from skyroute.motion.dubins import through

    route = plan(world, s, t)
    if not route.found:
        return _not_reached("no route between start and goal"), [], np.array([s])
    legs = through(route.path, radius, start_heading=h0, end_heading=h1)
    poses = np.vstack([leg.sample(step) for leg in legs])
    free = bool(world.segments_free(poses[:-1, :2], poses[1:, :2]).all())
    length = float(sum(leg.length for leg in legs))
    metrics = {"length": length, "moves": len(poses) - 1, "smoothness": _smoothness(poses),
               "free": free, "words": " ".join(leg.word for leg in legs)}
    rows = poses.tolist()
    return ({"reached": True, "trajectory": rows, "metrics": metrics,
             "columns": ["x", "y", "heading"]}, rows, poses[:, :2])


def _fly_lattice(world, s, t, headings, speed, rate, h0, resolution):
    from skyroute.motion.turn_lattice import plan_turns
    from skyroute.world_plan import default_resolution

    r = default_resolution(world) if resolution is None else resolution
    grid = world.merged().rasterize(r, clearance=r / math.sqrt(2) * 1.0001,
                                    bounds=world.extent_with([s, t], margin=4 * r))
    cs, ct = (tuple(int(v) for v in grid.to_cell([p])[0]) for p in (s, t))
    res = plan_turns(grid, cs, ct, headings=headings, speed=speed, turn_rate=rate,
                     start_heading=h0)
    if not res.found:
        return _not_reached("no lattice route"), [], np.array([s])
    xy = grid.to_world(res.cells)
    poses = np.c_[xy, res.headings]
    metrics = {"time": res.time, "length": float(res.distance * r), "moves": len(xy) - 1,
               "smoothness": _smoothness(poses), "expanded": res.expanded}
    rows = poses.tolist()
    return ({"reached": True, "trajectory": rows, "metrics": metrics,
             "columns": ["x", "y", "heading"]}, rows, xy)


def _fly_field(world, s, t, step, escape, sensor_range, sensor_rays, mode, max_turn):
    from skyroute.motion.potential import run_field

    run = run_field(world, s, t, step=step, escape=escape, sensor_range=sensor_range,
                    sensor_rays=sensor_rays, tolerance=step, mode=mode, max_turn=max_turn)
    xy = run.path if run.trace is None else run.trace
    rows = xy.tolist()
    return ({"reached": run.reached, "trajectory": rows, "metrics": run.metrics(),
             "columns": ["x", "y"]}, rows, xy)


def _not_reached(why: str) -> dict:
    return {"reached": False, "metrics": {"why": why}, "columns": []}


def _render(path: Path, rows, columns, lonlat) -> str:
    suffix = path.suffix.lower()
    if suffix == ".json":
        return json.dumps(rows)
    if suffix == ".csv":
        buf = io.StringIO()
        w = csv.writer(buf)
        w.writerow(columns)
        w.writerows(rows)
        return buf.getvalue()
    return dumps({"type": "FeatureCollection", "features": [{
        "type": "Feature", "properties": {},
        "geometry": {"type": "LineString", "coordinates": np.asarray(lonlat).tolist()}}]})
