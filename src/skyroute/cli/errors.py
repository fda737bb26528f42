"""Turn expected errors into one line on stderr and exit code 2; never a traceback."""

from __future__ import annotations

import re
import sys

import typer
from typer.exceptions import TyperException

from skyroute.errors import SkyrouteError

EXIT_BAD_INPUT = 2

# Library parameters whose CLI flag is not simply --name-with-dashes.
FLAG_OF = {"url": "--db", "names": "--map", "waypoints_out": "--waypoints",
           "mode": "--field-mode", "address": "--dask", "workers": "--jobs"}


def in_flags(exc: SkyrouteError) -> str:
    """The error's message with its parameter (``safety=-1 ...``) spoken of as the CLI
    flag (``--safety -1 ...``): the library names parameters, the CLI its flags."""
    msg = str(exc)
    params = getattr(exc, "param", None) or ()
    for param in (params,) if isinstance(params, str) else params:
        flag = FLAG_OF.get(param, "--" + param.replace("_", "-"))
        msg = re.sub(rf"(?<![\w.-]){re.escape(param)}=", f"{flag} ", msg)
    return msg


def run_cli(app: typer.Typer) -> None:
    """Run a Typer app; expected errors print ``skyroute: error: ...`` and exit 2."""
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
        sys.exit(130)
    if code == 130:  # Typer turns Ctrl-C into exit code 130, silently
        print("skyroute: interrupted", file=sys.stderr)
    sys.exit(code if isinstance(code, int) else 0)
