"""Tell the process that started a server when each of its processes is warm: internal to
``skyroute bench service`` and ``skyroute serve``, not a user feature.

``/health`` answers as soon as one process of ``serve --workers N`` has run its lifespan
(the warm-up, :mod:`skyroute.service.warm`), while the other N - 1 may still be warming
on the same cores; a load measured from then on competes with them. So the bench gives
``serve`` a folder in ``$SKYROUTE_READY_DIR``, each process writes a file named for its
pid there once its lifespan has warmed it, and the bench waits for N of them
(:func:`count_ready`) as well as for ``/health``. Without the variable nothing is written.

Light on purpose: the bench imports it without FastAPI.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

READY_DIR_ENV = "SKYROUTE_READY_DIR"

log = logging.getLogger("skyroute.service")


def mark_ready() -> Path | None:
    """Write this process's pid to ``$SKYROUTE_READY_DIR/<pid>`` (written aside and
    renamed, so a reader never sees half a file); the file, or None when the variable is
    unset or the folder cannot be written (logged: a server never stops for it)."""
    folder = os.environ.get(READY_DIR_ENV)
    if not folder:
        return None
    pid = os.getpid()
    path, part = Path(folder) / str(pid), Path(folder) / f".{pid}.part"
    try:
        part.write_text(f"{pid}\n")
        os.replace(part, path)
    except OSError as exc:
        log.warning("cannot mark this process ready in $%s: %s", READY_DIR_ENV, exc)
        return None
    return path


def count_ready(folder: Path) -> int:
    """How many processes have marked themselves ready in ``folder``."""
    try:
        return sum(1 for p in Path(folder).iterdir() if p.name.isdigit())
    except OSError:
        return 0
