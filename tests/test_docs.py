"""The docstring and README examples run as written."""

import doctest
import filecmp
import importlib
import json

import pytest

from tests.conftest import ROOT


def modules_with_examples() -> list[str]:
    """Every skyroute module whose source holds a docstring example (``>>>``), found
    rather than listed, so a new example cannot go unchecked."""
    src = ROOT / "src"
    return sorted(".".join(p.relative_to(src).with_suffix("").parts)
                  for p in (src / "skyroute").rglob("*.py") if ">>> " in p.read_text())


def test_examples_are_found():
    assert {"skyroute.planner", "skyroute.search.prepared",
            "skyroute.motion.dubins"} <= set(modules_with_examples())


@pytest.mark.parametrize("name", modules_with_examples())
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
    assert printed[synth].startswith(f"wrote {shlex.split(synth)[3]}: 108 orders over 3 days")
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
            # its long name and its short one, each the first of its kind ('prepare
            # --out' hid behind '-o': only '-o' was named, and '--out' elsewhere)
            own = [kind[0] for kind in ([f for f in flags if f.startswith("--")],
                                        [f for f in flags if not f.startswith("--")]) if kind]
            for flag in own:
                assert names(flag, sections[key]), (name, flag)
            for old in p.secondary_opts + [f for f in flags if f not in own]:
                assert names(old, text), (name, old)


FLAG = r"(?<![\w-])--?[a-zA-Z][\w-]*"


def cli_md_options(text: str, names: list[str]) -> list[tuple[str, str]]:
    """(command, option) for every option docs/cli.md writes in a synopsis of a command:
    a code block's lines from a ``skyroute COMMAND`` line to the next, an inline
    ```skyroute COMMAND ...``` span, and the first column of a table in the command's own
    ``## skyroute COMMAND`` section. Prose may name other commands' options; these may not."""
    import re

    def command(chunk):
        words = chunk.split()
        found = [n for n in names if words[:1] == ["skyroute"]
                 and words[1:1 + len(n.split())] == n.split()]
        return max(found, key=len, default=None)

    blocks = re.findall(r"^```[^\n]*\n(.*?)^```", text, re.M | re.S)
    prose = re.sub(r"^```[^\n]*\n.*?^```", "", text, flags=re.M | re.S)
    chunks = [c for b in blocks for c in re.split(r"\n(?=skyroute )", b)]
    chunks += prose.split("`")[1::2]  # inline code spans
    pairs = [(command(c), f) for c in chunks for f in re.findall(FLAG, c)]
    for key, body in re.findall(r"^## skyroute ([a-z -]+)\n(.*?)(?=^## |\Z)", prose,
                                re.M | re.S):
        if key in names:
            pairs += [(key, f) for cell in re.findall(r"^\| ([^|\n]*)\|", body, re.M)
                      for f in re.findall(FLAG, cell)]
    return [(c, f) for c, f in pairs if c is not None]


def test_cli_md_options_are_the_commands_options():
    """Every option docs/cli.md gives a command in its synopses and option tables is one
    of that command's (or an old name it keeps): an option renamed or dropped in the
    code but not in the page fails here; one renamed in the page only fails
    test_cli_md_names_every_option."""
    commands = dict(_cli_commands())
    pairs = cli_md_options((ROOT / "docs" / "cli.md").read_text(), list(commands))
    assert len({c for c, _ in pairs}) >= 20 and len(pairs) >= 200  # the parser found them
    known = {name: {o for p in cmd.params for o in p.opts + p.secondary_opts} | {"--help"}
             for name, cmd in commands.items()}
    assert [(c, f) for c, f in pairs if f not in known[c]] == []


def cli_md_defaults(text: str, names: list[str]) -> list[tuple[str, str, str]]:
    """(command, option, value) for every ``[--option VALUE]`` of a docs/cli.md synopsis
    (code blocks and inline spans, as :func:`cli_md_options` reads them) whose VALUE is
    written as the default (``[--clients 50]``, ``[--seeds 0-9]``), not as a placeholder
    (``[--safety C]``, ``[--db URL]``) or an example (``[--plot out.png]``)."""
    import re

    blocks = re.findall(r"^```[^\n]*\n(.*?)^```", text, re.M | re.S)
    prose = re.sub(r"^```[^\n]*\n.*?^```", "", text, flags=re.M | re.S)
    chunks = [c for b in blocks for c in re.split(r"\n(?=skyroute )", b)]
    chunks += prose.split("`")[1::2]
    out = []
    for chunk in chunks:
        words = chunk.split()
        found = [n for n in names if words[:1] == ["skyroute"]
                 and words[1:1 + len(n.split())] == n.split()]
        if found:
            out += [(max(found, key=len), flag, value) for flag, value in
                    re.findall(r"\[(--[\w-]+)\s+([^\]\s|]+)\]", chunk)]
    return out


