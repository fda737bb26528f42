"""The docstring and README examples run as written."""

import doctest
import filecmp
import importlib
import json

import pytest

MODULES = ["skyroute.world.grid", "skyroute.world.load", "skyroute.planner",
           "skyroute.fleet.vehicle", "skyroute.fleet.trajectory",
           "skyroute.fleet.separation", "skyroute.fleet.flightplan",
           "skyroute.io.fleet_out"]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    result = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0


def test_readme_python_example():
    from tests.conftest import ROOT

    result = doctest.testfile(str(ROOT / "README.md"), module_relative=False,
                              optionflags=doctest.ELLIPSIS)
    assert result.attempted >= 6 and result.failed == 0


def readme_cli_examples() -> list[str]:
    from tests.conftest import ROOT

    text = (ROOT / "README.md").read_text()
    usage = text[text.index("## Usage"):]
    block = usage[usage.index("```sh") + 5:]
    block = block[:block.index("```")]
    return [line.split("#")[0].strip() for line in block.splitlines()
            if line.strip().startswith("skyroute ")]


def same_tree(a, b) -> bool:
    cmp = filecmp.dircmp(a, b)
    if cmp.left_only or cmp.right_only or cmp.diff_files or cmp.funny_files:
        return False
    return all(same_tree(a / d, b / d) for d in cmp.common_dirs)


@pytest.mark.slow
def test_readme_cli_examples_run_in_order(monkeypatch, capsys, tmp_path, fly_once):
    """Each command as written, in one folder, exit code 0. Delivery days the suite has
    already flown from the same data are reused (fly_once); run alone, it flies them."""
    import shlex
    import sys

    from skyroute.cli.app import main
    from tests.conftest import ROOT

    commands = readme_cli_examples()
    assert len(commands) >= 8
    monkeypatch.chdir(tmp_path)  # one folder: later examples read earlier outputs
    printed = {}
    for command in commands:
        line, _, target = command.partition(" > ")  # 'cmd > file': stdout into the file
        monkeypatch.setattr(sys, "argv", shlex.split(line))
        with pytest.raises(SystemExit) as exit_info:
            main()
        out, err = capsys.readouterr()
        assert exit_info.value.code == 0, (command, err)
        printed[command] = out
        if target:
            (tmp_path / target.strip()).write_text(out)
    assert (tmp_path / "city.png").exists() and (tmp_path / "city-waypoints.json").exists()
    fleet_run = json.loads(printed[next(c for c in commands if " fleet.yaml " in c
                                        and "--json" in c)])
    assert fleet_run["conflicts"] == 0 and fleet_run["settings"]["drones"] == 8
    assert (tmp_path / "fleet-out" / "map.png").exists()
    # The README's 'data synth' command writes what the repository ships in examples/lunch
    # (the set the README's set-up command flies), file for file.
    synth = next(c for c in commands if c.startswith("skyroute data synth "))
    assert json.loads(printed[synth].replace("\n", ""))["orders"] == 108
    assert same_tree(ROOT / "examples" / "lunch", tmp_path / shlex.split(synth)[3])


def test_readme_lonlat_city_matches_plan_world(monkeypatch, capsys):
    """The README's lon/lat city example and its plan-world command agree exactly."""
    import json

    import skyroute
    from tests.cli.test_cli import run
    from tests.conftest import ROOT

    city = str(ROOT / "examples" / "city.csv")
    world = skyroute.load_world(city, altitude=10, safety=2)
    r = skyroute.plan(world, (-3.1890, 55.9456), (-3.1850, 55.9432))
    code, out, err = run(monkeypatch, capsys, "plan-world", city, "--start=-3.1890,55.9456",
                         "--goal=-3.1850,55.9432", "--altitude", "10", "--safety", "2",
                         "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["cost"] == r.cost and doc["path"] == r.path.tolist()
    assert round(doc["cost"], 6) == 367.319524  # the number the README prints


def test_shipped_city_is_what_synth_city_writes():
    import numpy as np

    from skyroute.world.synth import synth_city
    from tests.conftest import ROOT

    assert (ROOT / "examples" / "city.csv").read_text() == synth_city(np.random.default_rng(7))
