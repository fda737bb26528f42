"""A full disk (or another file system error) at the k-th rename of a staged file into
place, for the tests of :func:`skyroute.files.written_together` and what uses it."""

from __future__ import annotations

import os

import skyroute.files as files


def failing_rename(monkeypatch, at: int, *, errno: int = 28,
                   message: str = "No space left on device") -> None:
    """The ``at``-th rename of a staged (``.tmp``) file into place, from 1, raises
    ``OSError(errno, message)``; other renames, and those before and after, go through."""
    real, renames = os.replace, []

    def replace(src, dst):
        if str(src).endswith(".tmp"):
            renames.append(dst)
            if len(renames) == at:
                raise OSError(errno, message)
        return real(src, dst)

    monkeypatch.setattr(files.os, "replace", replace)


def earlier_versions(here, existed) -> dict[str, str]:
    """Files ``f0``, ``f1``, ... of ``here`` with an earlier version where ``existed[k]``
    ("old k"), written now; {name: text} of them, what a failed block must leave."""
    before = {}
    for k, old in enumerate(existed):
        if old:
            (here / f"f{k}").write_text(f"old {k}")
            before[f"f{k}"] = f"old {k}"
    return before
