"""What an app opens on first use and closes at shutdown: the store's engine (the engine
factory), the delivery site, the bundled grids, and the jobs' executor. Nothing here runs
at import or when the app is made, so ``create_app`` never touches a database. A store
or site that cannot be opened is a 503 that says so, and the reason (which names the
store's URL or path, the site's folder or URL) goes to the server's log, not to the
caller.

Routers reach these through the dependencies at the bottom (``Depends(engine)``, ...).
"""

from __future__ import annotations

import contextlib
import logging
import threading
from typing import TYPE_CHECKING, Annotated, Any

from fastapi import Depends, Request

from skyroute.errors import SkyrouteError, StoreBusyError
from skyroute.service.problems import Problem
from skyroute.service.settings import Settings

log = logging.getLogger("skyroute.service")

if TYPE_CHECKING:
    import sqlalchemy as sa

    from skyroute.delivery.site import Site
    from skyroute.world.grid import Grid


def make_engine(url: str) -> sa.Engine:
    """The store's engine for ``url``: connected, its schema upgraded to the newest
    migration (as ``deliver`` opens it)."""
    from skyroute.delivery import store

    engine = store.connect(url)
    store.init(engine)
    return engine


class Resources:
    """One app's lazily opened resources (thread-safe: handlers run in a thread pool)."""

    def __init__(self, settings: Settings) -> None:
        self.settings = settings
        self._lock = threading.Lock()
        self._engine = None
        self._site = None
        self._executor = None
        self._grids: dict[str, Grid] = {}
        self.cache: dict[str, object] = {}  # small per-app caches (rendered files)
        self.job_ids: list[str] = []  # jobs this app submitted (the queue limit)

    def engine(self) -> sa.Engine:
        if self._engine is None:
            with self._lock:
                if self._engine is None:
                    try:
                        self._engine = make_engine(self.settings.db_url)
                    except StoreBusyError:
                        raise  # a passing 503 with Retry-After (problems._busy)
                    except SkyrouteError as exc:  # its URL or path stays in the log
                        log.warning("the store cannot be opened: %s", exc)
                        raise Problem(503, "the store cannot be opened; the server's log "
                                      "says why", kind="store-unavailable") from None
        return self._engine

    def site(self) -> Site:
        """The delivery site named by ``data_dir`` or ``source_url`` (404 problem when the
        server was started without one)."""
        if not self.settings.has_site:
            raise Problem(404, "this server has no delivery site; start it with --data DIR "
                          "or --source URL", kind="no-site")
        if self._site is None:
            with self._lock:
                if self._site is None:
                    from skyroute.delivery.site import load_site
                    from skyroute.delivery.source import open_source

                    try:
                        self._site = load_site(open_source(self.settings.data_dir,
                                                           self.settings.source_url))
                    except SkyrouteError as exc:  # its folder or URL stays in the log
                        log.warning("the delivery site cannot be read: %s", exc)
                        raise Problem(503, "the delivery site cannot be read; the "
                                      "server's log says why", kind="site-unavailable"
                                      ) from None
        return self._site

    def grid(self, name: str) -> Grid | None:
        """A bundled map by name, read once (its search workspace is cached with it);
        None when no bundled map has that name."""
        grid = self._grids.get(name)
        if grid is None:
            from skyroute.world.load import bundled_maps
            from skyroute.world.movingai import read_map

            maps = bundled_maps()
            if name not in maps:
                return None
            grid = self._grids.setdefault(name, read_map(maps[name]))
        return grid

    def executor(self):
        """The jobs' executor (local processes or a Dask scheduler), opened once."""
        if self._executor is None:
            with self._lock:
                if self._executor is None:
                    from skyroute.jobs.executor import open_executor

                    s = self.settings
                    self._executor = open_executor(
                        "dask" if s.dask_address else "local", address=s.dask_address,
                        workers=s.job_workers)
        return self._executor

    def close(self) -> None:
        # abort: the jobs' worker processes end with the server. A job still running is
        # left so in the store and failed as an orphan (skyroute.jobs.runner); closed
        # only, the workers ran on after the server had gone (SIGTERM ends it at once,
        # with no exit handlers), each holding the server's stdout and stderr open
        for closer in (getattr(self._executor, "abort", None),
                       getattr(self._engine, "dispose", None)):
            if closer is not None:
                with contextlib.suppress(Exception):  # shutting down: nothing to tell
                    closer()
        self._executor = self._engine = None


async def resources(request: Request) -> Resources:
    """(async: a sync dependency would cost a trip through the thread pool)"""
    return request.app.state.resources


def engine(request: Request) -> sa.Engine:
    return request.app.state.resources.engine()


ResourcesDep = Annotated[Resources, Depends(resources)]
EngineDep = Annotated[Any, Depends(engine)]  # a sqlalchemy Engine, opened on first use
