"""Every command's --help as Typer renders it (Rich markup): text in square brackets that
a help string means literally must be shown, not read as a markup tag and dropped."""

import pytest
import typer.main
from rich.text import Text
from typer.testing import CliRunner

from skyroute.cli.app import app


def _commands(cmd, path=()):
    yield path, cmd
    if hasattr(cmd, "list_commands"):
        for name in cmd.list_commands(None):
            yield from _commands(cmd.get_command(None, name), (*path, name))


COMMANDS = list(_commands(typer.main.get_command(app)))


def _help_texts(cmd):
    yield "help", cmd.help or ""
    for p in cmd.params:
        yield p.name, getattr(p, "help", None) or ""


def test_walk_finds_nested_commands():
    names = {" ".join(path) for path, _ in COMMANDS}
    assert {"plan-world", "fly", "bench service", "fleet sweep", "db init"} <= names


@pytest.mark.parametrize("path,cmd", COMMANDS, ids=[" ".join(p) or "skyroute" for p, _ in COMMANDS])
def test_help_strings_survive_rich_markup(path, cmd):
    # Typer shows each help string as Text.from_markup(help); a literal '[' must be
    # escaped ('\\[' or rich.markup.escape), and then it renders as the text meant.
    for name, text in _help_texts(cmd):
        assert Text.from_markup(text).plain == text.replace("\\[", "["), (path, name, text)


@pytest.mark.parametrize("path,cmd", COMMANDS, ids=[" ".join(p) or "skyroute" for p, _ in COMMANDS])
def test_rendered_help_keeps_bracketed_text(path, cmd):
    result = CliRunner().invoke(app, [*path, "--help"], env={"COLUMNS": "200",
                                                             "TERMINAL_WIDTH": "200"})
    assert result.exit_code == 0, result.output
    assert "[, ...]" not in result.output


def test_plan_world_help_shows_the_waypoint_format():
    result = CliRunner().invoke(app, ["plan-world", "--help"], env={"COLUMNS": "200",
                                                                    "TERMINAL_WIDTH": "200"})
    assert result.exit_code == 0, result.output
    assert "Write [[north, east, altitude, heading], ...] JSON here." in result.output


@pytest.mark.parametrize("path,cmd", COMMANDS, ids=[" ".join(p) or "skyroute" for p, _ in COMMANDS])
def test_help_paragraphs_carry_no_hard_line_breaks(path, cmd):
    # Typer keeps the breaks of every paragraph after the first and wraps again, so a
    # docstring wrapped in the source printed lines broken mid-sentence
    for paragraph in (cmd.help or "").split("\n\n"):
        assert paragraph.startswith("\b") or "\n" not in paragraph, (path, paragraph)


def test_fly_help_second_paragraph_reads_as_one():
    result = CliRunner().invoke(app, ["fly", "--help"], env={"COLUMNS": "200",
                                                             "TERMINAL_WIDTH": "200"})
    assert result.exit_code == 0, result.output
    assert ("Points, headings and written trajectories are in --frame (headings in degrees); "
            "the step drone flies the ILP rules") in result.output


@pytest.mark.parametrize("path,cmd", COMMANDS, ids=[" ".join(p) or "skyroute" for p, _ in COMMANDS])
def test_usage_names_arguments_plainly(path, cmd):
    # Typer 0.28 wrote a required argument in braces: "skyroute fly [OPTIONS] {WORLD}"
    result = CliRunner().invoke(app, [*path, "--help"], env={"COLUMNS": "200",
                                                             "TERMINAL_WIDTH": "200"})
    usage = next(line for line in result.output.splitlines() if "Usage:" in line).split()
    arguments = [p for p in cmd.params if p.param_type_name == "argument"]
    assert usage[len(usage) - len(arguments):] == [
        p.metavar if p.required else f"[{p.metavar.strip('[]')}]" for p in arguments]
    assert not {"{", "}"} & set("".join(usage)), usage
