"""``skyroute plan``: one query on a grid map, printed and optionally written out."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from skyroute.cli.parse import check_outputs, parse_cell
from skyroute.cli.status import delayed_status
from skyroute.cli.tables import print_table, result_table
from skyroute.errors import InputFormatError, OptionError, QueryError
from skyroute.files import check_writable, write_atomic, written_together
from skyroute.io.geojson import dumps, grid_path_geojson
from skyroute.io.json_text import to_json
from skyroute.planner import plan
from skyroute.search.grid_plan import GRID_ALGORITHMS, grid_options
from skyroute.world.load import load_map

EXIT_NOT_FOUND = 1


def plan_command(
    map_file: Annotated[str, typer.Argument(metavar="MAP", help=(
        "A .map (MovingAI), .csv (wall segments x1,y1,x2,y2 in metres), image or .npy "
        "file, or the name of a bundled map (see 'skyroute maps').")) ],
    start: Annotated[str, typer.Option(help="Start cell X,Y (column,row).")],
    goal: Annotated[str, typer.Option(help="Goal cell X,Y (column,row).")],
    algorithm: Annotated[str, typer.Option(
        help="One of: " + ", ".join(GRID_ALGORITHMS) + ".")] = "astar",
    connectivity: Annotated[int | None, typer.Option(
        help="4 or 8 (default 8; 4 for bfs).")] = None,
    corner_cutting: Annotated[bool, typer.Option(
        "--corner-cutting", help="Allow a diagonal step past one blocked side cell.")] = False,
    heuristic: Annotated[str | None, typer.Option(
        help="octile, euclidean, manhattan or zero (default: the algorithm's own).")] = None,
    weight: Annotated[float, typer.Option(help="Weighted A*: w >= 1.")] = 1.0,
    prune: Annotated[str, typer.Option(help="none, collinear or los.")] = "none",
    safety: Annotated[float, typer.Option(
        "--safety", "--clearance",
        help="Block cells within this many metres of an obstacle (--clearance: old name).")]
        = 0.0,
    resolution: Annotated[float, typer.Option(
        "--resolution", "--cell-size",
        help="Metres per cell: the rasterising resolution for .csv walls (--cell-size: old "
             "name).")] = 1.0,
    max_expansions: Annotated[int | None, typer.Option(
        help="Give up after this many expansions (status budget_exhausted); default: "
             "enough to finish the search, with no cap (the map's cells bound it).")] = None,
    index: Annotated[Path | None, typer.Option(
        help="Answer from this prepared index ('skyroute prepare MAP -o MAP.idx'): the exact "
             "octile path; only with the default search options.")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
    plot: Annotated[Path | None, typer.Option(help="Write a PNG picture here.")] = None,
    geojson: Annotated[Path | None, typer.Option(help="Write the path as GeoJSON here.")] = None,
) -> None:
    """Plan a path on a grid map from START to GOAL.

    Exit code 0 when a path is found, 1 when there is none (or the budget ran out),
    2 for bad input. Output files are written only when a path is found.
    """
    s, t = parse_cell(start, "--start"), parse_cell(goal, "--goal")
    check_outputs(plot=plot, geojson=geojson)
    opts = grid_options(algorithm, connectivity=connectivity, corner_cutting=corner_cutting,
                        heuristic=heuristic, weight=weight, prune=prune,
                        max_expansions=max_expansions)
    if index is not None and opts != grid_options("astar"):
        raise OptionError("--index answers exact octile queries: leave --algorithm, "
                          "--connectivity, --corner-cutting, --heuristic, --weight, --prune "
                          "and --max-expansions at their defaults", param="index")
    with delayed_status("planning"):  # a first run compiles its kernels for seconds
        grid = _load_grid(map_file, resolution=resolution, safety=safety)
        _check_margin(map_file, grid, {"start": s, "goal": t}, resolution=resolution,
                      safety=safety)
        if index is not None:
            from skyroute.search.prepared import load_index

            result = load_index(index, grid).plan(s, t)
        else:
            result = plan(grid, s, t, algorithm=opts.algorithm,
                          connectivity=opts.connectivity, corner_cutting=opts.corner_cutting,
                          heuristic=opts.heuristic, weight=opts.weight, prune=opts.prune,
                          max_expansions=max_expansions)
    if result.found:
        with written_together():  # both files or neither (a Ctrl-C while plotting)
            if geojson:
                write_atomic(geojson, dumps(grid_path_geojson(grid, result)))
            if plot:
                from skyroute.io.plot import plot_grid_path

                plot_grid_path(grid, result, s, t, plot, prune=opts.prune, safety=safety)
    if as_json:
        typer.echo(to_json(result.to_dict()))
    else:
        from skyroute.cli.tables import plain_console

        files = (("plot", plot), ("geojson", geojson)) if result.found else ()
        # the cost is in cells (octile steps), as --json gives it; in metres too where a
        # cell is not 1 m (--resolution)
        print_table(plain_console(), result_table(
            f"{grid.name}: {result.algorithm}", result, unit="cells",
            metres_per_unit=grid.resolution, files=files))
    if not result.found:
        raise typer.Exit(EXIT_NOT_FOUND)


def _load_grid(map_file: str, *, resolution: float, safety: float):
    """:func:`load_map`; a world given as MAP (a colliders city, GeoJSON zones) says to
    plan in it with plan-world; an empty MAP says so (it read as the folder '.')."""
    from skyroute.errors import CITY, CityNotWallsError, WorldNotGridError

    if not map_file:
        raise OptionError("the MAP argument is empty: give a map file or a bundled map's "
                          "name (see 'skyroute maps')")
    plan_world = f"plan in it with 'skyroute plan-world {map_file} --start LON,LAT --goal LON,LAT'"
    try:
        return load_map(map_file, resolution=resolution, safety=safety)
    except CityNotWallsError as exc:
        raise InputFormatError(exc.path, f"{CITY}: {plan_world}", line=1) from None
    except WorldNotGridError as exc:
        raise InputFormatError(exc.path, f"{exc.what}: {plan_world}", line=exc.line) from None


def _check_margin(map_file: str, grid, cells: dict, *, resolution: float,
                  safety: float) -> None:
    """A start or goal blocked only by the ``--safety`` margin is named so (it read "is on
    a blocked cell", as if the map had an obstacle there): the map is read again without
    the margin, only then. Other faults are left to the planner's own errors, in its
    order (start first; off the grid before blocked)."""
    for what, (x, y) in cells.items():
        if not (0 <= x < grid.width and 0 <= y < grid.height):
            return
        if grid.blocked[y, x]:
            if safety > 0 and not _load_grid(map_file, resolution=resolution,
                                              safety=0.0).blocked[y, x]:
                raise QueryError(f"{what} ({x}, {y}) is free in {grid.name} but within the "
                                 f"--safety {safety:g} m margin of an obstacle; choose a "
                                 "cell farther from it or a smaller --safety", param=what)
            return


def prepare_command(
    map_file: Annotated[str, typer.Argument(metavar="MAP", help=(
        "A grid map file (as for 'skyroute plan') or the name of a bundled map."))],
    out: Annotated[Path, typer.Option("-o", "--out", help="Write the index here (.npz "
                                      "format), e.g. MAP.idx.")],
    method: Annotated[str, typer.Option(
        help="Index kind: auto (the faster of the two on sample queries), subgoal or "
             "jump.")] = "auto",
    safety: Annotated[float, typer.Option(
        help="Block cells within this many metres of an obstacle (as for plan).")] = 0.0,
    resolution: Annotated[float, typer.Option(
        help="Metres per cell for .csv walls (as for plan).")] = 1.0,
) -> None:
    """Build a map's index once for fast exact queries ('skyroute plan MAP --index ...')."""
    from skyroute.cli.tables import plain_console
    from skyroute.search.prepared import prepare

    if Path(map_file).is_file() and out.resolve() == Path(map_file).resolve():
        raise OptionError(f"-o {out} is the map itself; write the index to another path "
                          "(e.g. MAP.idx)")
    check_writable(out)  # before the build, which can take a while
    grid = _load_grid(map_file, resolution=resolution, safety=safety)
    if grid.blocked.all():
        plain_console(stderr=True).print(f"note: every cell of {grid.name} is blocked (--safety "
                                   f"{safety:g}): the index will refuse every query")
    with delayed_status(f"preparing {grid.name}"):  # a first run compiles for a minute
        index = prepare(grid, method=method)
    written = index.save(out)
    plain_console().print(f"{grid.name}: {index.describe()}, built in "
                          f"{index.build_seconds:,.3f} s, {written.stat().st_size / 1e6:,.2f} "
                          f"MB -> {written}")
