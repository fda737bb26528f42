"""Peak memory of a prepared-map build (issue 13's "<= 128 MB for a 512x512 map"),
measured by ``skyroute bench grid --prepared`` in a fresh Python process, so that
nothing the bench itself holds is counted.

The child loads the blocked cells and builds the index once, which loads its compiled
kernels, and drops it. Then it resets the kernel's record of its peak resident memory
(``/proc/self/clear_refs``, Linux 4.0 and later), builds the index again and reads the
record back (``VmHWM``): the figure is the most resident memory the second build added
over the process before it (the index, its scratch, the subgoal graph's and the
contraction's temporary arrays). So that glibc's malloc cannot hide part of the second
build in blocks the first one freed and it kept for reuse, the child runs with fixed mmap
and trim thresholds, which hand freed blocks back to the system at once (on this
project's machines the figures came out within a few per cent without them).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

_MALLOC = {"MALLOC_MMAP_THRESHOLD_": "65536", "MALLOC_TRIM_THRESHOLD_": "65536"}


def build_peak_bytes(blocked: np.ndarray, method: str = "auto") -> int | None:
    """Resident bytes that ``prepare(Grid(blocked), method=method)`` adds at its peak,
    measured in a child process; None where the system keeps no resettable peak."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "blocked.npy"
        np.save(path, np.asarray(blocked, dtype=bool))
        proc = subprocess.run([sys.executable, "-m", __name__, str(path), method],
                              capture_output=True, text=True, env={**os.environ, **_MALLOC})
    if proc.returncode != 0:
        last = (proc.stderr.strip().splitlines() or ["no output"])[-1]
        raise RuntimeError(f"build memory: the measuring process failed: {last}")
    return json.loads(proc.stdout.strip().splitlines()[-1])["peak_bytes"]  # the last line


def _status_kb(field: str) -> int:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(field + ":"):
                return int(line.split()[1])
    raise OSError(f"/proc/self/status has no {field}")


def _measure(path: str, method: str) -> int | None:
    import gc

    from skyroute.search.prepared import prepare
    from skyroute.world.grid import Grid

    grid = Grid(np.load(path))
    prepare(grid, method=method)  # loads (on a cold cache: compiles) the kernels
    gc.collect()
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")  # the peak resident set is now the current one
        before = _status_kb("VmRSS")
    except OSError:
        return None
    index = prepare(grid, method=method)
    peak = _status_kb("VmHWM")
    del index
    return (peak - before) * 1024


if __name__ == "__main__":
    print(json.dumps({"peak_bytes": _measure(sys.argv[1], sys.argv[2])}))
