"""``skyroute serve``: the REST service and viewer on uvicorn."""

from __future__ import annotations

import os
import signal
from pathlib import Path
from typing import Annotated

import typer

from skyroute.delivery.store import DEFAULT_DB
from skyroute.errors import InputFormatError, OptionError
from skyroute.files import read_text

TOKEN_ENV = "SKYROUTE_TOKEN"


def read_token(token_file: Path | None) -> tuple[str | None, str]:
    """(token, where it came from): ``$SKYROUTE_TOKEN``, else ``--token-file``, else
    (None, "generated")."""
    if os.environ.get(TOKEN_ENV):
        return os.environ[TOKEN_ENV].strip(), TOKEN_ENV
    if token_file is not None:
        try:  # a byte-order mark (Notepad's) is no part of the token
            token = read_text(token_file).strip()
        except InputFormatError as exc:
            raise OptionError(f"--token-file {exc}") from None
        if not token:
            raise OptionError(f"--token-file {token_file}: the file is empty")
        return token, str(token_file)
    return None, "generated"


def serve_command(
    db: Annotated[str, typer.Option(help="SQLAlchemy URL of the store.")] = DEFAULT_DB,
    data: Annotated[Path | None, typer.Option(
        help="The delivery site: a data folder in the ILP layout (as 'deliver').")] = None,
    source: Annotated[str | None, typer.Option(
        help="The delivery site over HTTP (as 'deliver').")] = None,
    host: Annotated[str, typer.Option(help="Address to listen on.")] = "127.0.0.1",
    allowed_hosts: Annotated[str | None, typer.Option(
        help="The names clients reach the server by, comma-separated (host names, "
             "addresses, *.example.com; '*' for any): a request whose Host header names "
             "another is a 400, so a page of another site cannot reach the server through "
             "a DNS name of its own (DNS rebinding). Default: on a loopback --host, "
             "localhost, 127.0.0.1, ::1 and the --host; on any other, any (with a "
             "warning).")] = None,
    port: Annotated[int, typer.Option(help="Port to listen on.")] = 8000,
    root_path: Annotated[str, typer.Option(
        help="The path a reverse proxy serves the server under (/skyroute for "
             "https://host/skyroute/...; the proxy strips it): the links the service "
             "hands out start with it. Default: none.")] = "",
    dask: Annotated[str | None, typer.Option(
        help="Run jobs on this Dask scheduler (tcp://HOST:8786); default: local "
             "processes.")] = None,
    token_file: Annotated[Path | None, typer.Option(
        help="Read the write token from this file (else $SKYROUTE_TOKEN, else one is made "
             "and printed).")] = None,
    workers: Annotated[int, typer.Option(help="Server processes.")] = 1,
    max_body_mb: Annotated[float, typer.Option(help="Largest request body, MB.")] = 10.0,
    max_expansions: Annotated[int, typer.Option(
        help="The cap on one POST /plan's search budget (a request without "
             "max_expansions, enough to finish the search, is capped to it).")] = 2_000_000,
    max_samples: Annotated[int, typer.Option(
        help="Largest PRM roadmap of one POST /plan (its samples; /openapi.json declares "
             "the limit).")] = 20_000,
    job_queue: Annotated[int, typer.Option(help="Jobs queued or running at once.")] = 8,
    log_level: Annotated[str, typer.Option(
        help="The lowest level logged on stderr, by uvicorn and skyroute alike: critical, "
             "error, warning, info, debug or trace.")] = "info",
    warm: Annotated[bool, typer.Option(
        "--warm/--no-warm", help="Load the planners' compiled kernels in each server "
        "process before it takes requests (about a second from numba's cache), so no "
        "caller's first /plan waits for them.")] = True,
) -> None:
    """Serve the REST API (/docs) and the web viewer (/) with uvicorn.

    Reads are open; writes need 'Authorization: Bearer TOKEN'. The token comes from
    $SKYROUTE_TOKEN or --token-file; without either, one is made and printed once.
    """
    import uvicorn
    from pydantic import ValidationError

    from skyroute.service.app import SETTINGS_ENV, create_app
    from skyroute.service.logs import LEVELS, log_config
    from skyroute.service.resources import make_engine
    from skyroute.service.settings import MB, Settings

    if data is not None and source is not None:
        raise OptionError("give at most one of --data DIR and --source URL")
    if data is not None or source is not None:
        from skyroute.delivery.source import open_source

        open_source(data, source)  # a bad folder or URL: one line now, not a 503 later
    if log_level.lower() not in LEVELS:  # uvicorn's KeyError traceback, after the banner
        raise OptionError(f"--log-level {log_level!r} is not valid; choose one of "
                          f"{', '.join(LEVELS)}")
    log_level = log_level.lower()
    if not 0 < port < 65536:
        raise OptionError(f"--port {port} must be 1..65535")
    if workers < 1:
        raise OptionError(f"--workers {workers} must be at least 1")
    root_path = check_root_path(root_path)
    check_listen(host, port)
    token, where = read_token(token_file)
    hosts = (default_hosts(host) if allowed_hosts is None
             else [h for h in allowed_hosts.split(",") if h.strip()])
    try:
        settings = Settings(db_url=db, data_dir=data, source_url=source, dask_address=dask,
                            max_body_bytes=int(max_body_mb * MB),
                            max_expansions=max_expansions, max_samples=max_samples,
                            job_queue=job_queue, warm=warm,
                            allowed_hosts=hosts, **({"token": token} if token else {}))
    except ValidationError as exc:  # a limit out of range, or the token: before the store
        err = exc.errors()[0]
        field = str(err["loc"][0]) if err["loc"] else ""
        flag = {"max_body_bytes": "--max-body-mb", "job_queue": "--job-queue",
                "max_expansions": "--max-expansions", "max_samples": "--max-samples",
                "allowed_hosts": "--allowed-hosts"
                }.get(field, TOKEN_ENV if where == TOKEN_ENV else f"--token-file {where}")
        raise OptionError(f"{flag}: {err['msg'].removeprefix('Value error, ')}") from None
    if dask is not None:  # a wrong address (or skyroute on the cluster): one line now;
        # it was found by the first job, a 422 naming the address to its caller
        from skyroute.jobs.executor import open_executor

        open_executor("dask", address=dask).close()
    engine = make_engine(db)  # the store opens and is migrated before anyone asks
    orphans = _fail_orphans(engine)
    engine.dispose()
    if orphans:
        typer.echo(f"{len(orphans)} job(s) left queued or running by a stopped server "
                   "marked failed", err=True)
    url = f"http://{host}:{port}/"
    typer.echo(f"skyroute service on {url} (API docs {url}docs)", err=True)
    if root_path:
        typer.echo(f"served by a proxy under {root_path}/: the links it hands out start "
                   "with it", err=True)
    if allowed_hosts is None and "*" in settings.allowed_hosts:
        typer.echo(f"warning: on --host {host} any Host header is taken, so a page of "
                   "another site may reach this server through a DNS name it points here; "
                   "give the names clients use with --allowed-hosts", err=True)
    if where == "generated":
        typer.echo(f"write token (give it as 'Authorization: Bearer TOKEN'; set "
                   f"{TOKEN_ENV} or --token-file to choose one):\n    {settings.token}")
    else:
        typer.echo(f"write token from {where}", err=True)
    # SIGTERM is how a server is stopped (systemd, docker): uvicorn shuts down gracefully
    # and then re-raises it, which run_cli's handler would report as "terminated", 143
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    # skyroute's loggers print as uvicorn's, at --log-level (each worker applies it)
    logs = {"log_level": log_level, "log_config": log_config(log_level),
            "root_path": root_path}
    if workers == 1:
        uvicorn.run(create_app(settings), host=host, port=port, **logs)
    else:
        os.environ[SETTINGS_ENV] = settings.model_dump_json()
        uvicorn.run("skyroute.service.app:app_from_env", factory=True, workers=workers,
                    host=host, port=port, **logs)