def test_cli_md_synopsis_defaults_are_the_commands_defaults():
    """A value docs/cli.md's synopses give an option (``[--requests 2000]``,
    ``[--method milp]``) is the default its --help shows: a default changed in the code
    alone fails here. A value in capitals is a placeholder, one the option does not
    default to (None) or one with '...' an example; each is left out."""
    commands = dict(_cli_commands())
    triples = cli_md_defaults((ROOT / "docs" / "cli.md").read_text(), list(commands))
    checked, bad = 0, []
    for name, flag, value in triples:
        (param,) = [p for p in commands[name].params if flag in p.opts + p.secondary_opts]
        if value.isupper() or "..." in value or param.default in (None, ""):
            continue
        if isinstance(param.default, str) or not isinstance(param.default, (int, float)):
            same = value == str(param.default)
        else:
            same = float(value) == float(param.default)
        checked += 1
        if not same:
            bad.append((name, flag, value, param.default))
    assert checked >= 40  # the synopses were read
    assert bad == []


def doc_command_lines() -> list[tuple[str, str]]:
    """(file, command line) for each ``skyroute`` command in a code block of README.md
    and docs/*.md, after any environment settings or ``time`` in front, up to a ``>``
    redirection; synopses (with ``[optional]`` parts) are left out."""
    import re

    out = []
    for path in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for block in re.findall(r"^```[^\n]*\n(.*?)^```", path.read_text(), re.M | re.S):
            for line in block.replace("\\\n", " ").splitlines():
                for part in re.split(r";|&&", line.split(" #")[0]):
                    m = re.search(r"(?:^|[\s/])(skyroute [^>]*)", part)
                    if m and "[" not in m.group(1):
                        out.append((path.name, m.group(1).strip()))
    return out


def test_doc_command_lines_parse():
    """Every ``skyroute`` command line the README and docs/ show, benchmarks' long runs
    included, names a command and options that exist, with the right arity (parsed by the
    CLI's own parser, not run)."""
    import shlex

    import typer.main
    from typer.exceptions import TyperException  # click's errors (typer carries its own)

    from skyroute.cli.app import app

    root = typer.main.get_command(app)
    lines = doc_command_lines()
    assert len(lines) >= 60
    bad = []
    for name, line in lines:
        args, cmd = shlex.split(line)[1:], root
        while hasattr(cmd, "list_commands") and args and args[0] in cmd.list_commands(None):
            cmd = cmd.get_command(None, args.pop(0))
        if hasattr(cmd, "list_commands"):
            bad.append((name, line, f"no such command: {args[:1]}"))
            continue
        try:
            cmd.make_context("skyroute", args)
        except TyperException as exc:  # an unknown option, a missing value or argument
            bad.append((name, line, exc.format_message()))
    assert bad == []


def test_fleet_md_python_example():
    """docs/fleet.md's Python example runs and prints what the page says (it was not run
    by any test, and showed no output to compare with)."""
    result = doctest.testfile(str(ROOT / "docs" / "fleet.md"), module_relative=False)
    assert result.attempted >= 6 and result.failed == 0


def docs_python_blocks() -> list[tuple[str, str]]:
    """(page, code) for each ```python block of docs/*.md written as a script (no ``>>>``
    prompts: doctest runs those) and not marked ``<!-- not run ...: why -->`` on the line
    before it, found rather than listed."""
    import re

    out = []
    for path in sorted((ROOT / "docs").glob("*.md")):
        for mark, code in re.findall(r"^(?:(<!-- not run[^\n]*-->)\n)?```python\n(.*?)^```",
                                     path.read_text(), re.M | re.S):
            if not mark and ">>> " not in code:
                out.append((path.name, code))
    return out


def test_docs_python_blocks_are_found():
    """The pattern finds the blocks (benchmarks.md's set-up timing) and the marked one
    (scaling.md's, which needs a cluster) stays out."""
    pages = [page for page, _ in docs_python_blocks()]
    assert "benchmarks.md" in pages and "scaling.md" not in pages


@pytest.mark.parametrize("page, code", docs_python_blocks(),
                         ids=[f"{p}:{i}" for i, (p, _) in enumerate(docs_python_blocks())])
def test_docs_python_blocks_run(page, code, monkeypatch, tmp_path):
    """Each script-style Python example of docs/ runs as written (no test ran them:
    only the README's and fleet.md's, which are doctests)."""
    monkeypatch.chdir(tmp_path)
    exec(compile(code, page, "exec"), {"__name__": "__main__"})


def test_relative_links_resolve():
    """Every relative link of the README, the changelog and docs/ names a file that exists
    and, with ``#anchor``, a heading of it (GitHub's anchors: lower case, punctuation
    dropped, spaces as hyphens)."""
    import re

    def anchors(path):
        return {re.sub(r"[^\w\- ]", "", h.strip().lower()).replace(" ", "-")
                for h in re.findall(r"^#+ (.*)$", path.read_text(), re.M)}

    pages = [ROOT / "README.md", ROOT / "CHANGELOG.md", *sorted((ROOT / "docs").glob("*.md"))]
    links = [(page, link) for page in pages
             for link in re.findall(r"\]\(([^)\s]+)\)", re.sub(r"^```.*?^```", "",
                                                            page.read_text(),
                                                            flags=re.M | re.S))
             if not re.match(r"[a-z]+:", link)]
    assert len(links) >= 15  # the pattern still finds them
    bad = []
    for page, link in links:
        path, _, anchor = link.partition("#")
        target = (page.parent / path) if path else page
        if not target.exists() or (anchor and anchor not in anchors(target)):
            bad.append((page.name, link))
    assert bad == []
