"""The leg table's disk cache (``delivery/legs.py``): a table kept by an earlier
``plan_moves`` whose answers differ is not read as this one's."""

import json

import pytest

import skyroute
from skyroute.delivery import legs
from tests.conftest import SHARED

ILP = SHARED / "ilp2021"
pytestmark = pytest.mark.shared_data
AREA = (-3.192473, 55.942617, -3.184319, 55.946233)


def _area_point(u, v):
    return (AREA[0] + u * (AREA[2] - AREA[0]), AREA[1] + v * (AREA[3] - AREA[1]))


def test_a_table_kept_before_the_default_budget_grew_is_not_read(monkeypatch, tmp_path):
    """This pair needs 215,220 expansions; under plan_moves' old default budget
    (200,000) it ran out, and the leg table kept it as "no flight" (-1) on disk, keyed
    by the table's VERSION 1. The default budget is now every state of the area, the pair
    is 36 moves, and a table kept before must not answer -1 for it (the version is part
    of the file's key: it was not bumped, and the old -1 was read back)."""
    world = skyroute.load_world(ILP / "website/buildings/no-fly-zones.geojson",
                                frame="degrees",
                                boundary=ILP / "testing/confinement-zone.geojson")
    monkeypatch.setenv("SKYROUTE_CACHE", str(tmp_path))
    a, b = _area_point(0.75, 0.75), _area_point(0.1875, 0.5)
    with monkeypatch.context() as m:  # the file the old plan_moves left
        m.setattr(legs, "VERSION", 1)
        stale = tmp_path / f"legs-{legs._world_key(world)}.json"
    stale.write_text(json.dumps({legs._pair(a, b): -1}))
    table = legs.leg_table(world, [a, b])
    assert table[0, 1] == 36
