"""``skyroute plan-world``: plan on a city (colliders.csv) or on zones (GeoJSON)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.console import Console

from skyroute.cli.tables import result_table
from skyroute.errors import OptionError, QueryError
from skyroute.geo import enu_to_lonlat, lonlat_to_enu
from skyroute.io.files import write_atomic
from skyroute.io.geojson import dumps
from skyroute.io.world_out import (
    path_lonlat,
    path_north_east,
    plot_world_path,
    waypoints,
    world_path_geojson,
)
from skyroute.planner import plan
from skyroute.world.load import load_world
from skyroute.world_plan import WORLD_ALGORITHMS, roadmap_edges

EXIT_NOT_FOUND = 1


def parse_pair(text: str, option: str, names: str) -> tuple[float, float]:
    """``"A,B"`` -> two finite floats."""
    parts = text.replace(" ", "").split(",")
    try:
        if len(parts) != 2:
            raise ValueError
        a, b = float(parts[0]), float(parts[1])
        if not (np.isfinite(a) and np.isfinite(b)):
            raise ValueError
    except ValueError:
        raise OptionError(f"{option} {text!r} must be two numbers {names}") from None
    return a, b


def plan_world_command(
    world_file: Annotated[Path, typer.Argument(metavar="WORLD", help=(
        "A colliders.csv city (metres around lat0/lon0) or a GeoJSON file of zones."))],
    start: Annotated[str, typer.Option(help="LON,LAT (lonlat, degrees) or NORTH,EAST "
                                       "(local).")],
    goal: Annotated[str, typer.Option(help="Same form as --start.")],
    frame: Annotated[str, typer.Option(help="lonlat, local or degrees.")] = "lonlat",
    altitude: Annotated[float | None, typer.Option(
        help="Keep the obstacles that count at this altitude (m).")] = None,
    safety: Annotated[float, typer.Option(
        help="Grow obstacles by this distance (m; degrees in the degrees frame).")] = 0.0,
    boundary: Annotated[str | None, typer.Option(
        help="A GeoJSON file or MINLON,MINLAT,MAXLON,MAXLAT to stay strictly inside.")] = None,
    algorithm: Annotated[str, typer.Option(help="One of: " + ", ".join(WORLD_ALGORITHMS))] =
        "visibility",
    resolution: Annotated[float | None, typer.Option(
        help="Grid algorithms: cell size in world units (default: 1000 cells across).")] =
        None,
    samples: Annotated[int, typer.Option(help="PRM samples.")] = 1000,
    seed: Annotated[int, typer.Option(help="PRM random seed.")] = 0,
    waypoints_out: Annotated[Path | None, typer.Option(
        "--waypoints", help="Write [[north, east, altitude, heading], ...] JSON here.")] = None,
    geojson: Annotated[Path | None, typer.Option(help="Write the path as lon/lat GeoJSON.")] =
        None,
    plot: Annotated[Path | None, typer.Option(help="Write a PNG map here.")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Plan between two points of a continuous world.

    Exit code 0 when a path is found, 1 when there is none, 2 for bad input; output
    files are written only when a path is found.
    """
    names = "NORTH,EAST" if frame == "local" else "LON,LAT"
    a = parse_pair(start, "--start", names)
    b = parse_pair(goal, "--goal", names)
    world = load_world(world_file, altitude=altitude, safety=safety, boundary=boundary,
                       frame=frame)
    s, t = (_to_world(world, p, frame) for p in (a, b))
    _check_in_user_frame(world, s, a, "start", frame)
    _check_in_user_frame(world, t, b, "goal", frame)
    result = plan(world, s, t, algorithm=algorithm, resolution=resolution, samples=samples,
                  seed=seed)
    alt = 0.0 if altitude is None else altitude
    if result.found:
        if waypoints_out:
            write_atomic(waypoints_out, json.dumps(waypoints(world, result.path, alt)))
        if geojson:
            write_atomic(geojson, dumps(world_path_geojson(world, result)))
        if plot:
            plot_world_path(world, result, s, t, plot,
                            edges=roadmap_edges(world, algorithm, samples=samples, seed=seed))
    local = (result.path if frame == "degrees" else path_north_east(world, result.path))
    doc = {"status": result.status.value,
           "cost": float(result.cost) if result.found else None,
           "path_local": local.tolist(),
           "path_lonlat": path_lonlat(world, result.path).tolist(),
           "seconds": result.seconds, "algorithm": result.algorithm}
    if as_json:
        typer.echo(json.dumps(doc))
    else:
        files = (("waypoints file", waypoints_out), ("geojson", geojson), ("plot", plot)) \
            if result.found else ()
        Console().print(result_table(f"{world.name}: {result.algorithm}", result,
                                     unit="deg" if world.frame == "degrees" else "m",
                                     files=files))
    if not result.found:
        raise typer.Exit(EXIT_NOT_FOUND)


def _user(world, p: np.ndarray, frame: str) -> tuple[float, float]:
    """A world point in the frame the user typed: (lon, lat) or (north, east)."""
    if frame == "local":
        return float(p[1]), float(p[0])
    if frame == "degrees":
        return float(p[0]), float(p[1])
    lon, lat, _ = enu_to_lonlat(p[0], p[1], 0.0, world.home)[0]
    return float(lon), float(lat)


def _check_in_user_frame(world, p: np.ndarray, typed, what: str, frame: str) -> None:
    """Raise the world's start/goal errors with coordinates in the user's frame."""
    names = ("north", "east") if frame == "local" else ("lon", "lat")
    fmt = "{:.2f}" if frame == "local" else "{:.7f}"  # 1e-7 degree is about 1 cm
    here = f"({fmt.format(typed[0])}, {fmt.format(typed[1])})"
    if not world.inside([p])[0]:
        xmin, ymin, xmax, ymax = world.bounds
        lo = _user(world, np.array([xmin, ymin]), frame)
        hi = _user(world, np.array([xmax, ymax]), frame)
        a0, a1 = sorted((lo[0], hi[0]))
        b0, b1 = sorted((lo[1], hi[1]))
        raise QueryError(f"{what} {here} lies outside the map ({names[0]} in "
                         f"({fmt.format(a0)}, {fmt.format(a1)}), {names[1]} in "
                         f"({fmt.format(b0)}, {fmt.format(b1)}))")
    j = int(world.blocking([p])[0])
    if j >= 0:
        near = _user(world, world.nearest_free(p, j), frame)
        raise QueryError(f"{what} {here} lies inside obstacle {world.names[j]!r}; nearest "
                         f"free point ({fmt.format(near[0])}, {fmt.format(near[1])})")


def _to_world(world, p: tuple[float, float], frame: str) -> np.ndarray:
    if frame == "degrees":
        return np.array(p)
    if frame == "local":
        return np.array([p[1], p[0]])  # (north, east) -> (x = east, y = north)
    return lonlat_to_enu(p[0], p[1], 0.0, world.home)[0, :2]


def synth_city_command(
    out: Annotated[Path, typer.Argument(help="The colliders.csv file to write.")],
    seed: Annotated[int, typer.Option(help="Random seed.")] = 0,
    blocks: Annotated[int, typer.Option(help="Blocks along each side.")] = 6,
) -> None:
    """Write a synthetic city (random box buildings in street blocks) as colliders.csv."""
    from skyroute.world.synth import synth_city

    if blocks < 1:
        raise OptionError(f"--blocks {blocks} must be >= 1")
    write_atomic(out, synth_city(np.random.default_rng(seed), blocks=blocks))
    typer.echo(f"wrote {out}: {blocks}x{blocks} blocks, home (0, 0) on a street crossing")
