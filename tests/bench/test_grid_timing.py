"""What `bench grid` times (the runner's own call, not the bench's reading of its answer)
and what it counts as matched (a legal path whose re-measured length is the optimum)."""

import dataclasses

import numpy as np
import pytest

from skyroute.bench import grid as bench_grid
from skyroute.bench import peers
from skyroute.bench.random_maps import far_queries, random_grid
from skyroute.world.grid import Grid
from skyroute.world.movingai import read_scen


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


# 5x5, one wall cell at (2, 2); the query (0, 2) -> (4, 2) has the octile optimum 2 + 2 sqrt 2,
# and (0, 2) (1, 2) (2, 1) (3, 1) (4, 2) has that length too but cuts the wall's corner.
WALL = np.zeros((5, 5), dtype=bool)
WALL[2, 2] = True
OPT = 2 + 2 * np.sqrt(2)
CORNER_CUT = np.array([(0, 2), (1, 2), (2, 1), (3, 1), (4, 2)])


def wall_case(tmp_path):
    scen = tmp_path / "wall.map.scen"
    scen.write_text(f"version 1\n0\twall.map\t5\t5\t0\t2\t4\t2\t{OPT:.8f}\n")
    return Grid(WALL, name="wall"), read_scen(scen)


def fake_peer(monkeypatch, path):
    fake = peers.Peer("fake", "numpy", "test peer", lambda g: lambda s, t: path, np.asarray)
    monkeypatch.setitem(peers.PEERS, "fake", fake)


def test_peer_path_that_cuts_a_corner_is_invalid_not_matched(monkeypatch, tmp_path):
    grid, scen = wall_case(tmp_path)
    fake_peer(monkeypatch, CORNER_CUT)
    row, = bench_grid.bench_queries(grid, scen, "wall", per_map=0, algorithms=[],
                                    peers=["fake"], seed=0)["rows"]
    assert row["max_cost_ratio"] == pytest.approx(1.0)  # the optimal length ...
    assert (row["matched"], row["invalid"]) == (0, 1)  # ... on a path the problem forbids


def test_peer_longer_legal_path_is_not_matched(monkeypatch, tmp_path):
    grid, scen = wall_case(tmp_path)
    fake_peer(monkeypatch, [(0, 2), (0, 1), (1, 0), (2, 0), (3, 1), (4, 2)])
    row, = bench_grid.bench_queries(grid, scen, "wall", per_map=0, algorithms=[],
                                    peers=["fake"], seed=0)["rows"]
    assert (row["matched"], row["invalid"]) == (0, 0)
    assert row["max_cost_ratio"] == pytest.approx((3 * np.sqrt(2) + 2) / OPT)


@pytest.mark.parametrize("algorithm", ["astar", "theta"])
def test_our_detour_with_the_optimal_cost_claimed_is_not_matched(monkeypatch, tmp_path,
                                                                 algorithm):
    """The path is checked, not the runner's own cost: a planner whose path is one step
    there and back longer while its cost still says optimal is counted invalid."""
    grid, scen = wall_case(tmp_path)
    real = bench_grid.plan

    def detour(g, s, t, **kw):
        r = real(g, s, t, **kw)
        back = np.vstack([r.path[:1], [[0, 3]], r.path])  # (0, 2) -> (0, 3) -> (0, 2) -> ...
        return dataclasses.replace(r, path=back)

    monkeypatch.setattr(bench_grid, "plan", detour)
    row, = bench_grid.bench_queries(grid, scen, "wall", per_map=0, algorithms=[algorithm],
                                    peers=[], seed=0)["rows"]
    assert (row["matched"], row["invalid"]) == (0, 1)
    assert row["max_cost_ratio"] > 1  # the path's own length, not the claimed cost


def test_our_honest_answers_are_matched_and_legal(tmp_path):
    grid, scen = wall_case(tmp_path)
    rows = bench_grid.bench_queries(grid, scen, "wall", per_map=0,
                                    algorithms=["astar", "jps", "dijkstra", "theta"],
                                    peers=[], seed=0, prepared=True)["rows"]
    got = {r["runner"]: (r["matched"], r["invalid"]) for r in rows}
    # Theta* is shorter than the octile optimum (any angle): legal, not matched
    assert got == {"astar": (1, 0), "jps": (1, 0), "dijkstra": (1, 0), "theta": (0, 0),
                   "prepared": (1, 0)}
