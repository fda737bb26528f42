"""Package streams: the seeded Poisson stream against its statistics, the CSV reader's
loading and its errors (each naming the file, the line and the field)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from skyroute.errors import InputFormatError, OptionError
from skyroute.fleet import packages
from skyroute.fleet.scenario import preset

HOURS = 200.0


@pytest.fixture(scope="module")
def nine():
    return preset("seed-9x9")


@pytest.mark.parametrize("seed", range(4))
def test_poisson_count_and_hourly_spread_match_the_rate(nine, seed):
    rate = 60.0
    s = packages.poisson(nine, hours=HOURS, seed=seed, rate_per_hour=rate)
    n, mean = len(s), rate * HOURS
    assert abs(n - mean) < 5 * math.sqrt(mean)  # Poisson: variance = mean
    counts = np.bincount((s.t // 3600).astype(int), minlength=int(HOURS))
    assert len(counts) == HOURS
    # hour by hour the counts are Poisson too: dispersion var/mean near 1
    # (its standard error is sqrt(2 / (hours - 1)), 0.1 here)
    assert abs(counts.var(ddof=1) / counts.mean() - 1.0) < 0.4
    # and the gaps exponential: their mean and standard deviation both 3600 / rate
    gaps = np.diff(s.t)
    assert gaps.mean() == pytest.approx(3600 / rate, rel=0.05)
    assert gaps.std() == pytest.approx(3600 / rate, rel=0.08)


def test_poisson_origins_destinations_and_gates(nine):
    s = packages.poisson(nine, hours=HOURS, seed=1, rate_per_hour=60.0)
    a = len(nine.airports)
    assert not (s.origin == s.destination).any()
    assert ((s.origin >= 0) & (s.origin < a) & (s.destination >= 0) & (s.destination < a)
            ).all()
    assert set(np.unique(s.origin_gate)) == set(np.unique(s.destination_gate)) == {0, 1}
    # uniform over airports and over ordered pairs of distinct airports
    n = len(s)
    for col in (s.origin, s.destination):
        share = np.bincount(col, minlength=a) / n
        assert np.abs(share - 1 / a).max() < 5 * math.sqrt((1 / a) / n)
    pairs = np.bincount(s.origin * a + s.destination, minlength=a * a).reshape(a, a)
    assert (np.diag(pairs) == 0).all() and (pairs[~np.eye(a, dtype=bool)] > 0).all()
    assert (np.diff(s.t) >= 0).all() and s.t[0] >= 0 and s.t[-1] < HOURS * 3600


def test_poisson_between_two_airports_never_stays():
    s = packages.poisson(preset("seed-3x3").model_copy(update={
        "airports": preset("seed-3x3").airports[:2]}), hours=50.0, seed=0)
    assert len(s) > 1000 and (s.origin != s.destination).all()


def test_poisson_is_seeded(nine):
    a = packages.poisson(nine, hours=5.0, seed=7)
    b = packages.poisson(nine, hours=5.0, seed=7)
    c = packages.poisson(nine, hours=5.0, seed=8)
    cols = ("t", "origin", "origin_gate", "destination", "destination_gate")
    assert all(np.array_equal(getattr(a, k), getattr(b, k)) for k in cols)
    assert len(a) != len(c) or not np.array_equal(a.t, c.t)
    assert not a.t.flags.writeable  # a stream is read-only


def test_poisson_options(nine):
    assert len(packages.poisson(nine, hours=3.0, seed=0, rate_per_hour=0.0)) == 0
    with pytest.raises(OptionError, match="rate_per_hour=-1"):
        packages.poisson(nine, hours=1.0, rate_per_hour=-1)
    with pytest.raises(OptionError, match="hours=0"):
        packages.poisson(nine, hours=0)


# ------------------------------------------------------------------ CSV

HEADER = "t,from_airport,from_gate,to_airport,to_gate\n"


def write(tmp_path, text: str, name: str = "p.csv"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_a_good_csv_loads_in_spawn_order(tmp_path, nine):
    p = write(tmp_path, HEADER + "120,B,1,A,0\n\n0, A ,0,C,1\n60.5,I,0,B,1\n")
    s = packages.read_csv(p, nine)
    assert s.t.tolist() == [0.0, 60.5, 120.0]
    assert s.origin.tolist() == [0, 8, 1] and s.origin_gate.tolist() == [0, 0, 1]
    assert s.destination.tolist() == [2, 1, 0] and s.destination_gate.tolist() == [1, 1, 0]
    assert len(packages.read_csv(write(tmp_path, HEADER, "empty.csv"), nine)) == 0


def test_a_scenario_reads_its_csv_beside_it_up_to_the_horizon(tmp_path, nine):
    write(tmp_path, HEADER + "10,A,0,B,1\n3599,B,0,C,0\n3600,C,1,A,0\n")
    s = nine.model_copy(update={"packages": nine.packages.model_copy(update={"csv": "p.csv"})})
    got = packages.for_scenario(s, hours=1.0, base=tmp_path)
    assert got.t.tolist() == [10.0, 3599.0]
    # a rate given overrides the file
    assert len(packages.for_scenario(s, hours=1.0, base=tmp_path, rate_per_hour=0.0)) == 0


@pytest.mark.parametrize("text, line, words", [
    ("t,from,from_gate,to_airport,to_gate\n10,A,0,B,1\n", 1,
     "header must be t,from_airport,from_gate,to_airport,to_gate"),
    ("", 1, "header must be"),
    (HEADER + "10,A,0,B,1\n20,Z,0,B,1\n", 3, "from_airport: no airport 'Z'; airports: A, B,"),
    (HEADER + "10,A,0,Q,1\n", 2, "to_airport: no airport 'Q'"),
    (HEADER + "10,A,2,B,1\n", 2, "from_gate: '2' must be 0 or 1"),
    (HEADER + "10,A,0,B,x\n", 2, "to_gate: 'x' must be 0 or 1"),
    (HEADER + "10,A,0,B,1\n\n-5,A,0,B,1\n", 4, "t: '-5' must be a number of seconds >= 0"),
    (HEADER + "soon,A,0,B,1\n", 2, "t: 'soon' must be a number"),
    (HEADER + "nan,A,0,B,1\n", 2, "t: 'nan' must be a number"),
    (HEADER + "10,C,0,C,1\n", 2, "to_airport: 'C' is the origin"),
    (HEADER + "10,A,0,B\n", 2, "expected 5 fields, got 4"),
    # a quoted field holding a line break (a spreadsheet's cell with one) ends its record
    # a line later: the next records' lines were one short, this one named line 3
    (HEADER + '10,A,0,B,1\n20,A,0,B,"1\n"\n30,A,9,B,1\n', 5, "from_gate: '9' must be"),
    (HEADER + '10,A,"x\ny",B,1\n20,A,0,B,2\n', 2, "from_gate: 'x\\ny' must be"),
    (HEADER + '10,A,"0\n",B,1\n20,A,0,B,2\n', 4, "to_gate: '2' must be"),
])
def test_csv_errors_name_the_file_the_line_and_the_field(tmp_path, nine, text, line, words):
    p = write(tmp_path, text)
    with pytest.raises(InputFormatError) as info:
        packages.read_csv(p, nine)
    msg = str(info.value)
    assert msg.startswith(f"{p}:{line}: ") and words in msg
    assert "\n" not in msg


def test_csv_that_cannot_be_read(tmp_path, nine):
    # named once, in the words every reader uses: it was "missing.csv: cannot read:
    # [Errno 2] No such file or directory: 'missing.csv'" and "bin.csv: not text:
    # 'utf-8' codec can't decode byte 0xff in position 0: invalid start byte"
    missing = tmp_path / "missing.csv"
    with pytest.raises(InputFormatError) as err:
        packages.read_csv(missing, nine)
    assert str(err.value) == f"{missing}: no such file"
    p = tmp_path / "bin.csv"
    p.write_bytes(b"\xff\xfe\x00t,from")
    with pytest.raises(InputFormatError) as err:
        packages.read_csv(p, nine)
    assert str(err.value) == f"{p}: cannot read: not UTF-8 text (invalid start byte at byte 0)"


def test_a_csv_past_the_package_limit_names_the_line(tmp_path, nine):
    p = write(tmp_path, HEADER + "0,A,0,B,1\n" * 100_000)
    assert len(packages.read_csv(p, nine)) == 100_000
    p = write(tmp_path, HEADER + "\n" + "0,A,0,B,1\n" * 100_001, "big.csv")
    with pytest.raises(InputFormatError) as err:
        packages.read_csv(p, nine)
    assert str(err.value) == (f"{p}:100003: more than 100,000 packages, the limit of one "
                              "run; split the file")


@pytest.mark.parametrize("kw", [{"seed": "3"}, {"seed": 3.5}, {"seed": -1},
                                {"seed": True}, {"hours": True}, {"hours": "2"},
                                {"rate_per_hour": "60"}, {"hours": 1e300},
                                {"rate_per_hour": 1e300}])
def test_poisson_names_a_bad_option(nine, kw):
    # seeds were numpy's TypeError or ValueError, huge values "lam value too large";
    # True and "2" hours were taken
    kw = {"hours": 1.0, **kw}
    with pytest.raises(OptionError) as err:
        packages.poisson(nine, **kw)
    bad = next(k for k in kw if k != "hours") if len(kw) > 1 else "hours"
    assert bad in str(err.value)


def test_poisson_takes_numpy_numbers(nine):
    a = packages.poisson(nine, hours=np.float32(1.0), seed=np.int64(3),
                         rate_per_hour=np.array(60.0))
    b = packages.poisson(nine, hours=1.0, seed=3, rate_per_hour=60.0)
    assert np.array_equal(a.t, b.t)


def test_a_csv_saved_with_a_byte_order_mark_and_crlf_reads_the_same(tmp_path, nine):
    # Excel's "CSV UTF-8": the mark was read as part of the first column's name, and the
    # header refused ("header must be t,from_airport,...")
    a, b = (x.id for x in nine.airports[:2])
    text = HEADER + f"10,{a},0,{b},1\n20,{b},1,{a},0\n"
    plain = packages.read_csv(write(tmp_path, text), nine)
    p = tmp_path / "excel.csv"
    p.write_bytes(b"\xef\xbb\xbf" + text.replace("\n", "\r\n").encode())
    got = packages.read_csv(p, nine)
    assert len(got) == len(plain) == 2
    for name in ("t", "origin", "origin_gate", "destination", "destination_gate"):
        assert np.array_equal(getattr(got, name), getattr(plain, name))
