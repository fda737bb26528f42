"""GeoJSON worlds as users bring them: Windows files, malformed features, a feature
written (lat, lon), the antimeridian, a file too large; each a one-line error naming the
file and the feature, or read as the plain file is."""

import json

import pytest
import shapely

import skyroute
from skyroute import InputFormatError, QueryError
from skyroute.world import geojson_world
from skyroute.world.geojson_world import read_geojson_world
from tests.cli.test_cli import run


def square(lon, lat, d=0.002):
    return [[lon, lat], [lon + d, lat], [lon + d, lat + d], [lon, lat + d], [lon, lat]]


def polygon(ring, **props):
    return {"type": "Feature", "properties": props,
            "geometry": {"type": "Polygon", "coordinates": [ring]}}


ZONE = polygon(square(-3.19, 55.943), name="zone")
AREA = polygon(square(-3.195, 55.940, 0.01), name="confinement area")


def write(path, *features):
    path.write_text(json.dumps({"type": "FeatureCollection", "features": list(features)}))
    return path


def refused(path, words, **kw):
    with pytest.raises(InputFormatError) as err:
        skyroute.load_world(path, **kw)
    assert str(err.value).startswith(f"{path}: ") and words in str(err.value), str(err.value)
    return str(err.value)


def test_a_byte_order_mark_is_read_past(tmp_path):
    plain = write(tmp_path / "z.geojson", ZONE, AREA)
    bom = tmp_path / "bom.geojson"
    bom.write_bytes(b"\xef\xbb\xbf" + plain.read_bytes().replace(b"\n", b"\r\n"))
    a, b = skyroute.load_world(plain), skyroute.load_world(bom)
    assert list(b.obstacles) == list(a.obstacles) and b.boundary == a.boundary
    upload = read_geojson_world("upload.geojson", text="\ufeff" + plain.read_text())
    assert list(upload.obstacles) == list(a.obstacles)


def test_a_file_past_the_byte_limit_is_refused_before_it_is_read(tmp_path):
    path = tmp_path / "huge.geojson"
    with path.open("wb") as fh:  # sparse: no 10 MB written
        fh.truncate(geojson_world.MAX_BYTES + 1)
    with pytest.raises(InputFormatError) as err:
        skyroute.load_world(path)
    assert str(err.value) == (f"{path}: 10,000,001 bytes, over the limit of 10,000,000 for "
                              "a GeoJSON file")
    zones = write(tmp_path / "z.geojson", ZONE)  # a boundary file too
    with pytest.raises(InputFormatError, match="over the limit of 10,000,000 for a GeoJSON"):
        skyroute.load_world(zones, boundary=path)


@pytest.mark.parametrize("feature, words", [
    (1, "feature 1 is int 1, not a GeoJSON Feature object"),
    ([ZONE], "feature 1 is list"),
    ({"type": "Feature", "properties": {"name": "pin"}, "geometry": None},
     "feature 1 ('pin') has no geometry; only Polygon and MultiPolygon features are zones"),
    ({"type": "Feature", "properties": ["x"], "geometry": {"coordinates": []}},
     "feature 1 ('feature 1') has a geometry with no type"),
    ({"type": "Feature", "properties": None, "geometry": "Polygon"},
     "feature 1 ('feature 1') has a geometry with no type"),
    (polygon([], name="blank"), "feature 1 ('blank') has no coordinates"),
])
def test_a_malformed_feature_is_one_line_naming_it(tmp_path, feature, words):
    refused(write(tmp_path / "z.geojson", ZONE, feature), words)


def test_two_boundaries_or_a_multipolygon_boundary_are_refused(tmp_path):
    other = polygon(square(-3.2, 55.93, 0.05), boundary=True)
    refused(write(tmp_path / "z.geojson", ZONE, AREA, other),
            "two boundaries: feature 1 ('confinement area') and feature 2 ('feature 2')")
    multi = {"type": "Feature", "properties": {"name": "confinement"},
             "geometry": {"type": "MultiPolygon",
                          "coordinates": [[square(-3.195, 55.94, 0.004)],
                                          [square(-3.185, 55.94, 0.004)]]}}
    refused(write(tmp_path / "z.geojson", ZONE, multi),
            "feature 1 ('confinement') is the boundary, so it must be one Polygon, not a "
            "MultiPolygon")


def swapped(feature):
    ring = feature["geometry"]["coordinates"][0]
    return polygon([[lat, lon] for lon, lat in ring], name="swapped")


