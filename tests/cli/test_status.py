"""The delayed status of commands that can be silent for seconds (a first run compiling
numba kernels): shown only when the work outlasts the delay, only on an interactive
terminal, always cleared; stdout untouched.

No timing asserts: the work waits on the status's ``settled`` event, never on a sleep.
"""

from __future__ import annotations

import io
import json

import pytest
from rich.console import Console

from skyroute.cli import plan_cmd
from skyroute.cli import status as status_mod
from skyroute.cli.status import COMPILING, delayed_status
from tests.cli.test_cli import QUERY, run

ERASED = "\x1b[2K"  # the line erased
CURSOR_BACK = "\x1b[?25h"  # the cursor shown again


def terminal() -> tuple[Console, io.StringIO]:
    screen = io.StringIO()
    return Console(file=screen, force_terminal=True, force_interactive=True, width=100), screen


@pytest.fixture
def no_forced_terminal(monkeypatch):
    for name in ("FORCE_COLOR", "TTY_COMPATIBLE", "TTY_INTERACTIVE"):
        monkeypatch.delenv(name, raising=False)


def cleared(out: str, text: str) -> bool:
    """The last frame of ``text`` is followed by the cursor shown and the line erased."""
    tail = out[out.rindex(text) + len(text):]
    return CURSOR_BACK in tail and out.endswith(ERASED)


def test_nothing_when_stderr_is_not_a_terminal(monkeypatch, no_forced_terminal):
    log = io.StringIO()
    monkeypatch.setattr("sys.stderr", log)  # the default console is stderr's, made late
    with delayed_status("planning", delay=0.0) as status:
        assert status.settled.wait(10)  # the work outlasts the delay
        assert not status.shown
    assert log.getvalue() == ""


def test_shown_on_a_terminal_after_the_delay_and_cleared():
    console, screen = terminal()
    with delayed_status("planning", delay=0.001, console=console) as status:
        assert status.settled.wait(10)
        assert status.shown and status.text == "planning…"
        status.update("drawing")
        assert status.text == "drawing…"
    out = screen.getvalue()
    assert "planning…" in out and cleared(out, "…")


def test_quick_work_shows_nothing_even_on_a_terminal():
    console, screen = terminal()
    with delayed_status("planning", console=console) as status:  # the default delay, 1 s
        pass
    assert status.settled.wait(10) and not status.shown
    assert screen.getvalue() == ""


def test_cleared_when_the_work_fails():
    console, screen = terminal()
    with pytest.raises(KeyError), delayed_status("planning", delay=0.001,
                                                 console=console) as status:
        assert status.settled.wait(10) and status.shown
        raise KeyError("boom")
    assert cleared(screen.getvalue(), "planning…")


def test_cleared_on_ctrl_c():
    console, screen = terminal()
    with pytest.raises(KeyboardInterrupt), delayed_status("planning", delay=0.001,
                                                          console=console) as status:
        assert status.settled.wait(10) and status.shown
        raise KeyboardInterrupt
    assert cleared(screen.getvalue(), "planning…")


def test_says_kernels_compile_only_when_numba_compiles():
    import numba

    @numba.njit  # not cached: each definition compiles on its first call
    def add_one(x):
        return x + 1

    console, _ = terminal()
    with delayed_status("planning", delay=0.001, console=console) as status:
        assert status.settled.wait(10)
        assert status.text == "planning…"  # nothing compiled yet: no claim
        add_one(1)
        assert status.text == f"planning… ({COMPILING})"
        add_one(2)  # compiled now: no event, the note stays for this phase
        status.update("writing")
        assert status.text == "writing…"  # a new phase, nothing compiled in it


def test_plan_json_stdout_stays_pure_json_while_the_status_shows(monkeypatch, capsys):
    # stderr made an interactive terminal as Rich reads the environment; the plan waits
    # until the status is up, so it shows while stdout gets the JSON
    monkeypatch.setenv("TTY_COMPATIBLE", "1")
    monkeypatch.setenv("TTY_INTERACTIVE", "1")
    monkeypatch.setattr(status_mod, "DELAY", 0.0)
    made = []

    def recording(*args, **kwargs):
        made.append(delayed_status(*args, **kwargs))
        return made[-1]

    real_load = plan_cmd.load_map

    def held_load(*args, **kwargs):
        assert made[-1].settled.wait(10)
        return real_load(*args, **kwargs)

    monkeypatch.setattr(plan_cmd, "delayed_status", recording)
    monkeypatch.setattr(plan_cmd, "load_map", held_load)
    code, out, err = run(monkeypatch, capsys, "plan", *QUERY, "--json")
    assert code == 0, err
    assert json.loads(out)["status"] == "found"  # the whole of stdout is the JSON
    assert made[-1].shown and "planning…" in err and cleared(err, "…")


def test_plan_json_off_a_terminal_writes_nothing_else(monkeypatch, capsys,
                                                      no_forced_terminal):
    monkeypatch.setattr(status_mod, "DELAY", 0.0)
    code, out, err = run(monkeypatch, capsys, "plan", *QUERY, "--json")
    assert code == 0, err
    assert json.loads(out)["status"] == "found" and err == ""
