"""The docstring and README examples run as written."""

import doctest
import filecmp
import importlib
import json

import pytest

from tests.conftest import ROOT

MODULES = ["skyroute.world.grid", "skyroute.world.load", "skyroute.planner",
           "skyroute.fleet.vehicle", "skyroute.fleet.trajectory",
           "skyroute.fleet.separation", "skyroute.fleet.flightplan",
           "skyroute.io.fleet_out", "skyroute.fleet.limits", "skyroute.io.plot"]


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


def _cli_commands():
    import typer.main

    from skyroute.cli.app import app

    def walk(cmd, path=()):
        if hasattr(cmd, "list_commands"):
            for name in cmd.list_commands(None):
                yield from walk(cmd.get_command(None, name), (*path, name))
        else:
            yield " ".join(path), cmd

    return list(walk(typer.main.get_command(app)))


@pytest.mark.parametrize("name,cmd", _cli_commands(), ids=[n for n, _ in _cli_commands()])
def test_cli_md_names_every_option(name, cmd):
    """docs/cli.md's section for a command (## skyroute NAME, or its group's) names each
    of its options (a synopsis lacked 'bench service --client' and 'fleet sweep
    --area-km'); an old name, kept as a second flag, may be named anywhere in the page."""
    import re

    text = (ROOT / "docs" / "cli.md").read_text()
    sections = dict(re.findall(r"^## skyroute ([a-z -]+)\n(.*?)(?=^## |\Z)", text, re.M | re.S))
    key = max((k for k in sections if name == k or name.startswith(k + " ")), key=len)
    def names(flag, where):
        return re.search(rf"(?<![\w-]){re.escape(flag)}(?![\w-])", where) is not None

    for p in cmd.params:
        flags = [o for o in p.opts if o.startswith("-")]
        if flags and flags[0] != "--help":
            assert any(names(f, sections[key]) for f in flags), (name, flags)
            for old in p.secondary_opts + flags[1:]:
                assert names(old, text), (name, old)
