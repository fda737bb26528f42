"""How commands that take a world read it and its points: shared arguments and options
(WORLD, --start, --goal, --frame, --altitude, --safety, --boundary) and their parsing."""

from __future__ import annotations

from typing import Annotated

import numpy as np
import typer

from skyroute.errors import OptionError, check_choice
from skyroute.geo import FRAME_ALIASES, FRAMES

DEFAULT_FRAME = "lonlat"  # a world's own frame, for colliders and GeoJSON files alike

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


def parse_pose(text: str, option: str, names: str) -> tuple[float, float, float | None]:
    """``"A,B"`` or ``"A,B,HEADING"`` -> two finite floats and a heading in degrees (or
    None)."""
    parts = text.replace(" ", "").split(",")
    try:
        if len(parts) not in (2, 3):
            raise ValueError
        vals = [float(p) for p in parts]
        if not all(np.isfinite(vals)):
            raise ValueError
    except ValueError:
        raise OptionError(f"{option} {text!r} must be two numbers {names}, optionally "
                          "followed by a heading in degrees") from None
    return vals[0], vals[1], (vals[2] if len(vals) == 3 else None)


def frame_of(frame: str | None) -> str:
    """The frame a command reads points in: ``--frame``, or a world's own (lonlat)."""
    frame = DEFAULT_FRAME if frame is None else frame
    check_choice("frame", frame, (*FRAMES, *FRAME_ALIASES))
    return FRAME_ALIASES.get(frame, frame)


def point_names(frame: str) -> str:
    """How a point is typed in ``frame``: LON,LAT / NORTH,EAST / EAST,NORTH."""
    return {"lonlat": "LON,LAT", "degrees": "LON,LAT", "ned": "NORTH,EAST",
            "enu": "EAST,NORTH"}[frame]


FRAME_HELP = ("How points are typed and printed: lonlat (LON,LAT; the default, a world's "
              "own), ned or local (NORTH,EAST metres from home), enu (EAST,NORTH metres) or "
              "degrees (LON,LAT on a flat plane, the ILP rules; GeoJSON only).")


# str, not Path: Typer makes an empty argument Path("."), which load_world read as a
# folder ("unknown world type ''"); load_world_file names it (as plan's MAP is a str)
WorldFile = Annotated[str, typer.Argument(metavar="WORLD", help=(
    "A colliders.csv city (metres around lat0/lon0) or a GeoJSON file of zones."))]
StartPoint = Annotated[str, typer.Option(
    "--start", help="A point in --frame: LON,LAT, NORTH,EAST or EAST,NORTH.")]
GoalPoint = Annotated[str, typer.Option("--goal", help="Same form as --start.")]
Frame = Annotated[str | None, typer.Option("--frame", help=FRAME_HELP)]
Altitude = Annotated[float | None, typer.Option(
    "--altitude", help="Keep the obstacles that count at this altitude (m).")]
Safety = Annotated[float, typer.Option(
    "--safety", help="Grow obstacles by this distance (m; degrees in the degrees frame).")]
Boundary = Annotated[str | None, typer.Option(
    "--boundary", help="A GeoJSON file or MINLON,MINLAT,MAXLON,MAXLAT to stay strictly "
                       "inside.")]


def load_world_file(world_file: str, **options):
    """:func:`skyroute.load_world`; a grid map given as WORLD says to plan on it with
    ``skyroute plan`` (as ``plan`` sends a colliders city to ``plan-world``); an empty
    WORLD says so, as ``plan`` says of an empty MAP (it read ".: unknown world type ''")."""
    from skyroute.errors import GridNotWorldError, InputFormatError, OptionError
    from skyroute.world.load import load_world

    if not str(world_file):
        raise OptionError("the WORLD argument is empty: give a colliders.csv city or a "
                          "GeoJSON file of zones")
    try:
        return load_world(world_file, **options)
    except GridNotWorldError as exc:
        raise InputFormatError(exc.path, f"{exc.what}: plan on it with 'skyroute plan "
                               f"{world_file} --start X,Y --goal X,Y'", line=exc.line) from None


def check_points(world_file: str, world, points: dict, **options) -> None:
    """Each ``{what: point}`` (in the world's frame) free in ``world``, else its
    QueryError; a point blocked only by the ``--safety`` margin is named so. It read
    "lies inside obstacle 'box at line 3'" for a point 2 m outside the building, as if
    the map had the building there; the world is read again without the margin, only
    then (``options``: those ``world`` was loaded with)."""
    from skyroute.errors import QueryError

    safety = options.get("safety") or 0.0
    for what, point in points.items():
        try:
            world.check_point(point, what)
        except QueryError as exc:
            # only "inside an obstacle" may be the margin's doing; converting the point
            # again re-raised "not a place" without the error's hint (--safety 5, FCND's)
            if safety <= 0 or "lies inside obstacle" not in str(exc):
                raise
            p = world.to_plane(point, what)
            j = int(world.blocking(p)[0])
            phrase = f"lies inside obstacle {world.names[j]!r}" if j >= 0 else None
            if phrase is None or phrase not in str(exc):
                raise
            bare = load_world_file(world_file, **{**options, "safety": 0.0})
            if not bare.is_free(p)[0]:
                raise
            unit = "degrees" if world.plane == "degrees" else "m"
            raise QueryError(str(exc).replace(
                phrase, f"lies outside obstacle {world.names[j]!r} but within its --safety "
                        f"{safety:g} {unit} margin")) from None
