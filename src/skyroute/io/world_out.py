"""A path planned on a World as FCND waypoints, lon/lat GeoJSON, and a PNG map.

Paths and points come in the world's frame (as :func:`skyroute.plan` returns them);
pictures are drawn in its plane (east/north metres, or lon/lat in degrees), onto a
caller's matplotlib Axes by :func:`draw_world_path`."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from skyroute.geo import heading_of, lonlat_to_enu
from skyroute.io.plot import (
    draw_path,
    legend_outside,
    mark_ends,
    new_figure,
    place_labels,
    save_figure,
    set_title,
)
from skyroute.result import PlanResult
from skyroute.world.world import AXES, World


def path_lonlat(world: World, path: np.ndarray) -> np.ndarray:
    """(K, 2) lon, lat of a path in the world's frame."""
    return world.plane_to_lonlat(world.to_plane(np.reshape(path, (-1, 2)), "path"))


def path_north_east(world: World, path: np.ndarray) -> np.ndarray:
    """(K, 2) north, east metres from home of a path in the world's frame."""
    p = world.to_plane(np.reshape(path, (-1, 2)), "path")
    if world.frame == "degrees" and len(p):
        enu = lonlat_to_enu(p[:, 0], p[:, 1], 0.0, world.home)
        return np.c_[enu[:, 1], enu[:, 0]]
    return np.c_[p[:, 1], p[:, 0]]


# metres: a shorter leg is a point repeated, without a heading of its own. A lon/lat
# point read back into metres is off by up to about 1e-8 m (a float's last digits of
# degrees), so a point repeated in lon/lat (a sampled Dubins path's last pose, repeated
# at its goal) came back as a leg of 5e-9 m whose "heading" was rounding noise: the
# last FCND waypoint turned 11 degrees away from the track. A micrometre is far above
# that noise and far below any leg flown.
_SAME_POINT = 1e-6


def waypoints(world: World, path: np.ndarray, altitude: float) -> list[list[float]]:
    """[[north, east, altitude, heading], ...] relative to home; heading (radians, 0 north,
    clockwise) along the track into each point, the first taking the first leg's. A leg
    of zero length (a point repeated) has no direction of its own: it keeps the heading
    of the leg before, or of the next leg when it comes first (0 when no leg has one);
    a leg under a micrometre is such a point (a lon/lat point repeated comes back within
    rounding, not exactly)."""
    ne = path_north_east(world, path)
    if len(ne) == 0:
        return []
    d = np.diff(ne, axis=0)
    legs = heading_of(d[:, 1], d[:, 0]) if len(d) else np.zeros(0)
    moves = np.hypot(d[:, 0], d[:, 1]) > _SAME_POINT
    if moves.any():  # each leg takes the latest moving leg's heading (the first's before it)
        latest = np.maximum.accumulate(np.where(moves, np.arange(len(d)), -1))
        legs = legs[np.where(latest < 0, np.argmax(moves), latest)]
    else:
        legs = np.zeros(len(d))
    headings = np.concatenate([legs[:1] if len(legs) else [0.0], legs])
    return [[float(n), float(e), float(altitude), float(h)]
            for (n, e), h in zip(ne, headings, strict=True)]


def world_path_geojson(world: World, result: PlanResult) -> dict:
    """A FeatureCollection with the path as a LineString in lon/lat (RFC 7946)."""
    props = {k: v for k, v in result.to_dict().items() if k not in ("path", "path_lonlat")}
    props.update(world=world.name, frame=world.frame)
    lonlat = result.path_lonlat if result.path_lonlat is not None else \
        path_lonlat(world, result.path)
    coords = np.asarray(lonlat).tolist()
    if len(coords) == 1:  # start == goal: a LineString needs two positions (RFC 7946)
        coords *= 2
    return {"type": "FeatureCollection", "features": [{
        "type": "Feature",
        "geometry": {"type": "LineString", "coordinates": coords},
        "properties": props}]}


def plot_world_path(world: World, result: PlanResult, start, goal, path: str | Path, *,
                    edges: np.ndarray | None = None, dpi: int = 150,
                    obstacles: str = "obstacles", targets: np.ndarray | None = None) -> Path:
    """Write the PNG ``skyroute plan-world --plot`` and ``fly --plot`` write:
    :func:`draw_world_path` on an 8 x 8 inch figure, the legend beside the map."""
    fig, ax = new_figure((8, 8))
    draw_world_path(ax, world, result, start, goal, edges=edges, obstacles=obstacles,
                    targets=targets, legend=True)
    return save_figure(fig, path, dpi=dpi)