LOOPBACK_HOSTS = ("localhost", "127.0.0.1", "::1")


def default_hosts(host: str) -> list[str]:
    """``--allowed-hosts``'s default for ``--host``: on a loopback address (every address
    ``host`` resolves to is one: 127.0.0.1, ::1, localhost) the names of this machine's
    loopback and ``host`` itself, the names a local client's Host header gives; on any
    other (0.0.0.0, a name of the machine's network) any, ``*``: the names other
    machines reach it by are not known here."""
    import ipaddress
    import socket

    try:
        found = socket.getaddrinfo(host, None, type=socket.SOCK_STREAM)
    except (socket.gaierror, UnicodeError):
        return ["*"]
    addresses = {ipaddress.ip_address(a[4][0].split("%")[0]) for a in found}
    if addresses and all(a.is_loopback for a in addresses):
        return [*LOOPBACK_HOSTS, host]
    return ["*"]


def check_root_path(value: str) -> str:
    """``--root-path`` as uvicorn takes it: empty, or ``/`` and path segments, without a
    trailing ``/`` (``/skyroute/`` is ``/skyroute``; ``/`` is none)."""
    path = value.strip().rstrip("/")
    if path and (not path.startswith("/") or any(c in path for c in "?#\\ ")
                 or "//" in path):
        raise OptionError(f"--root-path {value!r} must be a path such as /skyroute (a "
                          "leading /, no query, no spaces)")
    try:
        path.encode("ascii")  # uvicorn puts it in front of the raw path, as ASCII
    except UnicodeEncodeError:
        raise OptionError(f"--root-path {value!r} must be ASCII (percent-encode other "
                          "characters)") from None
    return path


