"""Inputs beyond what a local plane or lon/lat can hold are refused with one message
naming the input, where they used to crash a conversion (NaN, GEOS, PROJ) or, for a huge
safety, plan straight through the obstacle; and the searches that raster or sample a
world do so over the extent the query needs."""

import json
import math

import numpy as np
import pytest
import shapely

import skyroute
from skyroute import InputFormatError, OptionError, QueryError
from skyroute.roadmap.prm import PRM
from skyroute.roadmap.raster import default_resolution
from skyroute.world.points import MAX_METRES

HOME = "lat0 55.944494, lon0 -3.186874"
HEADER = "posX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ"


def _city(tmp_path, rows="10,10,5,1,1,5\n"):
    path = tmp_path / "c.csv"
    path.write_text(f"{HOME}\n{HEADER}\n{rows}")
    return path


def _zones(tmp_path, ring):
    path = tmp_path / "z.geojson"
    feature = {"type": "Feature", "properties": {"name": "far"},
               "geometry": {"type": "Polygon", "coordinates": [ring]}}
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}))
    return path


@pytest.mark.parametrize("frame,point", [("ned", (1e300, 0)), ("enu", (0, -2e7)),
                                         ("ned", (MAX_METRES * 1.01, 5.0))])
def test_a_point_far_beyond_the_local_plane_is_a_query_error(tmp_path, frame, point):
    world = skyroute.load_world(_city(tmp_path), frame=frame)
    with pytest.raises(QueryError, match=r"^start .* lies more than 1e\+07 m from home"):
        skyroute.plan(world, point, (50.0, 50.0))


def test_a_point_within_the_plane_still_plans(tmp_path):
    world = skyroute.load_world(_city(tmp_path), frame="ned")
    r = skyroute.plan(world, (0.0, 0.0), (MAX_METRES / 2, 0.0))
    assert r.found and math.isclose(r.cost, MAX_METRES / 2)


@pytest.mark.parametrize("row", ["1e308,10,5,1e308,2,5", "0,9999999,5,2,2,5",
                                 "0,0,5,1,1,1e8"])
def test_a_box_reaching_beyond_the_plane_names_its_line(tmp_path, row):
    with pytest.raises(InputFormatError, match="the box reaches more than") as err:
        skyroute.load_world(_city(tmp_path, f"10,10,5,1,1,5\n{row}\n"))
    assert err.value.line == 4


@pytest.mark.parametrize("ring", [
    [[-3.188, 95], [-3.187, 95], [-3.187, 96], [-3.188, 96], [-3.188, 95]],
    [[-200, -10], [200, -10], [200, 10], [-200, 10], [-200, -10]]])
def test_zones_off_the_globe_name_the_feature(tmp_path, ring):
    with pytest.raises(InputFormatError, match=r"feature 0 \('far'\): a vertex .* is not "
                       "a place"):
        skyroute.load_world(_zones(tmp_path, ring))


def test_a_boundary_box_off_the_globe_is_an_option_error(tmp_path):
    ring = [[-3.188, 55.9], [-3.187, 55.9], [-3.187, 55.91], [-3.188, 55.91], [-3.188, 55.9]]
    with pytest.raises(OptionError, match="is not a place") as err:
        skyroute.load_world(_zones(tmp_path, ring), boundary="-3.2,55.8,-3.1,95")
    assert err.value.param == "boundary"


@pytest.mark.parametrize("safety", [1.3e154, 1e200, MAX_METRES * 2])
def test_a_safety_beyond_the_plane_is_refused(tmp_path, safety):
    # 1e200 used to buffer the box into NaN and plan straight through it
    with pytest.raises(OptionError, match="must be at most") as err:
        skyroute.load_world(_city(tmp_path), frame="ned", safety=safety)
    assert err.value.param == "safety"


def test_a_large_safety_within_the_limit_still_blocks(tmp_path):
    world = skyroute.load_world(_city(tmp_path), frame="ned", safety=1e5)
    with pytest.raises(QueryError, match="inside obstacle"):
        skyroute.plan(world, (0.0, 0.0), (50.0, 50.0))


def test_prm_samples_around_obstacles_that_fill_their_own_bounds(tmp_path):
    # one box: its bounds hold no free point, the free space is around it
    world = skyroute.load_world(_city(tmp_path), frame="ned")
    r = skyroute.plan(world, (0.0, 0.0), (50.0, 50.0), algorithm="prm", samples=50)
    assert r.found
    a, b = r.path[:-1], r.path[1:]
    box = shapely.box(9, 9, 11, 11)
    assert not shapely.intersects(shapely.linestrings(np.stack([a, b], 1)), box).any()


def test_prm_with_no_free_space_is_an_option_error(tmp_path):
    ring = [[-3.2, 55.9], [-3.1, 55.9], [-3.1, 56.0], [-3.2, 56.0], [-3.2, 55.9]]
    path = _zones(tmp_path, ring)
    world = skyroute.load_world(path, boundary="-3.19,55.91,-3.11,55.99")
    with pytest.raises(OptionError, match="needs at least 2") as err:
        PRM(world, samples=20)
    assert err.value.param == "samples"


def test_default_resolution_spans_the_query_not_only_the_obstacles(tmp_path):
    # a 2 m box and a query 50 m away: 1000 cells across the box alone made a
    # 25,000 x 25,000 raster, refused as too large
    world = skyroute.load_world(_city(tmp_path), frame="ned")
    s, t = world.to_plane([(0.0, 0.0), (50.0, 50.0)])
    assert default_resolution(world) == pytest.approx(2 / 1000)
    assert default_resolution(world, [s, t]) == pytest.approx(50 / 1000)
    r = skyroute.plan(world, (0.0, 0.0), (50.0, 50.0), algorithm="astar")
    assert r.found and r.extra["resolution"] == pytest.approx(0.05)
