"""The option readers of skyroute.errors: what their messages say."""

from __future__ import annotations

import math

import numpy as np
import pytest

from skyroute.errors import OptionError, real, whole


@pytest.mark.parametrize("value", [math.inf, -math.inf, math.nan, np.float64("inf"),
                                   np.array(math.nan)])
@pytest.mark.parametrize("bounds, need, words", [
    ({"low": 0.0, "strict": True}, None, "a finite number > 0"),
    ({"low": 0.0, "strict": True}, "> 0", "a finite number > 0"),
    ({"low": 1.0}, "a number >= 1", "a finite number >= 1"),
    ({"low": 0.0, "strict": True}, "positive", "a finite positive number"),
    ({"low": 0.0, "strict": True, "high": math.pi}, "in (0, pi] radians",
     "a finite number in (0, pi] radians"),
    ({"low": 2.0, "high": 10.0}, None, "a finite number from 2 to 10"),
    ({}, None, "a finite number"),
])
def test_a_value_not_finite_is_refused_as_not_finite(value, bounds, need, words):
    # real() said "sensor_range=inf must be > 0": true of inf, and no help
    with pytest.raises(OptionError) as err:
        real("sensor_range", value, need=need, **bounds)
    assert str(err.value) == f"sensor_range={value!r} must be {words}"
    assert err.value.param == "sensor_range"


@pytest.mark.parametrize("value, need, words", [
    (0.0, "> 0", "sensor_range=0.0 must be > 0"),
    (-1.0, None, "sensor_range=-1.0 must be a number > 0"),
    ("5", "> 0", "sensor_range='5' must be > 0"),
    (True, None, "sensor_range=True must be a finite number"),
])
def test_a_finite_value_out_of_range_keeps_its_message(value, need, words):
    with pytest.raises(OptionError, match=f"^{words}$".replace("(", r"\(")):
        real("sensor_range", value, low=0.0, strict=True, need=need)


def test_whole_refuses_a_float_infinity_as_not_an_integer():
    with pytest.raises(OptionError, match=r"^sensor_rays=inf must be an integer >= 4$"):
        whole("sensor_rays", math.inf, low=4)


@pytest.mark.parametrize("value, shown", [
    (10**400, "<an integer of 401 digits>"),
    (-(10**400), "<a negative integer of 401 digits>"),
    (10**5000, "<an integer of 5,001 digits>"),  # repr() itself refuses over 4,300 digits
], ids=["10**400", "-10**400", "10**5000"])
def test_an_integer_beyond_a_float_is_one_option_error(value, shown):
    # real() raised OverflowError ('int too large to convert to float') from isfinite
    with pytest.raises(OptionError) as err:
        real("sensor_range", value, low=0.0, strict=True)
    assert str(err.value) == f"sensor_range={shown} must be a finite number > 0"
    assert err.value.param == "sensor_range"
    with pytest.raises(OptionError, match=f"^sensor_rays={shown} must be an integer "
                                          "from 4 to 360$"):
        whole("sensor_rays", value, low=4, high=360)


def test_a_fraction_beyond_a_float_is_one_option_error():
    from fractions import Fraction

    with pytest.raises(OptionError, match=r"^sensor_range=Fraction\(1000.*, 3\) must be a "
                                          r"finite number > 0$"):
        real("sensor_range", Fraction(10**400, 3), low=0.0, strict=True)


def test_a_long_integer_within_range_is_read_and_shown_in_full_below_30_digits():
    assert real("sensor_range", 10**300, low=0.0) == 1e300
    with pytest.raises(OptionError, match=r"^sensor_range=<an integer of 31 digits> must "
                                          r"be a number <= 5$"):
        real("sensor_range", 10**30, high=5)
    with pytest.raises(OptionError, match=f"^sensor_range={10**30 - 1} must be a number <= 5$"):
        real("sensor_range", 10**30 - 1, high=5)