def check_listen(host: str, port: int) -> None:
    """Bind ``host:port`` as uvicorn will, and let it go: a port another server holds, a
    host name that does not resolve or an address not of this machine is one line naming
    the option, before the store is opened or the banner printed (uvicorn said it in its
    log after "skyroute service on ..." and exited 3). Every address the name resolves
    to is bound, as asyncio's ``create_server`` binds them all: ``localhost`` is often
    ::1 and 127.0.0.1, and the first alone passed while another server held the second."""
    import errno
    import socket
    from contextlib import ExitStack

    try:
        found = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM,
                                   flags=socket.AI_PASSIVE)
    except (socket.gaierror, UnicodeError) as exc:
        raise OptionError(f"--host {host!r}: not an address "
                          f"({getattr(exc, 'strerror', None) or exc})") from None
    with ExitStack() as held:  # all at once, as the server holds them
        for family, kind, proto, _, addr in dict.fromkeys(found):
            s = held.enter_context(socket.socket(family, kind, proto))
            s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as uvicorn's own bind
            if family == socket.AF_INET6:  # as asyncio: '::' must not take 0.0.0.0 too
                s.setsockopt(socket.IPPROTO_IPV6, socket.IPV6_V6ONLY, 1)
            try:
                s.bind(addr)
            except OSError as exc:
                why = {errno.EADDRINUSE: "the port is in use (another server?); choose "
                                         "another --port",
                       errno.EADDRNOTAVAIL: "the address is not one of this machine's; see "
                                            "--host",
                       errno.EACCES: "permission denied (ports below 1024 need "
                                     "privileges)"}
                raise OptionError(f"--port {port}: cannot listen on {host}:{port}: "
                                  f"{why.get(exc.errno, exc.strerror)}") from None


def _fail_orphans(engine) -> list[str]:
    """Jobs a stopped server left unfinished, marked failed (none without skyroute.jobs):
    once here, before any worker takes a job, so no live job is touched."""
    try:
        from skyroute.jobs.runner import fail_orphans
    except ImportError:
        return []
    return fail_orphans(engine)
