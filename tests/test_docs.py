"""The docstring examples run as written."""

import doctest
import importlib

import pytest

MODULES = ["skyroute.world.grid", "skyroute.world.load", "skyroute.planner"]


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


@pytest.mark.slow
def test_readme_cli_examples_run_in_order(monkeypatch, capsys, tmp_path, fly_once):
    """Each command as written, in one folder, exit code 0. Delivery days the suite has
    already flown from the same data are reused (fly_once); run alone, it flies them."""
    import shlex
    import sys

    from skyroute.cli.app import main

    commands = readme_cli_examples()
    assert len(commands) >= 8
    monkeypatch.chdir(tmp_path)  # one folder: later examples read earlier outputs
    for command in commands:
        monkeypatch.setattr(sys, "argv", shlex.split(command))
        with pytest.raises(SystemExit) as exit_info:
            main()
        assert exit_info.value.code == 0, (command, capsys.readouterr().err)
    assert (tmp_path / "city.png").exists() and (tmp_path / "city-waypoints.json").exists()
