"""Serve a data set's ``website/`` folder over HTTP, as the course's web server did."""

from __future__ import annotations

import functools
import threading
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

from skyroute.errors import InputFormatError, SkyrouteError
from skyroute.files import need_folder


class _Quiet(SimpleHTTPRequestHandler):
    def log_message(self, format, *args):
        pass


def make_server(data: Path, port: int, host: str = "127.0.0.1") -> ThreadingHTTPServer:
    """A server for ``data/website`` on ``host:port`` (port 0 picks a free one)."""
    site = need_folder(data) / "website"
    if not site.is_dir():
        raise InputFormatError(data, "not a data folder: no website/ inside")
    handler = functools.partial(_Quiet, directory=str(site))
    try:
        return ThreadingHTTPServer((host, port), handler)
    except OSError as exc:
        raise SkyrouteError(f"cannot serve on {host}:{port}: {exc.strerror or exc}") from None


def serve_in_thread(data: Path, port: int = 0) -> tuple[ThreadingHTTPServer, str]:
    """Start a server in a daemon thread; return it and its base URL (tests, notebooks)."""
    server = make_server(data, port)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    host, p = server.server_address[:2]
    return server, f"http://{host}:{p}"
