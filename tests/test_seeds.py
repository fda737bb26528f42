"""One seed range everywhere: an integer from 0 to 2**32 - 1, refused past it with the
same words in Python and on the command line. Hybrid A*'s shortcutting seeds numba's
32-bit generator, so seed 2**32 flew seed 0's path (and 2**32 + 5 seed 5's)."""

from __future__ import annotations

import pytest
import shapely

import skyroute
from skyroute.errors import OptionError
from tests.cli.test_cli import run

BIG = 2**32  # one past the range: seed 0's stream in the old shortcutting
PY_WORDS = "must be an integer from 0 to 4,294,967,295"
CLI_WORDS = "is not in the range 0<=x<=4294967295"


def _tower():
    return skyroute.World([shapely.box(1, 1, 3, 3)], [0], [50], ("tower",),
                          boundary=shapely.box(-5, -5, 10, 10))


def _hybrid(seed):
    from skyroute.motion.hybrid import plan

    return plan(_tower(), (0, 2, 0), (5, 2, 0), 0.5, seed=seed)


def _tour(seed):
    from skyroute.motion.tour import tour

    return tour((0, 0, 0), [(4, 0), (4, 4)], 1.0, seed=seed)


def _prm(seed):
    return skyroute.plan(_tower(), (0, 2), (5, 2), algorithm="prm", samples=50, seed=seed)


def _poisson(seed):
    from skyroute.fleet.packages import poisson
    from skyroute.fleet.scenario import preset

    return poisson(preset("seed-3x3"), hours=0.1, seed=seed)


def _generate(seed):
    from skyroute.fleet.scenario import generate

    return generate(3, 3, seed=seed)


def _synth(seed, tmp_path):
    from skyroute.delivery.synth import synth

    return synth(tmp_path / "lunch", days=1, orders_per_day=1, seed=seed)


def _fleet_job(seed):
    from skyroute.jobs.fleet import check_fleet_params

    return check_fleet_params({"preset": "seed-3x3", "seed": seed})


CALLS = {"hybrid.plan": _hybrid, "tour": _tour, "prm": _prm, "poisson": _poisson,
         "generate": _generate, "fleet job": _fleet_job}


@pytest.mark.parametrize("seed", [BIG, BIG + 5, 2**64, -1])
@pytest.mark.parametrize("name", sorted(CALLS))
def test_a_seed_out_of_range_is_refused_with_the_same_words(name, seed):
    with pytest.raises(OptionError) as err:
        CALLS[name](seed)
    assert err.value.param == "seed"
    assert str(err.value) == f"seed={seed} {PY_WORDS}"


def test_synth_refuses_a_seed_past_the_range(tmp_path):
    with pytest.raises(OptionError, match=f"^seed={BIG} {PY_WORDS}$"):
        _synth(BIG, tmp_path)
    assert not (tmp_path / "lunch").exists()


@pytest.mark.parametrize("name", ["hybrid.plan", "tour", "prm"])
def test_the_largest_seed_is_taken(name):
    assert CALLS[name](2**32 - 1).status is skyroute.Status.FOUND


@pytest.mark.parametrize("args", [
    ("synth-city", "{tmp}/c.csv"),
    ("plan-world", "{city}", "--frame", "ned", "--start", "0,0", "--goal", "5,5",
     "--algorithm", "prm"),
    ("data", "synth", "{tmp}/lunch", "--days", "1"),
    ("fleet", "simulate", "--preset", "seed-3x3", "--hours", "0.1"),
    ("fleet", "scenario", "--airports", "3", "--drones", "3"),
    ("bench", "grid", "--per-map", "1", "--peers", ""),
    ("bench", "world", "--worlds", "1"),
    ("bench", "motion", "--worlds", "1"),
    ("bench", "fleet"),
    ("bench", "service"),
], ids=lambda a: "-".join(x for x in a[:2] if "{" not in x))
@pytest.mark.parametrize("seed", [str(BIG), "-1"])
def test_every_seed_option_takes_one_range_with_one_message(monkeypatch, capsys, tmp_path,
                                                            args, seed):
    city = tmp_path / "city.csv"
    city.write_text("lat0 37.79, lon0 -122.39\nposX,posY,posZ,halfSizeX,halfSizeY,"
                    "halfSizeZ\n20,20,5,2,2,5\n")
    args = [a.format(tmp=tmp_path, city=city) for a in args]
    code, out, err = run(monkeypatch, capsys, *args, "--seed", seed)
    assert code == 2, (out, err)
    assert f"'--seed': {seed} {CLI_WORDS}." in err and len(err.strip().splitlines()) == 1, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["city.csv"]


@pytest.mark.parametrize("seeds", [str(BIG), f"0,{BIG}", f"{BIG - 1}-{BIG}", "3,-1"])
def test_sweep_seeds_take_the_same_range(monkeypatch, capsys, seeds):
    code, out, err = run(monkeypatch, capsys, "fleet", "sweep", "--preset", "seed-3x3",
                         "--seeds", seeds, "--hours", "0.1")
    assert code == 2 and len(err.strip().splitlines()) == 1, (out, err)
    assert f"--seeds {seeds!r}: " in err and CLI_WORDS in err, err
