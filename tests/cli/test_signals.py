"""SIGINT and SIGTERM end a command with one line and 130 / 143, after its work has
unwound: no traceback, no temporary file left beside an output being written."""

import contextlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import typer

import skyroute
from skyroute.cli.errors import run_cli
from tests.conftest import ROOT

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


def _start(args, env=None, **kw):
    env = {**os.environ, "PYTHONPATH": str(SRC), **(env or {})}
    return subprocess.Popen([sys.executable, *args], env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, **kw)


# Ctrl-C handled inside a ctypes callback, as when it comes while numba's LLVM compiles
# (llvmlite's object-cache hook is the next Python to run): ctypes swallows the
# KeyboardInterrupt ("Exception ignored on calling ctypes callback function") and the
# command went on, or failed with numba's RuntimeError traceback.
CALLBACK = """
import ctypes, ctypes.util, os, signal, sys, time
import typer
from skyroute.cli.errors import run_cli

app = typer.Typer(add_completion=False)

@app.command()
def sort() -> None:
    cmp = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.POINTER(ctypes.c_int),
                           ctypes.POINTER(ctypes.c_int))
    def compare(a, b):
        os.kill(os.getpid(), signal.SIGINT)  # its handler runs here, in the callback
        return a[0] - b[0]
    values = (ctypes.c_int * 2)(2, 1)
    libc = ctypes.CDLL(ctypes.util.find_library("c"))
    libc.qsort(values, 2, ctypes.sizeof(ctypes.c_int), cmp(compare))
    print("sorted", flush=True)
    time.sleep(20)  # the rest of the work: the interrupt must end it
    print("finished")

run_cli(app)
"""


def test_an_interrupt_swallowed_by_a_ctypes_callback_still_interrupts():
    p = _start(["-c", CALLBACK])
    try:
        out, err = p.communicate(timeout=30)
    finally:
        p.kill()
    assert (p.returncode, err) == (130, "skyroute: interrupted\n")
    assert "finished" not in out


# Ctrl-C while code made from source text runs, as dataclasses make their methods by
# exec (numba's imports make hundreds, the first seconds of 'fly --vehicle dubins' and
# 'plan-world'). CPython notes a KeyboardInterrupt that leaves such an exec, even one
# caught later, and 'python -m' ended the process by SIGINT after its teardown: exit
# status -2 after "skyroute: interrupted", about one Ctrl-C in eight there.
IN_EXEC = """
import typer
from skyroute.cli.errors import run_cli

app = typer.Typer(add_completion=False)

@app.command()
def define() -> None:
    exec("import os, signal, time\\nos.kill(os.getpid(), signal.SIGINT)\\ntime.sleep(20)")
    print("finished")

run_cli(app)
"""


def test_ctrl_c_inside_an_exec_of_source_exits_130_under_python_m(tmp_path):
    (tmp_path / "exec_command.py").write_text(IN_EXEC)
    p = _start(["-m", "exec_command"], env={"PYTHONPATH": f"{SRC}{os.pathsep}{tmp_path}"})
    try:
        out, err = p.communicate(timeout=30)
    finally:
        p.kill()
    assert (p.returncode, err, out) == (130, "skyroute: interrupted\n", "")


def test_ctrl_c_while_numba_compiles_is_one_line(tmp_path):
    # a first run, the kernels compiled into an empty cache; SIGINT a moment after the
    # first one is saved, while the others compile (where it lands varies: in LLVM's
    # callback, the old code's traceback or lost Ctrl-C, or in Python)
    p = _start(["-m", "skyroute", "plan", "den312d", "--start", "50,76", "--goal", "60,13",
                "--json"], env={"NUMBA_CACHE_DIR": str(tmp_path), "NUMBA_DEBUG_CACHE": "1"})
    try:
        for line in p.stdout:
            if "data saved" in line:
                break
        time.sleep(0.15)
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=30)
    finally:
        p.kill()
    assert (p.returncode, err) == (130, "skyroute: interrupted\n")


