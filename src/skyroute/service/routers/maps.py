"""``GET /maps`` (the bundled MovingAI maps) and ``GET /maps/{name}`` (one map's rows,
for the viewer's canvas)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Path
from pydantic import BaseModel, Field

from skyroute.service.problems import Problem, responses
from skyroute.service.resources import ResourcesDep
from skyroute.world.movingai import BLOCKED, PASSABLE

router = APIRouter(tags=["maps"])


class MapInfo(BaseModel):
    name: str
    width: int
    height: int


class MapRows(MapInfo):
    rows: list[str] = Field(description="The map's lines, top row (y = 0) first, one "
                            "MovingAI terrain letter per cell (x = 0 first).")
    passable: str = Field(PASSABLE, description="Letters of passable cells.")
    blocked: str = Field(BLOCKED, description="Letters of blocked cells.")


@router.get("/maps", response_model=list[MapInfo], summary="The bundled maps")
def list_maps(res: ResourcesDep) -> list[MapInfo]:
    from skyroute.world.load import bundled_maps

    out = []
    for name in bundled_maps():
        g = res.grid(name)
        out.append(MapInfo(name=name, width=g.width, height=g.height))
    return out


@router.get("/maps/{name}", response_model=MapRows, responses=responses(404),
            summary="One bundled map's rows")
def get_map(name: Annotated[str, Path(max_length=200)],
            res: ResourcesDep) -> MapRows:
    from skyroute.world.load import bundled_maps

    key = f"map-rows:{name}"
    if key not in res.cache:
        maps = bundled_maps()
        if name not in maps:
            raise Problem(404, f"no bundled map {name!r}; the maps are "
                          + ", ".join(repr(m) for m in maps), kind="unknown-map")
        g = res.grid(name)
        lines = maps[name].read_text().replace("\r\n", "\n").split("\n")[4:4 + g.height]
        res.cache[key] = MapRows(name=name, width=g.width, height=g.height, rows=lines)
    return res.cache[key]
