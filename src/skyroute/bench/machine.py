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


def cpu_model(cpuinfo: str | None = None) -> str:
    """The CPU's model name from /proc/cpuinfo (Linux; ``cpuinfo``: that file's text),
    with its family and model numbers where given: a VM's name is often only the vendor's
    ("AMD EPYC"), which two CPU generations share. Elsewhere what ``platform`` knows
    ("x86_64" at least)."""
    if cpuinfo is None:
        try:
            with open("/proc/cpuinfo", encoding="utf-8") as f:
                cpuinfo = f.read()
        except OSError:
            cpuinfo = ""
    fields: dict[str, str] = {}
    for line in cpuinfo.splitlines():
        key, _, value = line.partition(":")
        key, value = key.strip(), value.strip()
        if not key and fields:
            break  # the first processor's block is enough
        if value:
            fields.setdefault(key, value)
    name = next((v for k, v in fields.items() if k in ("model name", "Hardware", "Processor")),
                None)
    if name is None:
        return platform.processor() or platform.machine()
    if "cpu family" in fields and "model" in fields:
        return f"{name} (family {fields['cpu family']}, model {fields['model']})"
    return name
