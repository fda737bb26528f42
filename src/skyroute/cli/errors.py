"""Turn expected errors into one line on stderr and exit code 2; never a traceback."""

from __future__ import annotations

import _thread
import os
import re
import signal
import sys
import threading
import time

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


class _Signals:
    """The signals that came while a command ran (SIGINT, SIGTERM), remembered apart from
    the exception each raised: that exception can be lost on its way up. A signal that
    arrives while C code runs (numba's LLVM compiling a kernel, most of a first run) is
    handled at the next line of Python, which is often a ctypes callback (llvmlite's
    object-cache hook); ctypes prints the KeyboardInterrupt as "Exception ignored on
    calling ctypes callback function" with its traceback, and numba then failed with
    RuntimeError ('no compiled object yet'): a traceback and exit code 1 for a Ctrl-C.

    A second signal while the first one's exception unwinds the work, or once the
    command is ending by it (``ending``), raises nothing: it cut the clean-up short (a
    temporary file not removed, workers not ended) or, in the last line, printed a
    KeyboardInterrupt traceback under ``skyroute: interrupted`` and died by the signal.
    One that comes after the first was swallowed (handled and done with) raises again.
    """

    def __init__(self, main_pid: int) -> None:
        self.main_pid = main_pid
        self.seen: int | None = None  # the last signal (signal.SIGINT / SIGTERM)
        self.active = True  # our handlers are in place
        self.ending = False  # the command is ending by a signal: its line is due

    def unwinding(self) -> bool:
        """Whether a signal's exception is being handled (an ``except`` or ``finally``
        block, a context manager's exit, or what they call), or the command is ending:
        by a signal, or with its exit code on the way out (SystemExit)."""
        handled = sys.exc_info()[1]
        return self.ending or isinstance(handled, SystemExit) or \
            _interrupt(handled) is not None

    def on_sigint(self, signum, frame):
        if self.unwinding():
            return
        self.seen = signal.SIGINT
        raise KeyboardInterrupt

    def on_sigterm(self, signum, frame):
        if os.getpid() != self.main_pid:  # a forked worker: die as it would have
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
            os.kill(os.getpid(), signal.SIGTERM)
            return
        if self.unwinding():
            return
        self.seen = signal.SIGTERM
        raise Terminated

    def unraisable(self, before):
        """A ``sys.unraisablehook``: an interrupt that could not be raised where it came
        (a ctypes callback, a ``__del__``) prints nothing and is raised again in the
        main thread (:meth:`_raise_later`). Other unraisable errors go to ``before``, but
        not after a signal: then they are its fallout (llvmlite's half-made objects
        failing in ``__del__`` when the interrupt stopped their ``__init__``), each a
        traceback after the one line."""
        def hook(info) -> None:
            if not isinstance(info.exc_value, KeyboardInterrupt | Terminated):
                if self.seen is None:
                    before(info)
                return
            signum = signal.SIGTERM if isinstance(info.exc_value, Terminated) else \
                signal.SIGINT
            try:
                self.seen = signum
                # a bare thread: Thread.start() waits for it, and another interrupt
                # raised in that wait would be lost in this hook
                _thread.start_new_thread(self._raise_later, (signum,))
            except (KeyboardInterrupt, Terminated):  # the one raised later came early
                _thread.start_new_thread(self._raise_later, (signum,))
        return hook

    def _raise_later(self, signum: int) -> None:
        """Run the handler of ``signum`` in the main thread again, once the hook that
        swallowed its exception has returned (raised there, it would be swallowed too:
        a signal's handler runs at the next line of Python, which would be the hook's)."""
        time.sleep(0.01)
        if self.active:  # a real signal to the main thread wakes it from a wait too
            signal.pthread_kill(threading.main_thread().ident, signum)


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


def database_failure(exc: BaseException) -> str | None:
    """One line for an error the store's database driver raised through SQLAlchemy (its
    ``orig``: a full disk, a disk I/O error, a server gone mid-run), else None. Such an
    error is no bug of skyroute and no input of the user's to fix, but it was printed as
    a traceback; the transaction it ended was rolled back (and a day's files put back).
    SQLAlchemy is not imported for the test: a plan never loads it."""
    if not type(exc).__module__.startswith("sqlalchemy"):
        return None
    orig = getattr(exc, "orig", None)
    if orig is None:
        return None
    text = (str(orig).strip().splitlines() or [type(orig).__name__])[0]
    return f"the store's database failed: {text} (nothing of the step it ended was stored)"


