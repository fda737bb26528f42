"""Long work as independent tasks on a local process pool or a Dask cluster.

- :mod:`~skyroute.jobs.executor`: ``open_executor("local" | "dask", address=, workers=)``,
  one ``map`` for both.
- :mod:`~skyroute.jobs.store`: the ``jobs``, ``fleet_runs`` and ``servers`` tables (in
  the delivery store, migrations 0002 and 0003).
- :mod:`~skyroute.jobs.deliver`: a range of delivery days, one task per day, each stored
  by the caller in one transaction as it arrives.
- :mod:`~skyroute.jobs.local_worker`: the start of each worker of the in-process Dask
  cluster (it leaves Ctrl-C to the command).
- :mod:`~skyroute.jobs.fleet`: fleet runs (stored in ``fleet_runs``) and sweeps.
- :mod:`~skyroute.jobs.runner`: ``submit`` / ``get``: jobs in a background thread with
  their state and progress in the store (what the service calls).

See docs/scaling.md for running on a cluster.
"""

from skyroute.lazy import exports as _exports

__getattr__, __dir__ = _exports(__name__)  # its modules, imported when first asked for
