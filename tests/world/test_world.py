"""Worlds: loaders (colliders.csv, GeoJSON), exact queries, the FCND city, bad input."""

import json
import math

import numpy as np
import pytest
import shapely

import skyroute
from skyroute import InputFormatError, OptionError, QueryError
from skyroute.geo import lonlat_to_enu
from tests.conftest import ROOT, SHARED

FCND = SHARED / "fcnd" / "colliders.csv"
ILP = SHARED / "ilp2021"


def write(path, text):
    path.write_text(text)
    return path


COLLIDERS = ("lat0 37.792480, lon0 -122.397450\nposX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n"
             "10,0,5,2,3,5\n-20,20,40,5,5,40\n")


def test_colliders_boxes_heights_and_safety(tmp_path):
    w = skyroute.load_world(write(tmp_path / "c.csv", COLLIDERS), safety=1.0)
    assert len(w.obstacles) == 2 and w.home.lat == 37.79248 and w.home.lon == -122.39745
    # box 0: north 10 +- 2, east 0 +- 3, grown by 1: x = east in [-4, 4], y = north in [7, 13]
    assert w.obstacles[0].bounds == (-4.0, 7.0, 4.0, 13.0)
    np.testing.assert_allclose(w.ceilings, [11.0, 81.0])
    assert len(skyroute.load_world(tmp_path / "c.csv", safety=1.0, altitude=20).obstacles) == 1
    assert len(skyroute.load_world(tmp_path / "c.csv", altitude=10).obstacles) == 1  # top 10


@pytest.mark.parametrize("text, line, words", [
    ("lat0 x\nposX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n1,2,3,4,5,6\n", 1, "lat0"),
    ("lat0 37.0, lon0 -122.0\nposX,posY\n1,2,3,4,5,6\n", 2, "header"),
    ("lat0 37.0, lon0 -122.0\nposX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n1,2,3,4,5\n", 3,
     "expected 6 numbers"),
    ("lat0 37.0, lon0 -122.0\nposX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n1,2,3,4,5,6\n"
     "1,2,x,4,5,6\n", 4, "expected 6 numbers"),
])
def test_bad_colliders_name_the_line(tmp_path, text, line, words):
    p = write(tmp_path / "bad.csv", text)
    with pytest.raises(InputFormatError) as err:
        skyroute.load_world(p)
    assert err.value.line == line and words in str(err.value)


def fc(*features):
    return json.dumps({"type": "FeatureCollection", "features": list(features)})


def feature(geom, **props):
    return {"type": "Feature", "geometry": geom, "properties": props}


