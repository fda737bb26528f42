"""A Dask worker plugin making chosen days or fleet runs fail in each worker of a
cluster (see tests/jobs/failing.py for the kinds); apart from failing.py so that the
local pool's spawned workers, which import that module, need not import Dask."""

from __future__ import annotations

from distributed import WorkerPlugin

from tests.jobs.failing import fail_in_workers


class FailingDaskWorkers(WorkerPlugin):
    """A Dask worker plugin doing what :func:`fail_in_workers` does in each worker of a
    cluster, also in one its nanny starts again after a death (register it with
    ``client.register_plugin``)."""

    name = "skyroute-failing-days"

    def __init__(self, kinds: dict[str, str], marks: str | None = None) -> None:
        self.kinds, self.marks = kinds, marks

    def setup(self, worker) -> None:
        fail_in_workers(self.kinds, self.marks)

    def teardown(self, worker) -> None:
        pass
