"""A status line for work that may run long without output (``skyroute plan``, ``fly``,
...): shown only when the work outlasts a delay, only where progress shows (an
interactive terminal on stderr, :func:`skyroute.cli.tables.shows_progress`), and gone
when the work ends, by return, error or Ctrl-C.

Quick work pays a thread that waits (about 0.2 ms) and nothing else: Rich is imported
only once the status is due, so ``skyroute plan --json`` on a warm compile cache still
loads no Rich (tests/cli/test_startup.py). Past the delay Rich is loaded even off a
terminal, in the waiting thread, to make the same decision as the progress bars.
"""

from __future__ import annotations

import sys
import threading
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rich.console import Console
    from rich.live import Live
    from rich.spinner import Spinner

DELAY = 1.0  # seconds of silence before the status shows
COMPILING = "the first run compiles kernels; later runs are fast"


class DelayedStatus:
    """``with delayed_status("planning"): ...``: after ``delay`` seconds of work, a
    spinner with "planning…" on stderr, with :data:`COMPILING` added once numba has
    compiled a kernel during this phase (a cache miss: what makes a first run slow).

    ``update(message)`` names a new phase; ``text`` is the line shown. ``settled`` is set
    when the status has been shown, found not wanted (off a terminal) or not needed (the
    work ended within the delay); ``shown`` tells whether it was. Tests wait on it.
    """

    def __init__(self, message: str, *, delay: float | None = None,
                 console: Console | None = None) -> None:
        self._message = message
        self._compiled = False  # numba compiled a kernel in this phase
        self._delay = DELAY if delay is None else delay
        self._console = console  # None: stderr, made when the status is due
        self._lock = threading.Lock()  # orders showing against ending
        self._done = threading.Event()
        self._live: Live | None = None
        self._spinner: Spinner | None = None
        self._listener = None
        self.settled = threading.Event()
        self.shown = False

    def __enter__(self) -> DelayedStatus:
        self._watch_compiles()
        threading.Thread(target=self._show_later, name="skyroute-status",
                         daemon=True).start()
        return self

    def __exit__(self, *exc) -> None:
        self._done.set()
        with self._lock:  # after this, the thread shows and registers nothing
            live, self._live = self._live, None
            listener, self._listener = self._listener, None
        if live is not None:
            live.stop()  # transient: the line is erased
        if listener is not None:
            sys.modules["numba.core.event"].unregister("numba:compile", listener)

    def update(self, message: str) -> None:
        """Name the next phase of the work (its compiles are its own)."""
        self._message, self._compiled = message, False
        self._retext()

    @property
    def text(self) -> str:
        """The status line: the message, and why it is slow when numba compiled."""
        return f"{self._message}…" + (f" ({COMPILING})" if self._compiled else "")

    def _retext(self) -> None:
        with self._lock:
            if self._spinner is not None:
                from rich.text import Text  # loaded already: the spinner shows

                self._spinner.update(text=Text(self.text))  # as given: no markup

    def _on_compile(self) -> None:
        if not self._compiled:
            self._compiled = True
            self._retext()

    def _watch_compiles(self) -> None:
        """Listen for numba's compiles once numba is loaded; never import it here (a
        command that does not use it must not pay for it)."""
        event = sys.modules.get("numba.core.event")
        if event is None or not hasattr(event, "Listener"):  # not loaded, or loading
            return
        with self._lock:
            if self._listener is None and not self._done.is_set():
                self._listener = _compile_listener(event, self._on_compile)
                event.register("numba:compile", self._listener)

    def _show_later(self) -> None:
        try:
            if self._done.wait(self._delay):
                return
            self._watch_compiles()  # numba may have been loaded by the work meanwhile
            from rich.live import Live
            from rich.spinner import Spinner
            from rich.text import Text

            from skyroute.cli.tables import plain_console, shows_progress

            console = self._console or plain_console(stderr=True)
            if not shows_progress(console):
                return
            with self._lock:
                if self._done.is_set():
                    return
                self._spinner = Spinner("dots", text=Text(self.text), style="status.spinner")
                # stdout stays the command's own (pure JSON with --json); stray stderr
                # lines (warnings) print above the status
                live = Live(self._spinner, console=console, refresh_per_second=12.5,
                            transient=True, redirect_stdout=False)
                live.start(refresh=True)
                self._live, self.shown = live, True
        except Exception:  # a status must never fail the work, nor print a traceback
            pass
        finally:
            self.settled.set()


def delayed_status(message: str, *, delay: float | None = None,
                   console: Console | None = None) -> DelayedStatus:
    """A status line for ``with`` around work that may run long without output; see
    :class:`DelayedStatus`. ``message`` says what is happening ("planning"; the ellipsis
    is added), ``delay`` the seconds before it shows (default :data:`DELAY`), ``console``
    where (default: stderr)."""
    return DelayedStatus(message, delay=delay, console=console)


def _compile_listener(event, on_start):
    """A numba event listener calling ``on_start()`` when a compile starts."""

    class CompileListener(event.Listener):
        def on_start(self, ev) -> None:
            on_start()

        def on_end(self, ev) -> None:
            pass

    return CompileListener()
