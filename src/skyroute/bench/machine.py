"""What a benchmark ran on, for its JSON report: two runs are only comparable (and one
only reproducible) with the versions, the CPU and the date beside the numbers."""

from __future__ import annotations

import datetime
import os
import platform
from collections.abc import Sequence
from importlib import metadata

from skyroute.version import __version__

# What every bench's numbers depend on; each command adds its peers.
BASE = ("numpy", "numba", "scipy", "shapely")


def machine(packages: Sequence[str] = ()) -> dict:
    """skyroute's version, Python's, each of :data:`BASE` and ``packages`` (their
    distribution names; None where not installed), the CPU model, its core count, the
    OS and the time of the run (UTC, ISO 8601)."""
    versions = {}
    for name in dict.fromkeys((*BASE, *packages)):
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = None
    return {"skyroute": __version__,
            "python": platform.python_version(),
            "packages": versions,
            "cpu": cpu_model(),
            "cores": os.cpu_count(),
            "os": platform.platform(),
            "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")}


def cpu_model() -> str:
    """The CPU's model name from /proc/cpuinfo (Linux); elsewhere what ``platform``
    knows ("x86_64" at least)."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                key, _, value = line.partition(":")
                if key.strip() in ("model name", "Hardware", "Processor") and value.strip():
                    return value.strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()
