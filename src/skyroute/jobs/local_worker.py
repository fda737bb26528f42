"""The start of each worker of the in-process Dask cluster (``--executor dask``), named
to the ``LocalCluster`` as a Dask preload: its ``dask_setup`` runs in each worker process
as it starts.

Its worker processes share the terminal's process group, so a Ctrl-C reached each of
them: each printed a ``KeyboardInterrupt`` traceback of some 30 lines over the command's
"skyroute: interrupted", and its nanny started it again. They ignore SIGINT, as the local
pool's workers do; the command that owns the cluster decides what their tasks become and
closes it (:meth:`skyroute.jobs.executor.DaskExecutor.abort`), which ends them.
"""

from __future__ import annotations

import signal
import threading


def dask_setup(worker) -> None:
    """Ignore SIGINT in this worker process (Dask calls this with the worker)."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
