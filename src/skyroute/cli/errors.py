"""Turn expected errors into one line on stderr and exit code 2; never a traceback."""

from __future__ import annotations

import os
import re
import signal
import sys
import threading

import typer
from typer.exceptions import TyperException

from skyroute.errors import SkyrouteError

EXIT_BAD_INPUT = 2
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as a shell reports Ctrl-C
EXIT_TERMINATED = 143  # 128 + SIGTERM


class Terminated(BaseException):
    """SIGTERM (``kill``, ``timeout``, a service manager), raised where the program is, as
    Ctrl-C raises KeyboardInterrupt: the work unwinds, so an output file being written is
    removed (:func:`skyroute.files.open_atomic`), an open transaction is rolled back and
    worker processes are shut down. Python's default was to die on the spot, silently."""

# Library parameters whose CLI flag is not simply --name-with-dashes.
FLAG_OF = {"url": "--db", "names": "--map", "waypoints_out": "--waypoints",
           "mode": "--field-mode", "address": "--dask", "workers": "--jobs",
           "rate_per_hour": "--rate"}


def in_flags(exc: SkyrouteError) -> str:
    """The error's message with its parameter (``safety=-1 ...``) spoken of as the CLI
    flag (``--safety -1 ...``): the library names parameters, the CLI its flags."""
    msg = str(exc)
    params = getattr(exc, "param", None) or ()
    for param in (params,) if isinstance(params, str) else params:
        flag = FLAG_OF.get(param, "--" + param.replace("_", "-"))
        msg = re.sub(rf"(?<![\w.-]){re.escape(param)}=", f"{flag} ", msg)
    return msg


def _on_sigterm(main_pid: int):
    def handler(signum, frame):
        if os.getpid() != main_pid:  # a forked worker: die as it would have
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
            os.kill(os.getpid(), signal.SIGTERM)
            return
        raise Terminated
    return handler


def _interrupt(exc: BaseException) -> BaseException | None:
    """The KeyboardInterrupt or Terminated behind ``exc``: a signal that arrives while a
    numba kernel is being called surfaces as SystemError ('CPUDispatcher(...) returned a
    result with an exception set') caused by it."""
    seen = 0
    while exc is not None and seen < 10:
        if isinstance(exc, KeyboardInterrupt | Terminated):
            return exc
        exc, seen = exc.__cause__ or exc.__context__, seen + 1
    return None


def run_cli(app: typer.Typer) -> None:
    """Run a Typer app; expected errors print ``skyroute: error: ...`` and exit 2;
    SIGINT prints ``skyroute: interrupted`` and exits 130, SIGTERM ``skyroute:
    terminated`` and 143, after the work has unwound."""
    before = signal.getsignal(signal.SIGTERM)
    ours = before is signal.SIG_DFL and threading.current_thread() is threading.main_thread()
    if ours:  # not over a handler someone else set (a test runner, an embedding program)
        signal.signal(signal.SIGTERM, _on_sigterm(os.getpid()))
    try:
        _run(app)
    finally:
        if ours:
            signal.signal(signal.SIGTERM, before)


def _run(app: typer.Typer) -> None:
    try:
        code = app(standalone_mode=False)
    except TyperException as exc:  # usage errors: unknown option, missing argument, ...
        ctx = getattr(exc, "ctx", None)
        hint = f" (see '{ctx.command_path} --help')" if ctx is not None else ""
        print(f"skyroute: error: {exc.format_message()}{hint}", file=sys.stderr)
        sys.exit(getattr(exc, "exit_code", EXIT_BAD_INPUT) or EXIT_BAD_INPUT)
    except SkyrouteError as exc:
        print(f"skyroute: error: {in_flags(exc)}", file=sys.stderr)
        sys.exit(EXIT_BAD_INPUT)
    except (typer.Abort, KeyboardInterrupt):
        print("skyroute: interrupted", file=sys.stderr)
        sys.exit(EXIT_INTERRUPTED)
    except Terminated:
        print("skyroute: terminated", file=sys.stderr)
        sys.exit(EXIT_TERMINATED)
    except SystemError as exc:
        signal_exc = _interrupt(exc)
        if signal_exc is None:
            raise
        term = isinstance(signal_exc, Terminated)
        print(f"skyroute: {'terminated' if term else 'interrupted'}", file=sys.stderr)
        sys.exit(EXIT_TERMINATED if term else EXIT_INTERRUPTED)
    if code == EXIT_INTERRUPTED:  # Typer turns Ctrl-C into exit code 130, silently
        print("skyroute: interrupted", file=sys.stderr)
    sys.exit(code if isinstance(code, int) else 0)
