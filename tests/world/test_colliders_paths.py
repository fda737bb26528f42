"""Paths in a colliders city checked against the file's own numbers, as FCND defines them.

A box counts at the flight altitude when its top (posZ + halfSizeZ) plus the safety
distance is above that altitude, as FCND's ``create_grid`` has it; it is grown by the
safety distance on every side. The reference here is shapely on boxes built from the
raw numbers, not skyroute's World: no leg of any planner's path may enter the interior
of their union, the visibility graph is never longer than the others, and the FCND
waypoints start at the start, end at the goal and head along each leg
(atan2(east, north), FCND's optional heading step).
"""

import itertools
import math

import numpy as np
import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import skyroute
from skyroute.io.world_out import waypoints

HOME = "lat0 37.792480, lon0 -122.397450\nposX,posY,posZ,halfSizeX,halfSizeY,halfSizeZ\n"


def city_text(rows) -> str:
    return HOME + "".join(",".join(f"{v:g}" for v in r) + "\n" for r in rows)


def blocked(rows, altitude: float, safety: float):
    """The union of the boxes that count at ``altitude``, grown by ``safety`` (plane
    x east, y north), worked out from the file's numbers."""
    b = np.asarray(rows, dtype=float).reshape(-1, 6)
    north, east, z, hn, he, hz = b.T
    keep = (z + hz + safety > altitude) & (z - hz - safety <= altitude)
    return shapely.union_all(shapely.box(east[keep] - he[keep] - safety,
                                         north[keep] - hn[keep] - safety,
                                         east[keep] + he[keep] + safety,
                                         north[keep] + hn[keep] + safety))


def enters(union, a, b) -> bool:
    """Whether the leg a -> b, (north, east) points, meets the union's interior."""
    leg = shapely.LineString([(a[1], a[0]), (b[1], b[0])])
    return union.relate_pattern(leg, "T********")


@st.composite
def cities(draw):
    """A few boxes on the ground of random heights (some below the flight altitude),
    often touching or overlapping, an altitude, a safety distance, and a start and a
    goal, (north, east) metres, outside every box that counts."""
    rows = []
    for _ in range(draw(st.integers(1, 7))):
        top = draw(st.integers(1, 30))
        rows.append((draw(st.integers(-25, 25)), draw(st.integers(-25, 25)), top / 2,
                     draw(st.integers(1, 8)), draw(st.integers(1, 8)), top / 2))
    altitude = float(draw(st.integers(0, 25)))
    safety = draw(st.sampled_from([0.0, 1.0, 2.5, 5.0]))
    point = st.tuples(st.floats(-45, 45), st.floats(-45, 45))
    return rows, altitude, safety, draw(point), draw(point)


ALGORITHMS = {"visibility": {}, "theta": {"resolution": 0.5}, "astar": {"resolution": 0.5},
              "prm": {"samples": 300}}


@settings(max_examples=40, deadline=None)
@given(cities())
def test_every_planner_keeps_out_of_the_boxes_at_the_altitude(case):
    rows, altitude, safety, start, goal = case
    union = blocked(rows, altitude, safety)
    clear = union.buffer(0.05)  # off the grown faces: each planner may start there
    assume(not clear.contains(shapely.Point(start[::-1])))
    assume(not clear.contains(shapely.Point(goal[::-1])))
    world = skyroute.load_world("city.csv", text=city_text(rows), altitude=altitude,
                                safety=safety, frame="ned")
    results = {a: skyroute.plan(world, start, goal, algorithm=a, **kw)
               for a, kw in ALGORITHMS.items()}
    exact = results["visibility"]
    for name, r in results.items():
        if not r.found:  # a grid or PRM may miss a narrow gap; none finds a path it lacks
            assert exact.found or name != "visibility"
            continue
        assert exact.found, name
        path = np.asarray(r.path)
        assert path[0].tolist() == list(start) and path[-1].tolist() == list(goal)
        assert not any(enters(union, a, b) for a, b in itertools.pairwise(path)), name
        length = float(np.hypot(*np.diff(path, axis=0).T).sum())
        assert r.cost == pytest.approx(length, rel=1e-9, abs=1e-9)
        assert exact.cost <= r.cost + 1e-9, name
        rows_out = waypoints(world, r.path, altitude)
        np.testing.assert_allclose(np.array(rows_out)[:, :3],
                                   np.c_[path, np.full(len(path), altitude)], atol=1e-9)
        for w0, w1 in itertools.pairwise(rows_out):
            dn, de = w1[0] - w0[0], w1[1] - w0[1]
            if math.hypot(dn, de) > 1e-6:
                turn = (w1[3] - math.atan2(de, dn) + math.pi) % (2 * math.pi) - math.pi
                assert abs(turn) < 1e-9


@pytest.mark.parametrize("top, through", [(9.99, True), (10.0, True), (10.01, False)])
def test_a_roof_at_the_altitude_less_the_safety_is_flown_over(top, through):
    # a wall across the way at 15 m with a 5 m margin: FCND's create_grid blocks it
    # when top + safety > altitude; a roof exactly 5 m below is flown over
    rows = [(0, 0, top / 2, 5, 50, top / 2)]
    world = skyroute.load_world("wall.csv", text=city_text(rows), altitude=15, safety=5,
                                frame="ned")
    for algorithm in ("visibility", "theta"):
        r = skyroute.plan(world, (-20, 0), (20, 0), algorithm=algorithm)
        assert r.found and (r.cost == pytest.approx(40.0)) is through, algorithm
        assert not enters(blocked(rows, 15, 5), r.path[0], r.path[1])