def run_cli(app: typer.Typer) -> None:
    """Run a Typer app; expected errors print ``skyroute: error: ...`` and exit 2;
    SIGINT prints ``skyroute: interrupted`` and exits 130, SIGTERM ``skyroute:
    terminated`` and 143, after the work has unwound; also when the signal's exception
    was swallowed on its way (:class:`_Signals`) and the work failed another way."""
    if threading.current_thread() is not threading.main_thread():
        _run(app, None)
        return
    signals = _Signals(os.getpid())
    # not over handlers someone else set (a test runner, an embedding program)
    handlers = {sig: ours for sig, ours, default in (
        (signal.SIGINT, signals.on_sigint, signal.default_int_handler),
        (signal.SIGTERM, signals.on_sigterm, signal.SIG_DFL))
        if signal.getsignal(sig) is default}
    before = {sig: signal.signal(sig, ours) for sig, ours in handlers.items()}
    hook = sys.unraisablehook
    sys.unraisablehook = signals.unraisable(hook)
    try:
        _run(app, signals)
    finally:
        signals.active = False
        sys.unraisablehook = hook
        for sig, handler in before.items():
            signal.signal(sig, handler)
        _forget_interrupts_in_exec()


def _forget_interrupts_in_exec() -> None:
    """Clear CPython's note that a KeyboardInterrupt left an ``exec`` of source text.

    CPython notes it whenever one does (``run_eval_code_obj``), even when a caller
    catches it, and ``python -m`` then ends the process by SIGINT after the teardown,
    whatever the exit code: ``python -m skyroute`` exited -2 (a shell shows 130 either
    way) after ``skyroute: interrupted`` about one Ctrl-C in eight in the first seconds
    of ``fly`` or ``plan-world``, which import numba: dataclasses make their methods by
    ``exec`` of source, and the Ctrl-C landed in one. Each such ``exec`` clears the note
    first, so an empty one clears it; the command's exit code stands."""
    exec("")


def _signal_exit(signum, signals: _Signals | None) -> None:
    if signals is not None:
        signals.ending = True  # a second Ctrl-C must not cut the line short
    term = signum == signal.SIGTERM
    print(f"skyroute: {'terminated' if term else 'interrupted'}", file=sys.stderr)
    sys.exit(EXIT_TERMINATED if term else EXIT_INTERRUPTED)


def _run(app: typer.Typer, signals: _Signals | None) -> None:
    try:
        # One name for the program in every usage line and hint, as in the "skyroute:
        # error:" prefix, the docs and the commands messages suggest ("plan in it with
        # 'skyroute plan-world ...'"): Click named it "python -m skyroute" when so run,
        # and "python -m pytest.skyroute" when main() ran inside another -m program.
        code = app(standalone_mode=False, prog_name="skyroute")
    except TyperException as exc:  # usage errors: unknown option, missing argument, ...
        ctx = getattr(exc, "ctx", None)
        hint = f" (see '{ctx.command_path} --help')" if ctx is not None else ""
        print(f"skyroute: error: {exc.format_message()}{hint}", file=sys.stderr)
        sys.exit(getattr(exc, "exit_code", EXIT_BAD_INPUT) or EXIT_BAD_INPUT)
    except (typer.Abort, KeyboardInterrupt):
        _signal_exit(signal.SIGINT, signals)
    except Terminated:
        _signal_exit(signal.SIGTERM, signals)
    except Exception as exc:
        # the signal's own exception lost on the way (see _Signals), or wrapped: a
        # SystemError from a numba call ('CPUDispatcher(...) returned a result with an
        # exception set') caused by it; an error after a signal is the signal's doing
        found = _interrupt(exc)
        if found is not None:
            _signal_exit(signal.SIGTERM if isinstance(found, Terminated) else signal.SIGINT,
                         signals)
        if signals is not None and signals.seen is not None:
            _signal_exit(signals.seen, signals)
        if isinstance(exc, SkyrouteError):
            print(f"skyroute: error: {in_flags(exc)}", file=sys.stderr)
            sys.exit(EXIT_BAD_INPUT)
        line = database_failure(exc)
        if line is not None:
            print(f"skyroute: error: {line}", file=sys.stderr)
            sys.exit(EXIT_BAD_INPUT)
        raise
    if code == EXIT_INTERRUPTED:  # Typer turns Ctrl-C into exit code 130, silently
        _signal_exit(signal.SIGINT, signals)
    sys.exit(code if isinstance(code, int) else 0)