@pytest.mark.parametrize("frame", ["lonlat", "degrees"])
def test_a_feature_written_lat_lon_is_named_not_silently_far_away(tmp_path, frame):
    # it used to load, 7,800 km from the rest, guarding nothing the planner went near
    path = write(tmp_path / "z.geojson", ZONE, swapped(ZONE), AREA)
    text = refused(path, "feature 1 ('swapped') lies ", frame=frame)
    assert text.endswith(" km from the rest of the world (a world reaches at most 1,000 km "
                         "from its centre): are its coordinates (lat, lon)? GeoJSON and "
                         "boundary boxes are (lon, lat)")
    refused(write(tmp_path / "z.geojson", ZONE, swapped(AREA)), "feature 1 ('swapped') lies ")


def test_a_world_within_the_reach_still_loads(tmp_path):
    far = polygon(square(-3.19 + 12.0, 55.943), name="700 km east")  # 750 km apart
    w = skyroute.load_world(write(tmp_path / "z.geojson", ZONE, far))
    assert len(w.obstacles) == 2


def test_a_polygon_across_the_antimeridian_is_refused(tmp_path):
    ring = [[179.9, 10], [-179.9, 10], [-179.9, 10.1], [179.9, 10.1], [179.9, 10]]
    refused(write(tmp_path / "z.geojson", polygon(ring, name="dateline")),
            "feature 0 ('dateline') spans lon -179.9 to 179.9, across the antimeridian")
    east, west = polygon(square(179.9, 10, 0.09), name="e"), polygon(square(-180, 10, 0.09))
    refused(write(tmp_path / "z.geojson", east, west),
            "the zones span lon -180 to 179.99, across the antimeridian")


def test_a_point_outside_is_shown_as_given_with_a_hint_when_it_is_swapped(tmp_path):
    w = skyroute.load_world(write(tmp_path / "z.geojson", ZONE, AREA))
    with pytest.raises(QueryError) as err:  # the lon/lat round trip moved it far away
        skyroute.plan(w, (55.941, -3.194), (-3.186, 55.949))
    assert str(err.value).startswith("start (55.9410000, -3.1940000) lies outside the map")
    assert str(err.value).endswith("; (-3.1940000, 55.9410000) is inside: points are "
                                   "(lon, lat)")
    with pytest.raises(QueryError) as err:
        skyroute.plan(w, (-3.3, 55.941), (-3.186, 55.949))
    assert str(err.value).startswith("start (-3.3000000, 55.9410000) lies outside the map (")
    assert "points are" not in str(err.value)


def test_plan_world_with_a_swapped_feature_is_one_line_and_writes_nothing(monkeypatch, capsys,
                                                                          tmp_path):
    path = write(tmp_path / "z.geojson", ZONE, swapped(ZONE), AREA)
    out = tmp_path / "p.geojson"
    code, text, err = run(monkeypatch, capsys, "plan-world", str(path), "--start=-3.194,55.941",
                          "--goal=-3.186,55.949", "--geojson", str(out))
    assert code == 2 and text == "" and err.count("\n") == 1 and not out.exists()
    assert err.startswith(f"skyroute: error: {path}: feature 1 ('swapped') lies ")


def test_a_boundary_box_written_lat_lon_is_refused_for_zones_and_cities(monkeypatch, capsys,
                                                                        tmp_path):
    # a colliders city took it, projected 7,800 km away, and then told the user to swap
    # their (right) start: "(55.9445, -3.1869) is inside: points are (lon, lat)"
    box = "55.93,-3.2,55.96,-3.18"
    zones = write(tmp_path / "z.geojson", ZONE)
    refused(zones, f"boundary='{box}' lies ", boundary=box)
    city = tmp_path / "c.csv"
    city.write_text("lat0 55.944494, lon0 -3.186874\n"
                    "posX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n10,10,5,1,1,5\n")
    code, out, err = run(monkeypatch, capsys, "plan-world", str(city), f"--boundary={box}",
                         "--start=-3.1869,55.9445", "--goal=-3.1868,55.9446")
    assert code == 2 and out == "" and err.count("\n") == 1
    assert err.startswith(f"skyroute: error: --boundary '{box}' reaches 7,843 km from the "
                          "city's home (lon -3.18687, lat 55.9445), more than 1,000 km: are "
                          "its coordinates (lat, lon)?")
    w = skyroute.load_world(city, boundary="-3.2,55.93,-3.18,55.96")  # the right way round
    assert skyroute.plan(w, (-3.1869, 55.9445), (-3.1868, 55.9446)).found


# -- coordinates with a height, NaN, and documents that are not a FeatureCollection -------

def lifted(feature, alt=12.5):
    """``feature`` with a third coordinate (a height) on every vertex, as GeoJSON allows."""
    rings = feature["geometry"]["coordinates"]
    return {**feature, "geometry": {"type": feature["geometry"]["type"],
                                    "coordinates": [[[*p, alt] for p in r] for r in rings]}}


