"""Frames and headings. PROJ is the reference for the transforms; these tests check the
round trip, directions and distances against independent formulae."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyroute.geo import (
    Home,
    enu_to_lonlat,
    heading_of,
    ilp_to_ned_heading,
    lonlat_to_enu,
    lonlat_to_ned,
    ned_heading_to_ilp,
    ned_to_lonlat,
)

SF = Home(-122.397450, 37.792480, 0.0)  # the FCND home (colliders.csv line 1)
EDINBURGH = Home(-3.186874, 55.944494, 0.0)


@settings(max_examples=200, deadline=None)
@given(st.floats(-10_000, 10_000), st.floats(-10_000, 10_000), st.floats(-50, 500),
       st.sampled_from([SF, EDINBURGH]))
def test_round_trip_within_a_millimetre(north, east, down, home):
    lla = ned_to_lonlat(north, east, down, home)
    back = lonlat_to_ned(lla[:, 0], lla[:, 1], lla[:, 2], home)
    assert np.abs(back - [[north, east, down]]).max() < 1e-3


def test_directions_and_scale():
    # 0.001 degree of latitude is about 110.9 m at 37.8 N; east of home is +east
    n = lonlat_to_ned(SF.lon, SF.lat + 0.001, 0.0, SF)[0]
    assert n[0] == pytest.approx(110.99, abs=0.1) and abs(n[1]) < 1e-6
    e = lonlat_to_enu(SF.lon + 0.001, SF.lat, 0.0, SF)[0]
    expected = math.radians(0.001) * 6378137.0 * math.cos(math.radians(SF.lat)) / \
        math.sqrt(1 - 0.00669438 * math.sin(math.radians(SF.lat)) ** 2)
    assert e[0] == pytest.approx(expected, rel=1e-6) and abs(e[1]) < 1e-3
    assert lonlat_to_enu(SF.lon, SF.lat, 0.0, SF) == pytest.approx(np.zeros((1, 3)), abs=1e-9)
    np.testing.assert_allclose(enu_to_lonlat(0, 0, 0, SF), [[SF.lon, SF.lat, 0.0]], atol=1e-12)


@pytest.mark.parametrize("ned_deg, ilp", [(0, 90), (90, 0), (180, 270), (270, 180), (45, 45),
                                          (350, 100)])
def test_heading_conventions(ned_deg, ilp):
    assert ned_heading_to_ilp(math.radians(ned_deg)) == pytest.approx(ilp)
    assert ilp_to_ned_heading(ilp) == pytest.approx(math.radians(ned_deg) % (2 * math.pi))


def test_heading_of_moves():
    np.testing.assert_allclose(heading_of([0, 1, 0, -1], [1, 0, -1, 0]),
                               np.radians([0, 90, 180, 270]))
