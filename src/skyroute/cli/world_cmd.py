"""``skyroute plan-world``: plan on a city (colliders.csv) or on zones (GeoJSON)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.markup import escape  # help is Rich markup: '[north, ...]' would read as a tag

from skyroute.cli import world_args as wa
from skyroute.cli.parse import check_outputs
from skyroute.cli.status import delayed_status
from skyroute.cli.tables import plain_console, print_table, result_table
from skyroute.errors import SEED_MAX, OptionError
from skyroute.files import write_atomic, written_together
from skyroute.io.geojson import dumps
from skyroute.io.json_text import to_json
from skyroute.io.world_out import (
    obstacles_label,
    path_north_east,
    plot_world_path,
    waypoints,
    world_path_geojson,
)
from skyroute.planner import plan
from skyroute.result import Status
from skyroute.roadmap.world_plan import WORLD_ALGORITHMS, options_for, roadmap_edges

EXIT_NOT_FOUND = 1
# what a first query's set-up time holds, by algorithm (the grid ones: on the raster)
SET_UP = {"visibility": "the visibility graph, compiled kernels",
          "prm": "the roadmap, compiled kernels",
          "raster": "the raster, masks, tables, compiled kernels"}


def plan_world_command(
    world_file: wa.WorldFile,
    start: wa.StartPoint,
    goal: wa.GoalPoint,
    frame: wa.Frame = None,
    altitude: wa.Altitude = None,
    safety: wa.Safety = 0.0,
    boundary: wa.Boundary = None,
    algorithm: Annotated[str, typer.Option(help="One of: " + ", ".join(WORLD_ALGORITHMS))] =
        "visibility",
    resolution: Annotated[float | None, typer.Option(
        help="Grid algorithms: cell size in world units (default: 1000 cells across).")] =
        None,
    samples: Annotated[int | None, typer.Option(help="PRM samples (default 1000).")] = None,
    seed: Annotated[int | None, typer.Option(
        min=0, max=SEED_MAX, help="PRM random seed (default 0).")] = None,
    waypoints_out: Annotated[Path | None, typer.Option(
        "--waypoints", help=escape(
            "Write [[north, east, altitude, heading], ...] JSON here: FCND waypoints, metres "
            "from home, heading in radians clockwise from north (not degrees, as the CLI "
            "reads headings elsewhere)."))] = None,
    geojson: Annotated[Path | None, typer.Option(help="Write the path as lon/lat GeoJSON.")] =
        None,
    plot: Annotated[Path | None, typer.Option(help="Write a PNG map here.")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Plan between two points of a continuous world.

    Points are read and the path printed in --frame, exactly as skyroute.plan() reads
    and returns them for a world loaded in that frame. Exit code 0 when a path is found,
    1 when there is none, 2 for bad input; output files are written only when a path is
    found.
    """
    frame = wa.frame_of(frame)
    given = {k: v for k, v in (("resolution", resolution), ("samples", samples),
                               ("seed", seed)) if v is not None}
    stray = [k for k in given if algorithm in WORLD_ALGORITHMS
             and k not in options_for(algorithm, **given)]
    if stray:  # as skyroute.plan refuses them: an option that would change nothing
        raise OptionError(f"--algorithm {algorithm} does not use "
                          + " or ".join(f"--{k}" for k in stray)
                          + " (--samples and --seed: prm; --resolution: the grid algorithms)")
    a = wa.parse_pair(start, "--start", wa.point_names(frame))
    b = wa.parse_pair(goal, "--goal", wa.point_names(frame))
    check_outputs(waypoints=waypoints_out, geojson=geojson, plot=plot)
    with delayed_status("planning"):  # a roadmap or raster, and a first run's compiles
        loaded = {"altitude": altitude, "safety": safety, "boundary": boundary, "frame": frame}
        world = wa.load_world_file(world_file, **loaded)
        wa.check_points(world_file, world, {"start": a, "goal": b}, **loaded)
        result = plan(world, a, b, algorithm=algorithm, **given)
    alt = 0.0 if altitude is None else altitude
    if result.found:
        with written_together():  # all the files or none (a Ctrl-C while plotting)
            if waypoints_out:
                write_atomic(waypoints_out, to_json(waypoints(world, result.path, alt)))
            if geojson:
                write_atomic(geojson, dumps(world_path_geojson(world, result)))
            if plot:
                plot_world_path(world, result, a, b, plot,
                                edges=roadmap_edges(world, algorithm,
                                                    **{k: given[k] for k in ("samples", "seed")
                                                       if k in given}),
                                obstacles=obstacles_label(altitude, safety, world.frame))
    if as_json:
        typer.echo(to_json(world_result_doc(world, result)))
    else:
        files = (("waypoints file", waypoints_out), ("geojson", geojson), ("plot", plot)) \
            if result.found else ()
        table = result_table(f"{world.name}: {result.algorithm}", result,
                             unit="deg" if world.plane == "degrees" else "m", files=files,
                             set_up=SET_UP.get(algorithm, SET_UP["raster"]))
        if result.status == Status.NO_PATH and algorithm == "prm":
            table.add_row("why", prm_no_path_why(given.get("samples", 1000),
                                                 given.get("seed", 0)))
        print_table(plain_console(), table)
    if not result.found:
        raise typer.Exit(EXIT_NOT_FOUND)


def prm_no_path_why(samples: int, seed: int) -> str:
    """What a PRM's no_path means: its roadmap joins no path, not that none exists (on
    the FCND city with a 5 m margin at 5, 20 and 50 m, 1,000 samples missed 5 of 44
    random pairs the visibility graph joined)."""
    return (f"the roadmap of {samples:,} samples (seed {seed}) joins no path from start "
            "to goal; one may still exist: more --samples, another --seed, or "
            "--algorithm visibility (exact) may find it")


def world_result_doc(world, result) -> dict:
    """The --json object of a world plan: the path in the frame (``path``), as north/east
    metres (``path_local``; lon/lat in the degrees frame, as before) and as lon/lat;
    ``seconds`` the search alone, ``setup_seconds`` what its first query set up (the
    roadmap or raster, compiled kernels; in a command's one query, always a number)."""
    local = result.path if world.frame == "degrees" else path_north_east(world, result.path)
    lonlat = result.path_lonlat if result.path_lonlat is not None else np.empty((0, 2))
    return {"status": result.status.value,
            "cost": float(result.cost) if result.found else None,
            "frame": world.frame,
            "path": result.path.tolist(),
            "path_local": np.asarray(local).tolist(),
            "path_lonlat": np.asarray(lonlat).tolist(),
            "expanded": int(result.expanded),
            "seconds": result.seconds,
            "setup_seconds": result.extra.get("setup_seconds"),
            "algorithm": result.algorithm}


def synth_city_command(
    out: Annotated[Path, typer.Argument(metavar="OUT",
                                        help="The colliders.csv file to write.")],
    seed: Annotated[int, typer.Option(min=0, max=SEED_MAX, help="Random seed.")] = 0,
    blocks: Annotated[int, typer.Option(help="Blocks along each side.")] = 6,
) -> None:
    """Write a synthetic city (random box buildings in street blocks) as colliders.csv."""
    from skyroute.world.synth import synth_city

    with delayed_status(f"writing {out}"):  # 100 x 100 blocks: 35,000 buildings
        write_atomic(out, synth_city(np.random.default_rng(seed), blocks=blocks))  # checks blocks
    typer.echo(f"wrote {out}: {blocks}x{blocks} blocks, home (0, 0) on a street crossing")