def draw_world_path(ax, world: World, result: PlanResult | None = None, start=None,
                    goal=None, *, edges: np.ndarray | None = None,
                    obstacles: str = "obstacles", targets: np.ndarray | None = None,
                    legend: bool = False):
    """Draw obstacles (grey), the boundary (dashed), roadmap edges (thin, plane
    segments), the path, start (green dot) and goal (red star) onto a matplotlib Axes:
    what ``skyroute plan-world --plot`` draws. Returns ``ax``.

    ``result.path``, ``start``, ``goal`` and ``targets`` are in the world's frame (as
    :func:`skyroute.plan` takes and returns them); the axes are its plane: east and north
    metres (x east, true proportions), or lon/lat in the degrees frame, so a "ned"
    world's (north, east) points are drawn turned into (east, north); draw anything else
    through :meth:`World.to_plane`. The legend names start and goal as given.
    ``obstacles`` is the grey shapes' legend entry (:func:`obstacles_label` says at
    which altitude and grown by what margin the world was loaded, which the world itself
    does not record). ``targets`` (a tour's; ``goal`` None) are drawn numbered as given.
    The artists are labelled for ``ax.legend()``; ``legend=True`` puts it beside the map
    and widens the figure for it, as the pictures written to files have it.

    >>> import shapely, skyroute
    >>> from matplotlib.figure import Figure
    >>> w = skyroute.World([shapely.box(1, 1, 3, 3)], [0], [50], ("tower",))
    >>> r = skyroute.plan(w, (0, 2), (4, 2))
    >>> ax = draw_world_path(Figure().subplots(), w, r, (0, 2), (4, 2))
    >>> ax.get_title(), ax.get_xlabel()
    ('world: visibility, 4.82843 m', 'east (m)')
    """
    draw_world(ax, world, label=obstacles)
    if edges is not None and len(edges):
        from matplotlib.collections import LineCollection

        name = result.algorithm if result is not None else "roadmap"
        ax.add_collection(LineCollection(edges, colors="tab:cyan", linewidths=0.3, alpha=0.5,
                                         label=f"{name} graph ({len(edges):,} edges)"))
    if result is not None and result.found:
        draw_path(ax, world.to_plane(result.path, "path"), lw=1.8)
    if start is not None:
        mark_ends(ax, world.to_plane(start, "start")[0],
                  None if goal is None else world.to_plane(goal, "goal")[0],
                  start_text=_point(world, start),
                  goal_text="" if goal is None else _point(world, goal))
    if targets is not None:
        pts = world.to_plane(np.asarray(targets, dtype=float).reshape(-1, 2), "targets")
        ax.plot(*pts.T, "D", color="tab:red", ms=7, markeredgecolor="white",
                markeredgewidth=0.8, clip_on=False, zorder=6, linestyle="none",
                label=f"targets ({len(pts)}), numbered as given")
    if result is not None:
        unit = "deg" if world.plane == "degrees" else "m"
        cost = f"{result.cost:.6g} {unit}" if result.found else result.status.value
        set_title(ax, [f"{world.name}: {result.algorithm}", cost])
    else:
        set_title(ax, [world.name])
    frame_axes(ax, world)
    if legend:
        legend_outside(ax)
    if targets is not None:
        place_labels(ax, pts, [str(k + 1) for k in range(len(pts))],
                     avoid=() if start is None else world.to_plane(start, "start"))
    return ax


def obstacles_label(altitude: float | None, safety: float, frame: str) -> str:
    """What the grey shapes of a world loaded by :func:`skyroute.load_world` with
    ``altitude``, ``safety`` and ``frame`` are: the obstacles that count at that altitude
    (all of them for None), already grown by the margin (metres; degrees in the degrees
    frame), e.g. ``obstacles at 10 m, grown by 2 m``."""
    at = "all altitudes" if altitude is None else f"{altitude:g} m"
    unit = "deg" if frame == "degrees" else "m"
    grown = f", grown by {safety:g} {unit}" if safety > 0 else ""
    return f"obstacles at {at}{grown}"


def _point(world: World, p) -> str:
    """A point as it was typed, in the world's frame and named by its axes
    (:data:`~skyroute.world.world.AXES`): ``(north 120 m, east -180 m)``."""
    a, b = AXES[world.frame]
    unit = "" if world.frame in ("lonlat", "degrees") else " m"
    x, y = np.asarray(p, dtype=float).reshape(-1)[:2]
    return f"({a} {x:.7g}{unit}, {b} {y:.7g}{unit})"


def draw_world(ax, world: World, *, label: str = "obstacles") -> None:
    """Obstacles filled grey (holes white; ``label`` in the legend) and the boundary
    dashed.

    The obstacles go in two collections, not one patch each: a city of thousands of
    boxes then draws (and places the legend) in a fraction of a second."""
    import shapely
    from matplotlib.collections import PolyCollection

    shells, holes = [], []
    for poly in world.obstacles:
        for part in getattr(poly, "geoms", [poly]):
            shells.append(np.asarray(part.exterior.coords))
            holes.extend(np.asarray(hole.coords) for hole in part.interiors)
    for rings, colour, name in ((shells, "0.45", label), (holes, "white", None)):
        if rings:
            ax.add_collection(PolyCollection(rings, facecolors=colour, linewidths=0,
                                             label=name))
    ax.autoscale_view()
    if world.boundary is not None:
        x, y = shapely.Polygon(world.boundary).exterior.xy
        ax.plot(x, y, "--", color="tab:orange", lw=1.2, label="boundary")


def finish_axes(ax, world: World) -> None:
    """:func:`frame_axes`, and the legend beside the map."""
    frame_axes(ax, world)
    legend_outside(ax)


def frame_axes(ax, world: World) -> None:
    """Axis names with units, true proportions (degrees squeezed by cos latitude), plain
    tick numbers (no "+5.594e1" offset on latitudes)."""
    degrees = world.plane == "degrees"
    ax.set_xlabel("longitude (°)" if degrees else "east (m)")
    ax.set_ylabel("latitude (°)" if degrees else "north (m)")
    ax.set_aspect("equal" if world.plane == "metres" else
                  1 / np.cos(np.radians(np.mean(ax.get_ylim()))))
    ax.ticklabel_format(useOffset=False, style="plain")