# 'fly --vehicle dubins' with Hybrid A*'s search (one compiled call) spied on: each call
# says when it starts and what it returned. A radius of 1 m in the bundled city: its
# 300,000 expansions take seconds (the default budget, minutes).
FLY_DUBINS = """
import sys
from skyroute.motion import hybrid_search
from skyroute.cli.app import console

search = hybrid_search.search

def spy(*args):
    print("searching", flush=True)
    out = search(*args)
    print("status", int(out[0]), flush=True)
    return out

hybrid_search.search = spy
sys.argv = ["skyroute", "fly", sys.argv[1], "--vehicle", "dubins", "--frame", "ned",
            "--altitude", "10", "--safety", "2", "--start", "104,104", "--goal", "-74,5",
            "--radius", "1", "--max-expansions", "300000", "--json"]
console()
"""


def test_ctrl_c_stops_hybrid_a_star_inside_its_search():
    # Ctrl-C waited for the compiled search's end (the default budget: minutes); it now
    # returns at its next poll (4,096 expansions) and the command ends in one line, 130
    from skyroute.search.interrupt import INTERRUPTED

    p = _start(["-c", FLY_DUBINS, str(ROOT / "examples/city.csv")])
    try:
        lines = []
        while lines.count("searching\n") < 2:  # the forward search, after the reversed one
            lines.append(p.stdout.readline())
            assert lines[-1], lines
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=120)
    finally:
        p.kill()
    assert (p.returncode, err) == (130, "skyroute: interrupted\n")
    assert out == f"status {INTERRUPTED}\n"  # no JSON: the flight was not planned


def test_ctrl_c_while_a_fleet_run_is_written_leaves_the_earlier_run(tmp_path):
    # the folder holds an earlier run; Ctrl-C once the first file of the new one is
    # written must leave that run whole, not a mix of the two (report.json new, the
    # rest old) nor a part of the new one
    from skyroute.io.fleet_out import RUN_FILES

    out = tmp_path / "run"
    out.mkdir()
    for name in RUN_FILES:
        (out / name).write_text(f"earlier {name}\n")
    before = sorted(out.iterdir())
    # tracks every 0.05 s: a tracks.csv of 7 MB, seconds to write after report.json
    p = _start(["-m", "skyroute", "fleet", "simulate", "--preset", "seed-3x3", "--hours", "1",
                "--track-step", "0.05", "--out", str(out), "--json"])
    try:
        while p.poll() is None and not any(
                f.name.startswith(".report.json.") or f.read_text() != f"earlier {f.name}\n"
                for f in out.iterdir() if f.name.startswith((".report", "report"))):
            time.sleep(0.002)
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=30)
    finally:
        p.kill()
    assert (p.returncode, err) == (130, "skyroute: interrupted\n")
    assert sorted(out.iterdir()) == before  # no temporary file left either
    assert all((out / n).read_text() == f"earlier {n}\n" for n in RUN_FILES)


def _starting_workers(pid: int) -> int:
    """The processes under ``pid`` that multiprocessing's spawn started whose Python has
    set its SIGINT handler and not yet been told to ignore SIGINT (/proc's masks): a
    Dask worker importing distributed, before its preload."""
    import psutil

    n = 0
    for child in psutil.Process(pid).children(recursive=True):
        with contextlib.suppress(psutil.Error, OSError):  # (one that ended meanwhile)
            status = dict(line.split(":\t", 1)
                          for line in Path(f"/proc/{child.pid}/status").read_text().splitlines()
                          if line.startswith(("SigCgt", "SigIgn")))
            bit = 1 << (signal.SIGINT - 1)
            n += "spawn_main" in " ".join(child.cmdline()) and \
                bool(int(status["SigCgt"], 16) & bit) and not int(status["SigIgn"], 16) & bit
    return n


def test_ctrl_c_as_the_dask_workers_start_is_one_line():
    # a terminal's Ctrl-C reaches the whole group: in the seconds the in-process
    # cluster's workers took to import distributed, each printed a KeyboardInterrupt
    # traceback, then "Nanny failed to start" and, at exit, distributed's close_clusters
    # AssertionError (Status.init), some 80 lines under "skyroute: interrupted"
    p = _start(["-m", "skyroute", "fleet", "sweep", "--preset", "seed-3x3", "--seeds", "0-3",
                "--hours", "1", "--executor", "dask", "--jobs", "2"],
               start_new_session=True)
    try:
        end = time.monotonic() + 120
        while p.poll() is None and time.monotonic() < end and _starting_workers(p.pid) < 2:
            time.sleep(0.005)  # both workers started, importing distributed
        os.killpg(p.pid, signal.SIGINT)
        _, err = p.communicate(timeout=120)
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(p.pid, signal.SIGKILL)
    assert (p.returncode, err) == (130, "skyroute: interrupted\n")


