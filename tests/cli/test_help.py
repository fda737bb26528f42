"""Every command's --help as Typer renders it (Rich markup): text in square brackets that
a help string means literally must be shown, not read as a markup tag and dropped."""

import inspect

import pytest
import typer.main
import typer.rich_utils
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
    assert "Write [[north, east, altitude, heading], ...] JSON here" in result.output
    # the file's heading is FCND's, radians; the CLI reads headings in degrees elsewhere
    assert "heading in radians clockwise from north" in " ".join(result.output.split())


@pytest.mark.parametrize("path,cmd", COMMANDS, ids=[" ".join(p) or "skyroute" for p, _ in COMMANDS])
def test_help_paragraphs_carry_no_hard_line_breaks(path, cmd):
    # Typer keeps the breaks of every paragraph after the first and wraps again, so a
    # docstring wrapped in the source printed lines broken mid-sentence
    for paragraph in (cmd.help or "").split("\n\n"):
        assert paragraph.startswith("\b") or "\n" not in paragraph, (path, paragraph)


def _source_paragraphs(cmd):
    """The paragraphs of the command's help as written (its function's docstring, else
    its help), each on one line: what ``--help`` should print, however it is wrapped."""
    callback = getattr(cmd.callback, "__wrapped__", cmd.callback)
    text = (callback and inspect.getdoc(callback)) or cmd.help or ""
    for paragraph in text.partition("\f")[0].split("\n\n"):
        if not paragraph.startswith("\b"):
            yield Text.from_markup(" ".join(paragraph.split())).plain


@pytest.mark.parametrize("path,cmd", COMMANDS, ids=[" ".join(p) or "skyroute" for p, _ in COMMANDS])
def test_rendered_help_prints_each_paragraph_as_one_line(path, cmd, monkeypatch):
    # As rendered, not as held in cmd.help: Typer kept the source's line breaks in every
    # paragraph after the first and wrapped again, so 'fly --help' broke its second
    # paragraph mid-sentence. Wide enough for any paragraph, each must be one line.
    monkeypatch.setattr(typer.rich_utils, "MAX_WIDTH", 2000)
    result = CliRunner().invoke(app, [*path, "--help"])
    assert result.exit_code == 0, result.output
    lines = {line.strip() for line in result.output.splitlines()}
    for paragraph in _source_paragraphs(cmd):
        assert len(paragraph) < 1900 and paragraph in lines, (path, paragraph)


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


def test_commands_registered_on_the_app_are_unwrapped_too(monkeypatch):
    # Only the loaders' commands were unwrapped; one added with @app.command (or by
    # Typer, as built) kept its line breaks.
    from skyroute.cli.lazy_group import lazy_group

    host = typer.Typer(cls=lazy_group({}), add_completion=False)

    @host.command("direct")
    def direct() -> None:
        """First paragraph.

        A second paragraph, wrapped in the source
        at an arbitrary column.
        """

    @host.command("other")  # two commands: Typer makes a group
    def other() -> None:
        """Another."""

    monkeypatch.setattr(typer.rich_utils, "MAX_WIDTH", 2000)
    result = CliRunner().invoke(host, ["direct", "--help"])
    assert "A second paragraph, wrapped in the source at an arbitrary column." in {
        line.strip() for line in result.output.splitlines()}


def test_version_is_the_installed_one():
    """pyproject takes its version from skyroute.__version__: the two cannot drift."""
    from importlib.metadata import version

    import skyroute

    result = CliRunner().invoke(app, ["--version"])
    assert result.exit_code == 0
    assert result.output == f"skyroute {skyroute.__version__}\n"
    assert version("skyroute") == skyroute.__version__


def test_deliver_replace_help_reads_as_one_sentence():
    """It was pieced together as "...; with --data also: Store the file's orders ..."."""
    (deliver,) = [cmd for path, cmd in COMMANDS if path == ("deliver",)]
    (replace,) = [p for p in deliver.params if p.name == "replace"]
    assert "(kept otherwise); with --data also store the files' orders of each day" \
        in replace.help
