"""What `bench grid` times: the runner's own call, not the bench's reading of its answer."""

import numpy as np
import pytest

from skyroute.bench import grid as bench_grid
from skyroute.bench import peers
from skyroute.bench.random_maps import far_queries, random_grid


class FakeClock:
    """perf_counter stand-in that advances only when a fake runner says it worked."""

    def __init__(self):
        self.now = 0.0

    def __call__(self):
        return self.now


def test_peer_time_is_its_query_alone(monkeypatch):
    clock = FakeClock()
    monkeypatch.setattr(bench_grid.time, "perf_counter", clock)
    grid = random_grid(48, 0.1, seed=2)
    scen = far_queries(grid, 3, seed=2)

    def prepare(g):
        def query(s, t):  # the peer's own work: 1 ms on the fake clock
            clock.now += 1e-3
            return (s, t)
        return query

    def cells(answer):  # reading the answer (the bench's work): 100 ms on the fake clock
        clock.now += 0.1
        s, t = answer
        for a, b in zip(scen.starts, scen.goals, strict=True):
            if tuple(a.tolist()) == s and tuple(b.tolist()) == t:
                ref = bench_grid.plan(grid, s, t)
                return np.asarray(ref.path)
        raise AssertionError("unknown query")

    fake = peers.Peer("fake", "numpy", "test peer", prepare, cells)
    monkeypatch.setitem(peers.PEERS, "fake", fake)
    report = bench_grid.bench_queries(grid, scen, "fake-run", per_map=0, algorithms=[],
                                      peers=["fake"], seed=0)
    row, = report["rows"]
    assert row["median_ms"] == pytest.approx(1.0)  # the query's 1 ms, none of the 100 ms after it
    assert row["matched"] == 3  # and its answer was still read and checked