# A command whose clean-up after a Ctrl-C takes a while (workers ending, a transaction
# rolled back, temporary files removed): a second Ctrl-C comes during it.
SLOW_CLEANUP = """
import sys, time
from pathlib import Path
import typer
from skyroute.cli.errors import run_cli

app = typer.Typer(add_completion=False)

@app.command()
def work(marker: str) -> None:
    try:
        print("ready", flush=True)
        time.sleep(30)
    finally:
        print("cleaning up", flush=True)
        time.sleep(0.5)
        Path(marker).write_text("done")  # the clean-up's last step

run_cli(app)
"""


@pytest.mark.parametrize("second", [signal.SIGINT, signal.SIGTERM])
def test_a_second_signal_does_not_cut_the_clean_up_short(tmp_path, second):
    # a second Ctrl-C (or SIGTERM) while the first one's clean-up ran raised in that
    # clean-up: its last steps were skipped (a temporary file left, workers not ended)
    marker = tmp_path / "cleaned"
    p = _start(["-c", SLOW_CLEANUP, str(marker)])
    try:
        assert p.stdout.readline() == "ready\n"
        p.send_signal(signal.SIGINT)
        assert p.stdout.readline() == "cleaning up\n"
        p.send_signal(second)
        _, err = p.communicate(timeout=20)
    finally:
        p.kill()
    assert (p.returncode, err) == (130, "skyroute: interrupted\n")
    assert marker.read_text() == "done"


class _Stderr:
    """stderr on which a second Ctrl-C arrives while the one line is written."""

    def __init__(self) -> None:
        self.text = ""

    def write(self, text: str) -> int:
        if not self.text:
            signal.raise_signal(signal.SIGINT)
        self.text += text
        return len(text)

    def flush(self) -> None:
        pass


def test_a_second_ctrl_c_while_the_line_is_printed(monkeypatch):
    # 'skyroute prepare' pressed Ctrl-C twice: a KeyboardInterrupt traceback under
    # "skyroute: interrupted", and the process died by the signal (exit status -2)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # run_cli's then
    monkeypatch.setattr(sys, "argv", ["skyroute"])
    err = _Stderr()
    monkeypatch.setattr(sys, "stderr", err)
    try:
        with pytest.raises(SystemExit) as done:
            run_cli(_raises(KeyboardInterrupt()))
    except KeyboardInterrupt:  # (not out of the test: it would end the test session)
        pytest.fail("the second Ctrl-C came out of run_cli as a KeyboardInterrupt")
    assert done.value.code == 130
    assert err.text == "skyroute: interrupted\n"


# Signals in Python's teardown, after the command has done its work (an atexit hook of
# numba, Dask or multiprocessing runs then: the hook here stands for them). One Ctrl-C
# printed "Exception ignored in atexit callback" and a KeyboardInterrupt traceback under
# the command's output (later in the teardown the process was killed by the signal
# instead: exit status -2 for a command that had done its work); ignoring them all left
# a teardown that hangs (a thread or a pool not let go) to SIGKILL.
TEARDOWN = """
import atexit, os, signal, sys, time
from skyroute.cli.app import console

def hook():
    for _ in range({signals}):
        os.kill(os.getpid(), signal.SIGINT)
    time.sleep({hang})

atexit.register(hook)
sys.argv = ["skyroute", "--version"]
console()
"""


@pytest.mark.parametrize("signals, hang", [(1, 0), (2, 120)],
                         ids=["one-changes-nothing", "a-second-leaves-a-hung-teardown"])
def test_signals_in_the_teardown_keep_the_commands_exit_code(signals, hang):
    p = _start(["-c", TEARDOWN.format(signals=signals, hang=hang)])
    try:
        stdout, err = p.communicate(timeout=60)
    finally:
        p.kill()
    assert (p.returncode, err) == (0, "")
    assert stdout == f"skyroute {skyroute.__version__}\n"
