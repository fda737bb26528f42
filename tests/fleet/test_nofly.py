"""No-fly zones: cruises go round them (checked with shapely, not our planner's own
test), what cannot bend is refused with the zone's name, and a fleet run keeps out."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

from skyroute.errors import InputFormatError, QueryError
from skyroute.fleet.flightplan import plan_flight
from skyroute.fleet.report import report
from skyroute.fleet.scenario import parse_scenario, preset
from skyroute.fleet.simulate import run
from skyroute.fleet.trajectory import ARC

ZONE = [[-400, -700], [-400, 700], [300, 700], [300, -700]]  # (north, east) metres


def _inside(pieces, poly) -> int:
    """Pieces with a point strictly inside ``poly``: lines exactly, arcs densely."""
    bad = 0
    for i in range(len(pieces)):
        if pieces.kind[i] == ARC:
            ts = np.linspace(pieces.t0[i], pieces.t1[i], 400)
            pts = pieces.at(np.full(len(ts), i), ts)
            hit = shapely.contains_xy(poly, pts[:, 1], pts[:, 0]).any()
        else:
            a, b = pieces.at([i, i], [pieces.t0[i], pieces.t1[i]])
            line = shapely.LineString([(a[1], a[0]), (b[1], b[0])])
            hit = line.intersects(poly) and not line.touches(poly)
        bad += bool(hit)
    return bad


def _two_airports(zone):
    return parse_scenario({
        "airports": [
            {"id": "W", "north": 0, "east": -3000, "landing": {"heading_deg": 90},
             "takeoff": {"heading_deg": 90}},
            {"id": "E", "north": 0, "east": 3000, "landing": {"heading_deg": 90},
             "takeoff": {"heading_deg": 90}}],
        "no_fly_zones": [{"name": "wall", "points": zone}]})


def test_a_cruise_goes_round_a_zone_on_its_straight_line():
    s = _two_airports([[-300, -500], [-300, 500], [300, 500], [300, -500]])
    f = plan_flight(s, 0, "W", "E", depart=0.0, altitude=100.0)
    poly = shapely.Polygon([(e, n) for n, e in s.no_fly_zones[0].points])
    assert _inside(f.pieces, poly) == 0
    # the Dubins path without the zone crosses it; the detour is longer
    free = plan_flight(s.model_copy(update={"no_fly_zones": []}), 0, "W", "E", depart=0.0,
                       altitude=100.0)
    assert _inside(free.pieces, poly) > 0
    assert f.landing_request > free.landing_request


def test_what_cannot_bend_is_refused_with_the_zones_name(tmp_path):
    # the final approach to E from 100 m starts 951 m out: a zone there blocks it
    s = _two_airports([[-100, 2200], [-100, 2500], [100, 2500], [100, 2200]])
    with pytest.raises(QueryError, match=r"airport E's final approach .* 'wall'"):
        plan_flight(s, 0, "W", "E", depart=0.0, altitude=100.0)
    with pytest.raises(InputFormatError, match=r"no_fly_zones\[0\].*covers a runway of "
                                               "airport W"):
        _two_airports([[-50, -3100], [-50, -2900], [50, -2900], [50, -3100]])
    with pytest.raises(InputFormatError, match=r"no_fly_zones\[0\]\.points: List should"):
        _two_airports([[0, 0], [1, 1]])


def test_a_fleet_run_keeps_out_of_a_zone_and_apart():
    d = preset("seed-9x9").model_dump()
    d["no_fly_zones"] = [{"name": "centre", "points": ZONE}]
    s = parse_scenario(d)
    sim = run(s, hours=1.0, seed=2, scheduler="optimal", airspace="shared")
    rep = report(sim)
    assert rep["conflicts"] == 0 and rep["lost"] == 0 and rep["delivered"] > 0
    poly = shapely.Polygon([(e, n) for n, e in ZONE])
    assert _inside(sim.pieces(), poly) == 0


@pytest.fixture(scope="module")
def zoned_run():
    s = _two_airports([[-300, -500], [-300, 500], [300, 500], [300, -500]])
    return run(s, hours=0.3, seed=1)


def test_the_run_files_show_the_zones(zoned_run):
    # an operator saw the drones bend round nothing: no file showed the zones
    from skyroute.geo import Home, lonlat_to_ned
    from skyroute.io.fleet_out import fleet_geojson, fleet_geojson_from_tracks, tracks_csv

    s = zoned_run.scenario
    home = Home(lon=s.home_lon, lat=s.home_lat)
    for fc in (fleet_geojson(zoned_run),
               fleet_geojson_from_tracks(s, tracks_csv(zoned_run, 5.0))):
        zones = [f for f in fc["features"] if f["properties"]["kind"] == "no_fly_zone"]
        assert [f["properties"]["name"] for f in zones] == ["wall"]
        geom = zones[0]["geometry"]
        assert geom["type"] == "Polygon" and len(geom["coordinates"]) == 1
        ring = np.array(geom["coordinates"][0])
        assert ring[0].tolist() == ring[-1].tolist() and len(ring) == 5  # closed
        ne = lonlat_to_ned(ring[:, 0], ring[:, 1], np.zeros(len(ring)), home)[:, :2]
        poly = shapely.Polygon(ne[:, ::-1])  # (east, north)
        assert poly.exterior.is_ccw  # RFC 7946: the exterior ring anticlockwise
        want = shapely.Polygon([(e, n) for n, e in s.no_fly_zones[0].points])
        assert poly.normalize().equals_exact(want.normalize(), 0.01)


def test_the_map_draws_the_zones(zoned_run, tmp_path, monkeypatch):
    import skyroute.io.plot as plot
    from skyroute.io.fleet_out import plot_map

    figures = []
    save = plot.save_figure
    monkeypatch.setattr(plot, "save_figure",
                        lambda fig, path, **kw: figures.append(fig) or save(fig, path, **kw))
    plot_map(zoned_run, tmp_path / "map.png")
    ax = figures[0].axes[0]
    zones = [p for p in ax.patches if p.get_gid() == "no_fly_zone wall"]
    assert len(zones) == 1
    corners = {tuple(np.round(v, 6)) for v in zones[0].get_xy()}
    assert corners == {(float(e), float(n)) for n, e in zoned_run.scenario.no_fly_zones[0]
                       .points}
    assert "no-fly zone" in [t.get_text() for t in ax.get_legend().get_texts()]


# two C-shaped zones round airport C that touch only at two corners, (1500, 0) and
# (4500, 0): no gap between them, though their union is two polygons and has no hole
RING = [{"name": "west", "points": [[1400, -1600], [1400, 0], [1500, 0], [1500, -1500],
                                    [4500, -1500], [4500, 0], [4600, 0], [4600, -1600]]},
        {"name": "east", "points": [[1500, 0], [1500, 1600], [4500, 1600], [4500, 0],
                                    [4400, 0], [4400, 1500], [1600, 1500], [1600, 0]]}]
RING_ERROR = ("no_fly_zones: no cruise can join airports C and A: zones 'west', 'east' "
              "close a ring round C (zones that touch leave no gap)")


def ringed(zones=RING) -> dict:
    """Airports A and B 8 km apart (the farthest pair, which the airborne check flies)
    and C, 3 km north of their midpoint, inside ``zones``."""
    def port(name, north, east, landing):
        return {"id": name, "north": north, "east": east,
                "landing": {"heading_deg": landing}, "takeoff": {"heading_deg": 90}}

    return {"name": "ring", "airports": [port("A", 0, -4000, 90), port("B", 0, 4000, 90),
                                         port("C", 3000, 0, 0)],
            "no_fly_zones": zones}


def test_airports_a_ring_of_zones_cuts_off_are_refused_before_a_run(monkeypatch):
    # a run failed when C was first flown, mid-run, with the planner's raw status
    # ("B -> C at 50 m: no cruise around the no-fly zones ...: no_path")
    from skyroute.fleet import simulate
    from skyroute.fleet.airborne import check_flights

    s = parse_scenario(ringed())
    with pytest.raises(InputFormatError) as err:
        check_flights(s, "ring.yaml")
    assert str(err.value) == f"ring.yaml: {RING_ERROR}"

    def no_flight(*_args, **_kwargs):
        raise AssertionError("a flight was planned before the zones were checked")

    monkeypatch.setattr(simulate, "plan_flight", no_flight)
    with pytest.raises(InputFormatError) as err:
        run(s, hours=0.5, seed=0)
    assert str(err.value) == f"scenario: {RING_ERROR}"


def test_a_gap_in_the_ring_lets_the_cruise_through():
    from skyroute.fleet.airborne import check_flights
    from skyroute.fleet.nofly import cut_off

    # the east zone's lower arm stops 100 m short: a gap wider than a turning circle
    east = [[1500, 100], [1500, 1600], [4500, 1600], [4500, 0], [4400, 0], [4400, 1500],
            [1600, 1500], [1600, 100]]
    s = parse_scenario(ringed([RING[0], {"name": "east", "points": east}]))
    assert cut_off(s) is None
    check_flights(s, "ring.yaml")  # no error
    # zones in a ring round no airport, or round every one, part none of them
    for move in (lambda n, e: (n, e + 2e4), lambda n, e: (3000 + 4 * (n - 3000), 4 * e)):
        moved = [{**z, "points": [move(n, e) for n, e in z["points"]]} for z in RING]
        assert cut_off(parse_scenario(ringed(moved))) is None


def hexagon_ring(turn: float) -> list[dict]:
    """Six zones, the sectors of a hexagonal band (inner radius 1200 m, outer 1500 m)
    round airport C of :func:`ringed`, each sharing its two side edges with its
    neighbours; and a chain of three boxes, each touching the next, running 3 km out
    from the top of the band. All turned by ``turn`` radians about C (so the union's
    nodes are rounded, not exact)."""
    c_n, c_e = 3000.0, 0.0

    def turned(n, e):
        dn, de = n - c_n, e - c_e
        return [c_n + dn * math.cos(turn) - de * math.sin(turn),
                c_e + dn * math.sin(turn) + de * math.cos(turn)]

    # the hexagon's corners, each worked out once, so neighbours share edges exactly
    band = [[turned(c_n + r * math.sin(t), c_e + r * math.cos(t)) for r in (1200, 1500)]
            for t in np.radians(np.arange(0, 360, 60))]
    zones = [{"name": f"ring{k}", "points": [band[k][0], band[k][1], band[(k + 1) % 6][1],
                                             band[(k + 1) % 6][0]]} for k in range(6)]
    for j, (lo, hi) in enumerate(((1250, 2300), (2300, 3300), (3300, 4300))):
        zones.append({"name": f"spur{j}",
                      "points": [turned(c_n + n, c_e + e)
                                 for n, e in ((lo, -100), (lo, 100), (hi, 100), (hi, -100))]})
    return zones


@pytest.mark.parametrize("turn", [0.0, 0.16, 0.64, 1.93, 2.42, 3.54, 6.12])
def test_a_ring_names_only_the_zones_that_close_it(turn):
    # all nine zones were named: the ring's six and the three of the chain joined to it
    from skyroute.fleet.airborne import check_flights
    from skyroute.fleet.nofly import cut_off

    zones = hexagon_ring(turn)
    s = parse_scenario(ringed(zones))
    inside, outside, names = cut_off(s)
    assert (inside, outside) == (["C"], ["A", "B"])
    assert names == [f"'ring{k}'" for k in range(6)]
    with pytest.raises(InputFormatError) as err:
        check_flights(s, "hex.yaml")
    assert str(err.value) == ("hex.yaml: no_fly_zones: no cruise can join airports C and A: "
                              "zones 'ring0', 'ring1', 'ring2', 'ring3', 'ring4', 'ring5' "
                              "close a ring round C (zones that touch leave no gap)")
    # independently (shapely, no growth): the six sectors alone enclose C, the chain
    # alone does not, and any five sectors leave C joined to the outside
    c = shapely.Point(0.0, 3000.0)
    poly = [shapely.Polygon([(e, n) for n, e in z["points"]]) for z in zones]
    holes = shapely.get_parts(shapely.union_all(poly[:6])).tolist()
    assert len(holes) == 1 and shapely.Polygon(holes[0].interiors[0]).contains(c)
    assert not any(shapely.Polygon(r).contains(c) for p in shapely.get_parts(
        shapely.union_all(poly[6:])) for r in p.interiors)
    for k in range(6):
        five = shapely.union_all(poly[:k] + poly[k + 1:6])
        assert not any(shapely.Polygon(r).contains(c) for p in shapely.get_parts(five)
                       for r in p.interiors)
    # the scenario without the chain names the same ring
    assert cut_off(parse_scenario(ringed(zones[:6])))[2] == names


def test_a_cruise_the_planner_cannot_find_names_the_flight_not_a_status():
    from skyroute.fleet.nofly import cruise
    from skyroute.motion.dubins import shortest_path

    s = parse_scenario(ringed())
    start, goal = (0.0, 0.0, 0.0), (0.0, 3000.0, 0.0)  # (east, north, heading): into C
    with pytest.raises(QueryError) as err:
        cruise(s, start, goal, 250.0, shortest_path(start, goal, 250.0),
               what="flight A -> C at 50 m")
    assert str(err.value) == ("flight A -> C at 50 m: no cruise with a 250 m turning radius "
                              "gets round the no-fly zones from the climb-out (0 N, 0 E) to "
                              "the approach gate (3000 N, 0 E)")
    assert err.value.param == "no_fly_zones"


def test_a_flight_the_zones_block_names_the_scenario_file_when_read():
    # the airborne check plans the farthest pair: a final approach through a zone was a
    # QueryError naming no file
    from skyroute.fleet.airborne import check_flights

    s = _two_airports([[-100, 2200], [-100, 2500], [100, 2500], [100, 2200]])
    with pytest.raises(InputFormatError) as err:
        check_flights(s, "two.yaml")
    assert str(err.value) == ("two.yaml: no_fly_zones: airport E's final approach from 80 m "
                              "crosses no-fly zone 'wall'")


def test_a_cruise_search_out_of_budget_says_so_not_that_none_exists(monkeypatch):
    from skyroute.fleet.nofly import cruise
    from skyroute.motion import hybrid
    from skyroute.motion.dubins import shortest_path

    s = _two_airports(ZONE)
    start, goal = (-2000.0, 0.0, 0.0), (2000.0, 0.0, 0.0)  # (east, north, heading)
    path = shortest_path(start, goal, 100.0)  # straight through the wall
    assert cruise(s, start, goal, 100.0, path)  # round it, with the default budget
    monkeypatch.setattr(hybrid, "MAX_NODES", 30)
    with pytest.raises(QueryError) as err:
        cruise(s, start, goal, 100.0, path, what="flight W -> E at 50 m")
    assert str(err.value) == (
        "flight W -> E at 50 m: the search for a cruise with a 100 m turning radius round "
        "the no-fly zones from the climb-out (0 N, -2000 E) to the approach gate (0 N, "
        "2000 E) ran out of its budget (10 expansions): it found none, nor showed that "
        "none exists")
    assert err.value.param == "no_fly_zones"


def _masts_at(name: str, airport: int, altitude: float):
    """Preset ``name`` with two small zones at the far side of both loiter circles of
    ``airport`` at ``altitude`` only (a lower level's circles, 95 m nearer the runway
    per 10 m, stay clear of them), and the data of that scenario."""
    import yaml

    from skyroute.fleet.scenario import runway_ends, to_yaml

    s = preset(name)
    a = s.airports[airport]
    thr, _ = runway_ends(a, a.landing)
    psi = math.radians(a.landing.heading_deg)
    u = np.array([math.cos(psi), math.sin(psi)])
    gate = thr - altitude / math.tan(math.radians(s.drone.glide_angle_deg)) * u
    r = s.drone.turn_radius
    zones = []
    for k, side in enumerate((1, -1)):
        n, e = (float(x) for x in gate + side * r * np.array([-u[1], u[0]]) - (r + 5) * u)
        zones.append({"name": f"mast{k}", "points": [[n - 10, e - 10], [n + 10, e - 10],
                                                      [n + 10, e + 10], [n - 10, e + 10]]})
    data = yaml.safe_load(to_yaml(s))
    data["no_fly_zones"] = zones
    return parse_scenario(data), data


def test_a_level_whose_loiter_circles_the_zones_block_is_refused_before_a_run():
    # seed-9x9's drone 8 cruises at 130 m in layers; both its loiter circles at E enter
    # a zone. E is not of the farthest pair the airborne check plans, so the run failed
    # when drone 8 was first sent to E (after 1.1 simulated hours with seed 1) with a
    # line naming neither the file, the zones nor the drone
    from skyroute.errors import OptionError
    from skyroute.fleet.simulate import check_levels

    s, _ = _masts_at("seed-9x9", 4, 130.0)
    with pytest.raises(OptionError) as err:
        check_levels(s, "layers", where="masts.yaml")
    assert str(err.value) == (
        "masts.yaml: no_fly_zones: airport E: both loiter circles at 130 m cross no-fly "
        "zones 'mast1' and 'mast0', drone 8's level in layers; fly shared, fewer drones "
        "or move the zone")
    with pytest.raises(OptionError, match=r"^no_fly_zones: airport E: both loiter "):
        run(s, hours=0.1, seed=1)  # the library refuses it before the first event too
    check_levels(s, "shared")  # its four levels, 50 to 80 m, are clear
    check_levels(s.model_copy(update={"drones": 8}), "layers")  # up to 120 m


def test_a_climb_out_or_final_the_zones_block_at_a_shared_level_is_refused_before_a_run():
    from skyroute.errors import OptionError
    from skyroute.fleet.simulate import check_levels

    # the final approach to E from 80 m (the fourth shared level) starts 761 m out, at
    # 1939 m east; from 70 m 666 m out
    s = _two_airports([[-1, 1950], [-1, 2000], [1, 2000], [1, 1950]])
    with pytest.raises(OptionError) as err:
        check_levels(s, "shared", where="two.yaml")
    assert str(err.value) == (
        "two.yaml: no_fly_zones: airport E's final approach from 80 m crosses no-fly zone "
        "'wall', one of the 4 shared levels; fewer shared_levels, a smaller layer_step "
        "or move the zone")
    check_levels(s.model_copy(update={"airspace": s.airspace.model_copy(
        update={"shared_levels": 3})}), "shared")


def test_the_cli_refuses_a_blocked_level_in_one_line_and_writes_nothing(monkeypatch, capsys,
                                                                       tmp_path):
    import yaml

    from tests.cli.test_cli import run as cli

    _, data = _masts_at("seed-9x9", 4, 130.0)
    path = tmp_path / "masts.yaml"
    path.write_text(yaml.safe_dump(data))
    code, out, err = cli(monkeypatch, capsys, "fleet", "simulate", str(path), "--hours",
                         "24", "--seed", "1", "--out", str(tmp_path / "out"))
    assert code == 2 and out == ""
    assert err.splitlines() == [
        f"skyroute: error: {path}: no_fly_zones: airport E: both loiter circles at 130 m "
        "cross no-fly zones 'mast1' and 'mast0', drone 8's level in layers; fly shared, "
        "fewer drones or move the zone"]
    assert not (tmp_path / "out").exists()