SQUARE = {"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]]]}


@pytest.mark.parametrize("text, words", [
    (fc(feature({"type": "Point", "coordinates": [0, 0]}, name="pin")),
     "feature 0 ('pin') is a Point; only Polygon and MultiPolygon"),
    (fc(feature({"type": "Polygon", "coordinates": [[[0, 0], [2, 2], [2, 0], [0, 2], [0, 0]]]},
                name="bow")), "feature 0 ('bow') is not a valid polygon: Self-intersection"),
    ('{"type": "Feature"}', "expected a GeoJSON FeatureCollection"),
    ("{not json", "not JSON"),
])
def test_bad_geojson_names_the_feature(tmp_path, text, words):
    p = write(tmp_path / "z.geojson", text)
    with pytest.raises(InputFormatError, match=None) as err:
        skyroute.load_world(p, frame="degrees")
    assert words in str(err.value) and str(p) in str(err.value)


def test_geojson_boundary_from_feature_bbox_or_file(tmp_path):
    box = {"type": "Polygon", "coordinates": [[[-1, -1], [3, -1], [3, 3], [-1, 3], [-1, -1]]]}
    p = write(tmp_path / "z.geojson", fc(feature(SQUARE, name="zone"),
                                         feature(box, name="Drone confinement zone")))
    w = skyroute.load_world(p, frame="degrees")
    assert len(w.obstacles) == 1 and w.boundary.bounds == (-1, -1, 3, 3)
    w2 = skyroute.load_world(p, frame="degrees", boundary="-2,-2,4,4")
    assert w2.boundary.bounds == (-2, -2, 4, 4)
    with pytest.raises(OptionError, match="min must be below max"):
        skyroute.load_world(p, frame="degrees", boundary="4,4,-2,-2")


def test_exact_point_and_segment_queries():
    w = skyroute.World(shapely.box(np.array([0.0]), 0, 1, 1), [-np.inf], [np.inf], ("sq",),
                       shapely.box(-5, -5, 5, 5))
    assert w.is_free([[1, 0.5], [0.5, 0.5], [5, 0], [2, 2]]).tolist() == [True, False, False,
                                                                          True]
    assert w.segment_free((-1, 1), (2, 1))        # along the top edge: touching
    assert not w.segment_free((-1, 0.5), (2, 0.5))  # through the interior
    assert not w.segment_free((-1, -1), (6, -1))    # leaves the boundary
    assert w.segment_free((-1, 0), (0, 1)) and w.clearance([[3, 0.5]])[0] == 2.0


@pytest.mark.shared_data
def test_ilp_zones_in_degrees_and_metres():
    w = skyroute.load_world(ILP / "website/buildings/no-fly-zones.geojson", frame="degrees",
                            boundary=ILP / "testing/confinement-zone.geojson")
    assert len(w.obstacles) == 5 and w.boundary.bounds == (-3.192473, 55.942617, -3.184319,
                                                           55.946233)
    at = (-3.186874, 55.944494)  # Appleton Tower
    r = skyroute.plan(w, at, (-3.1913, 55.9455))
    assert r.found and all(w.segment_free(a, b) for a, b in zip(r.path[:-1], r.path[1:],
                                                                strict=True))
    m = skyroute.load_world(ILP / "website/buildings/no-fly-zones.geojson", frame="lonlat")
    # the zones span 0.00326 degrees of longitude: about 203 m at 55.94 N
    assert m.frame == "lonlat" and m.plane == "metres" and 200 < m.bounds[2] - m.bounds[0] < 206


@pytest.mark.shared_data
def test_fcnd_home_to_goal_is_free_and_theta_within_one_percent():
    w = skyroute.load_world(FCND, altitude=5, safety=5, frame="enu")
    goal = lonlat_to_enu(-122.396428, 37.795232, 0.0, w.home)[0, :2]
    exact = skyroute.plan(w, (0, 0), goal)
    assert exact.found
    for a, b in zip(exact.path[:-1], exact.path[1:], strict=True):
        assert w.segment_free(a, b)
    theta = skyroute.plan(w, (0, 0), goal, algorithm="theta", resolution=1.0)
    assert theta.found and exact.cost <= theta.cost <= 1.01 * exact.cost
    for a, b in zip(theta.path[:-1], theta.path[1:], strict=True):
        assert w.segment_free(a, b)
    # straight-line distance is a lower bound, the rasterised A* path an upper one
    assert math.dist((0, 0), goal) <= exact.cost


@pytest.mark.shared_data
def test_fcnd_prm_and_grid_paths_are_free():
    w = skyroute.load_world(FCND, altitude=5, safety=5, frame="enu")
    goal = lonlat_to_enu(-122.396428, 37.795232, 0.0, w.home)[0, :2]
    exact = skyroute.plan(w, (0, 0), goal).cost
    for algorithm, kw in (("prm", {"samples": 1500, "seed": 3}), ("jps", {"resolution": 2.0})):
        r = skyroute.plan(w, (0, 0), goal, algorithm=algorithm, **kw)
        assert r.found and r.cost >= exact - 1e-9
        for a, b in zip(r.path[:-1], r.path[1:], strict=True):
            assert w.segment_free(a, b)
    with pytest.raises(QueryError, match="lies inside obstacle 'box at line"):
        skyroute.plan(w, (-310.2, -439.2)[::-1], goal)


def test_repr_summarises_the_world():
    world = skyroute.World([shapely.box(0, 0, 1, 1)] * 3, 0.0, 10.0, (),
                           boundary=shapely.box(-5, -5, 5, 5), name="three")
    assert repr(world) == "<World 'three': 3 obstacles, a boundary, frame 'enu'>"


def _tower() -> skyroute.World:
    return skyroute.World([shapely.box(1, 1, 3, 3)], [0], [50], ("tower",))


@pytest.mark.parametrize("algorithm", ["astar", "theta", "jps"])
def test_grid_planners_pass_round_an_obstacle_that_spans_an_unbounded_world(algorithm):
    # the raster ended at the obstacle's own bounds: "no_path" where the visibility graph
    # found 4.83 (the README's example world)
    exact = skyroute.plan(_tower(), (0, 2), (4, 2))
    r = skyroute.plan(_tower(), (0, 2), (4, 2), algorithm=algorithm, resolution=0.1)
    assert r.found and exact.cost - 1e-9 <= r.cost <= exact.cost * 1.1


@pytest.mark.parametrize("algorithm", ["astar", "theta"])
@pytest.mark.parametrize("frame", ["ned", "lonlat"])
def test_a_raster_past_the_local_plane_is_refused_naming_resolution(algorithm, frame):
    """A resolution whose raster (8 cells round the obstacles and points) reaches past
    the 1e7 m of a local plane: a path "more than 1e+07 m from home" (ned), or through
    far-off lon/lat, came back instead."""
    w = skyroute.load_world(ROOT / "examples" / "city.csv", altitude=10, frame=frame)
    a, b = (w.from_plane([p])[0] for p in ((0.0, 0.0), (100.0, 100.0)))
    with pytest.raises(OptionError, match=r"resolution=2e\+06 makes a raster reaching "
                       r"1.6e\+07 m from home.*finer resolution") as info:
        skyroute.plan(w, a, b, algorithm=algorithm, resolution=2e6)
    assert info.value.param == "resolution"
    r = skyroute.plan(w, a, b, algorithm=algorithm, resolution=1e6)  # 8e6 m: in the plane
    assert r.found and np.abs(w.to_plane(r.path)).max() <= 1e7


@pytest.mark.parametrize("kw", [{"resolution": "1"}, {"resolution": [1]},
                                {"safety": "1"}, {"safety": [1]}, {"altitude": "x"},
                                {"bounds": (0, 0, 1)}])
def test_rasterize_names_a_bad_option(kw):
    # a numpy TypeError or ValueError before
    kw = {"resolution": 0.5, **kw}
    name = next(k for k in kw if k != "resolution") if len(kw) > 1 else "resolution"
    with pytest.raises(OptionError, match=f"{name}="):
        _tower().rasterize(**kw)


def test_rasterize_takes_numpy_numbers():
    a = _tower().rasterize(np.array(0.5), safety=np.float32(0.25))
    b = _tower().rasterize(0.5, safety=0.25)
    assert np.array_equal(a.blocked, b.blocked)


@pytest.mark.parametrize("kw", [{"altitude": float("nan")}, {"altitude": "10"},
                                {"altitude": [10]}, {"safety": "1"}, {"safety": True}])
def test_load_world_names_a_bad_altitude_or_safety(kw):
    # altitude=nan kept no building (an empty city), [10] was taken, "1" a TypeError
    (name, _), = kw.items()
    with pytest.raises(OptionError, match=f"{name}="):
        skyroute.load_world("examples/city.csv", **kw)


@pytest.mark.parametrize("query", ["is_free", "inside", "blocking", "clearance"])
def test_point_queries_refuse_three_columns(query):
    # an (N, 3) array was read as 3N/2 points: two rows of three gave three answers
    with pytest.raises(QueryError, match=r"got shape \(2, 3\)"):
        getattr(_tower(), query)([[0, 2, 0], [4, 2, 0]])
    assert len(getattr(_tower(), query)([])) == 0


def test_segment_queries_refuse_unequal_ends():
    with pytest.raises(QueryError, match="as many points"):
        _tower().segments_free([[0, 0]], [[1, 1], [2, 2]])


def test_a_loaded_world_keeps_the_path_it_was_given_through_views_and_pickling(tmp_path,
                                                                               monkeypatch):
    import pickle

    monkeypatch.chdir(tmp_path)
    (tmp_path / "sub").mkdir()
    write(tmp_path / "sub" / "c.csv", COLLIDERS)
    w = skyroute.load_world("sub/c.csv", boundary="-122.4,37.79,-122.39,37.80")
    assert (w.name, w.source, w.where) == ("c.csv", "sub/c.csv", "sub/c.csv")
    for view in (w.at(10.0), w.merged(), w.in_frame("ned"), w.in_frame("degrees"),
                 pickle.loads(pickle.dumps(w))):
        assert (view.name, view.source) == ("c.csv", "sub/c.csv")
    again = skyroute.load_world(tmp_path / "sub" / "c.csv")
    assert again.source == str(tmp_path / "sub" / "c.csv")
    assert w == w and w != again  # a World is equal only to itself, as before
    built = skyroute.World(w.obstacles, w.floors, w.ceilings, w.names, name="mine")
    assert built.source is None and built.where == "mine"


def test_an_empty_world_path_is_named_as_such():
    """``load_world("")`` read the folder "." (Path("")): ".: unknown world type ''", as
    load_map's empty path said "a folder, not a map file" before it was named."""
    with pytest.raises(OptionError, match=r"^path='' is empty: give a colliders\.csv "
                       r"city or a GeoJSON file$") as info:
        skyroute.load_world("")
    assert info.value.param == "path"


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_a_world_built_with_a_vertex_not_finite_is_refused_naming_it(bad):
    """The loaders refuse NaN and infinity in a file, but a World built in code took them:
    the step drone's plan_moves then raised numpy's "cannot convert float NaN to integer"
    for a NaN (its edge grid; before the grid it flew 30 moves round whatever the kernels
    made of the ring) and GEOS's "encountered NaN/Inf numbers" for an infinity."""
    ring = [(0, 0), (1e-3, 0), (1e-3, bad), (0, 1e-3)]
    with pytest.raises(OptionError, match=r"^obstacle 1 \('tower'\) has a vertex that is "
                       r"not finite \(0\.001, -?(nan|inf)\)"):
        skyroute.World([shapely.box(5, 5, 6, 6), shapely.Polygon(ring)], 0, 1,
                       ("hall", "tower"), frame="degrees")
    with pytest.raises(OptionError, match=r"^the boundary has a vertex that is not finite"):
        skyroute.World([], 0, 1, (), boundary=shapely.Polygon([(-1, -1), (1, -1), (bad, 1)]))
