"""Deprecated location of :mod:`skyroute.files` (kept for one release)."""

from skyroute.files import write_atomic  # noqa: F401
