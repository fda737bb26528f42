"""A path planned on a World as FCND waypoints, lon/lat GeoJSON, and a PNG map.

Paths and points come in the world's frame (as :func:`skyroute.plan` returns them);
pictures are drawn in its plane (east/north metres, or lon/lat in degrees)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from skyroute.geo import heading_of, lonlat_to_enu
from skyroute.io.plot import save_figure
from skyroute.result import PlanResult
from skyroute.world.world import World


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


def waypoints(world: World, path: np.ndarray, altitude: float) -> list[list[float]]:
    """[[north, east, altitude, heading], ...] relative to home; heading (radians, 0 north,
    clockwise) along the track into each point, the first taking the first leg's."""
    ne = path_north_east(world, path)
    if len(ne) == 0:
        return []
    d = np.diff(ne, axis=0)
    legs = heading_of(d[:, 1], d[:, 0]) if len(d) else np.zeros(0)
    headings = np.concatenate([legs[:1] if len(legs) else [0.0], legs])
    return [[float(n), float(e), float(altitude), float(h)]
            for (n, e), h in zip(ne, headings, strict=True)]


def world_path_geojson(world: World, result: PlanResult) -> dict:
    """A FeatureCollection with the path as a LineString in lon/lat (RFC 7946)."""
    props = {k: v for k, v in result.to_dict().items() if k not in ("path", "path_lonlat")}
    props.update(world=world.name, frame=world.frame)
    lonlat = result.path_lonlat if result.path_lonlat is not None else \
        path_lonlat(world, result.path)
    return {"type": "FeatureCollection", "features": [{
        "type": "Feature",
        "geometry": {"type": "LineString", "coordinates": np.asarray(lonlat).tolist()},
        "properties": props}]}


def plot_world_path(world: World, result: PlanResult, start, goal, path: str | Path, *,
                    edges: np.ndarray | None = None, dpi: int = 150) -> Path:
    """Draw obstacles (grey), the boundary (dashed), roadmap edges (thin, plane
    segments), the path; ``result.path``, ``start`` and ``goal`` in the world's frame."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 8))
    draw_world(ax, world)
    if edges is not None and len(edges):
        from matplotlib.collections import LineCollection

        ax.add_collection(LineCollection(edges, colors="tab:cyan", linewidths=0.3, alpha=0.5,
                                         label=f"{result.algorithm} graph "
                                               f"({len(edges):,} edges)"))
    if result.found:
        p = world.to_plane(result.path, "path")
        ax.plot(p[:, 0], p[:, 1], "-o", color="tab:blue", lw=1.8, ms=3, label="path")
    ax.plot(*world.to_plane(start, "start")[0], "o", color="tab:green", ms=9, label="start")
    ax.plot(*world.to_plane(goal, "goal")[0], "*", color="tab:red", ms=13, label="goal")
    unit = "deg" if world.plane == "degrees" else "m"
    cost = f"{result.cost:.6g} {unit}" if result.found else result.status.value
    ax.set_title(f"{world.name}: {result.algorithm}, {cost}", fontsize=10)
    finish_axes(ax, world, legend_below=edges is not None and len(edges) > 0)
    return save_figure(fig, path, dpi=dpi)


def draw_world(ax, world: World) -> None:
    """Obstacles filled grey (holes white) and the boundary dashed.

    The obstacles go in two collections, not one patch each: a city of thousands of
    boxes then draws (and places the legend) in a fraction of a second."""
    import shapely
    from matplotlib.collections import PolyCollection

    shells, holes = [], []
    for poly in world.obstacles:
        for part in getattr(poly, "geoms", [poly]):
            shells.append(np.asarray(part.exterior.coords))
            holes.extend(np.asarray(hole.coords) for hole in part.interiors)
    for rings, colour in ((shells, "0.45"), (holes, "white")):
        if rings:
            ax.add_collection(PolyCollection(rings, facecolors=colour, linewidths=0))
    ax.autoscale_view()
    if world.boundary is not None:
        x, y = shapely.Polygon(world.boundary).exterior.xy
        ax.plot(x, y, "--", color="tab:orange", lw=1.2, label="boundary")


def finish_axes(ax, world: World, *, legend_below: bool = False) -> None:
    """Axis names, true proportions (degrees squeezed by cos latitude), a legend (below
    the axes when lines cover the whole map and no place inside is free)."""
    ax.set_xlabel("longitude" if world.plane == "degrees" else "east (m)")
    ax.set_ylabel("latitude" if world.plane == "degrees" else "north (m)")
    ax.set_aspect("equal" if world.plane == "metres" else
                  1 / np.cos(np.radians(np.mean(ax.get_ylim()))))
    if legend_below:
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.08), ncol=4, fontsize=8,
                  frameon=False)
    else:
        ax.legend(loc="best", fontsize=8, framealpha=0.9)