@pytest.mark.parametrize("frame", ["degrees", "lonlat", "ned", "enu"])
@pytest.mark.parametrize("algorithm", ["visibility", "prm"])
def test_zones_with_heights_plan_as_without(tmp_path, frame, algorithm):
    # a [lon, lat, alt] ring failed in the degrees frame's visibility graph (numpy's
    # "all the input array dimensions ... must match"): a traceback
    flat = skyroute.load_world(write(tmp_path / "flat.geojson", ZONE, AREA), frame=frame)
    high = skyroute.load_world(write(tmp_path / "high.geojson", lifted(ZONE), lifted(AREA)),
                               frame=frame)
    assert not any(shapely.has_z(high.obstacles)) and not shapely.has_z(high.boundary)
    assert all(shapely.equals(high.obstacles, flat.obstacles))
    start, goal = flat.from_plane(flat.plane_from_lonlat([(-3.1945, 55.9405),
                                                          (-3.1855, 55.9495)]))
    seed = {"seed": 1} if algorithm == "prm" else {}
    a = skyroute.plan(flat, start, goal, algorithm=algorithm, **seed)
    b = skyroute.plan(high, start, goal, algorithm=algorithm, **seed)
    assert a.found and b.cost == a.cost


def test_a_world_built_from_polygons_with_heights_plans_as_without():
    # the README's World, its square given 3-D: round two of its corners, as in 2-D
    ring = [(1, 1), (3, 1), (3, 3), (1, 3)]
    flat = skyroute.World([shapely.Polygon(ring)], [0], [50], ("tower",))
    high = skyroute.World([shapely.Polygon([(x, y, 9) for x, y in ring])], [0], [50],
                          ("tower",))
    a, b = skyroute.plan(flat, (0, 2), (4, 2)), skyroute.plan(high, (0, 2), (4, 2))
    assert round(b.cost, 6) == 4.828427 and b.path.tolist() == a.path.tolist()


def test_a_name_with_a_lone_surrogate_is_refused_naming_the_feature(monkeypatch, capsys,
                                                                    tmp_path):
    # JSON's "\ud800" is half a surrogate pair, no character: plan-world's visibility
    # graph could not hash the name (a UnicodeEncodeError traceback)
    path = tmp_path / "z.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [
        ZONE, polygon(square(-3.185, 55.943), name="\ud800"), AREA]}))
    assert "\\ud800" in path.read_text()
    code, out, err = run(monkeypatch, capsys, "plan-world", str(path),
                         "--start=-3.194,55.941", "--goal=-3.186,55.949")
    assert code == 2 and out == "" and err == (
        f"skyroute: error: {path}: feature 1: its name holds U+D800, half of a UTF-16 "
        "surrogate pair and no character\n")


@pytest.mark.parametrize("value", ["NaN", "Infinity", "-Infinity", "1e999"])
def test_a_coordinate_that_is_no_json_number_names_the_feature(tmp_path, value):
    # Python's json reads NaN and Infinity; GEOS then said "ParseException: Error parsing
    # JSON: '[json.exception.parse_error.101] ... invalid literal; last read: '[[[N''"
    text = json.dumps({"type": "FeatureCollection", "features": [ZONE, AREA]})
    path = tmp_path / "z.geojson"
    path.write_text(text.replace("-3.19,", f"{value},", 1))
    refused(path, "feature 0 ('zone'): coordinates must be finite numbers, found NaN or "
            "Infinity (or one too large, such as 1e999)")


@pytest.mark.parametrize("doc, words", [
    (ZONE, "expected a GeoJSON FeatureCollection; got one Feature (wrap it: "
           "{\"type\": \"FeatureCollection\", \"features\": [...]})"),
    (ZONE["geometry"], "expected a GeoJSON FeatureCollection; got a bare Polygon (make it "
                       "the geometry of a Feature in one)"),
    ({"type": "FeatureCollection", "features": {}},
     "expected a GeoJSON FeatureCollection; its 'features' is not a list of features"),
    ([ZONE], "expected a GeoJSON FeatureCollection; got a JSON array"),
    ({"zones": [ZONE]}, "expected a GeoJSON FeatureCollection; got a JSON object with no "
                        "GeoJSON 'type'"),
])
def test_a_document_that_is_not_a_feature_collection_says_what_it_is(tmp_path, doc, words):
    path = tmp_path / "z.geojson"
    path.write_text(json.dumps(doc))
    assert refused(path, words) == f"{path}: {words}"


def test_plan_world_on_zones_with_heights_in_degrees(monkeypatch, capsys, tmp_path):
    path = write(tmp_path / "z.geojson", lifted(ZONE), lifted(AREA))
    code, out, err = run(monkeypatch, capsys, "plan-world", str(path), "--frame", "degrees",
                         "--start=-3.1945,55.9405", "--goal=-3.1855,55.9495", "--json")
    assert code == 0 and err == "" and json.loads(out)["status"] == "found"
