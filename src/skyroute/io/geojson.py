"""A planned path as GeoJSON."""

from __future__ import annotations

from skyroute.io.json_text import to_json
from skyroute.result import PlanResult
from skyroute.world.grid import Grid


def grid_path_geojson(grid: Grid, result: PlanResult) -> dict:
    """A FeatureCollection with the path as a LineString in the grid's world frame.

    Coordinates are metres (x, y) of cell centres, not longitude/latitude: a grid has no
    geodetic anchor, so the file carries planar coordinates in its local frame, as the
    properties say. Properties repeat the result's status, cost and statistics.
    """
    coords = grid.to_world(result.path).tolist() if result.found else []
    if len(coords) == 1:  # start == goal: a LineString needs two positions (RFC 7946)
        coords *= 2
    props = {k: v for k, v in result.to_dict().items() if k != "path"}
    props.update(map=grid.name, frame="grid-local metres", resolution=grid.resolution,
                 cells=result.path.tolist())
    return {
        "type": "FeatureCollection",
        "features": [{
            "type": "Feature",
            "geometry": {"type": "LineString", "coordinates": coords},
            "properties": props,
        }],
    }


def dumps(obj: dict) -> str:
    """Compact, stable JSON text."""
    return to_json(obj, separators=(",", ":")) + "\n"
