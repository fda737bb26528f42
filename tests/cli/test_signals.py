"""SIGINT and SIGTERM end a command with one line and 130 / 143, after its work has
unwound: no traceback, no temporary file left beside an output being written."""

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest
import typer

import skyroute
from skyroute.cli.errors import run_cli

SRC = Path(skyroute.__file__).resolve().parents[1]

# A command caught halfway through writing its output file when the signal comes.
WRITER = """
import sys, time
import typer
from skyroute.cli.errors import run_cli
from skyroute.files import open_atomic

app = typer.Typer(add_completion=False)

@app.command()
def write(path: str) -> None:
    with open_atomic(path) as f:
        f.write(b"half of it")
        print("ready", flush=True)
        time.sleep(30)
        f.write(b" and the rest")

run_cli(app)
"""


@pytest.mark.parametrize(("sig", "code", "line"), [
    (signal.SIGTERM, 143, "skyroute: terminated"),
    (signal.SIGINT, 130, "skyroute: interrupted"),
])
def test_signal_mid_write_leaves_nothing(tmp_path, sig, code, line):
    out = tmp_path / "out"
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    p = subprocess.Popen([sys.executable, "-c", WRITER, str(out / "day.geojson")], env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline() == "ready\n"
        p.send_signal(sig)
        _, err = p.communicate(timeout=20)
    finally:
        p.kill()
    assert (p.returncode, err) == (code, line + "\n")
    assert list(out.iterdir()) == []  # neither the file nor its temporary twin


def _raises(exc: BaseException):
    app = typer.Typer(add_completion=False)

    @app.command()
    def go() -> None:
        raise exc

    return app


def test_signal_inside_a_numba_call_is_an_interrupt(monkeypatch, capsys):
    # Ctrl-C while a numba kernel was called: CPython reports the KeyboardInterrupt as
    # the cause of a SystemError ('CPUDispatcher(...) returned a result with an exception
    # set'), which was a traceback and exit code 1
    try:
        raise SystemError("CPUDispatcher(<function search>) returned a result with an "
                          "exception set") from KeyboardInterrupt()
    except SystemError as e:
        exc = e
    monkeypatch.setattr(sys, "argv", ["skyroute"])
    with pytest.raises(SystemExit) as done:
        run_cli(_raises(exc))
    assert done.value.code == 130
    assert capsys.readouterr().err == "skyroute: interrupted\n"


def test_other_system_errors_are_not_hidden(monkeypatch):
    monkeypatch.setattr(sys, "argv", ["skyroute"])
    with pytest.raises(SystemError):
        run_cli(_raises(SystemError("a real bug")))


def test_sigterm_handler_is_restored(monkeypatch):
    monkeypatch.setattr(sys, "argv", ["skyroute"])
    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(SystemExit):
        run_cli(_raises(KeyboardInterrupt()))
    assert signal.getsignal(signal.SIGTERM) is before
