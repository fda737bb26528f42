"""The tautness test that spares contraction work: literal table entries and first steps,
and the lemma it rests on checked against scipy's Dijkstra on the grid: whenever it says
a turn at subgoal v shortens, the grid distance between the two neighbours is strictly
less than the way through v."""

import numpy as np
import pytest
from scipy.sparse.csgraph import dijkstra

from skyroute.bench.random_maps import octile_graph
from skyroute.search.prepared import build_arrays
from skyroute.search.subgoal_landmarks import edge_lengths
from skyroute.search.subgoal_taut import (
    ALWAYS,
    edge_first_steps,
    first_steps,
    free_around,
    shorten_table,
)

E, NE, N, W, SW, SE = 1, 2, 4, 16, 32, 128
TABLE = shorten_table()


def test_table_entries():
    assert TABLE[E, E] & ALWAYS  # back where it came from
    assert TABLE[E, NE] & ALWAYS  # 45 degrees: a cardinal step between
    assert TABLE[E, N] == NE  # 90 degrees, cardinal: only if the corner cell is free
    assert TABLE[NE, SE] == E  # 90 degrees, diagonal: through the cardinal cell
    assert TABLE[E, W] == 0 and TABLE[E, SW] == 0 and TABLE[NE, W] == 0  # kept
    assert TABLE[E | NE, W | SW] == 0
    assert TABLE[E | NE, N] == NE | ALWAYS  # NE and N are 45 degrees apart


def _padded(rows):
    blocked = np.array([[c == "@" for c in r] for r in rows])
    padded = np.ones((blocked.shape[0] + 2, blocked.shape[1] + 2), np.uint8)
    padded[1:-1, 1:-1] = blocked
    return padded.ravel(), blocked.shape[1] + 2


def test_first_steps_of_both_walks():
    blk, Wp = _padded(["....", "....", "...."])
    a, b = Wp + 1, 2 * Wp + 4  # (0, 0) to (3, 1)
    assert first_steps(blk, Wp, a, b) == NE | E  # diagonal first from a; from b: ends E
    blk, Wp = _padded(["....", ".@..", "...."])
    assert first_steps(blk, Wp, a, b) == E  # (1, 1) blocked: only the walk from b
    blk, Wp = _padded(["..@.", ".@..", "...."])
    assert first_steps(blk, Wp, a, b) == 0  # neither walk: the test then keeps the turn


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("share", [0.1, 0.2, 0.35])
def test_a_turn_said_to_shorten_is_strictly_longer_than_the_grid_distance(seed, share):
    rng = np.random.default_rng(seed)
    blocked = rng.random((24, 24)) < share
    h, w = blocked.shape
    Wp = w + 2
    padded = np.ones((h + 2, w + 2), np.uint8)
    padded[1:-1, 1:-1] = blocked
    blk = padded.ravel()
    arrays = build_arrays(blocked)
    cells, offs, nbr = arrays["cells"], arrays["offs"], arrays["nbr"]
    length = edge_lengths(cells, offs, nbr, Wp)
    fwd, _ = edge_first_steps(blk, Wp, cells, offs, nbr)
    free = free_around(cells, blk, Wp)
    grid_ids = (cells // Wp - 1) * w + cells % Wp - 1
    dist = dijkstra(octile_graph(blocked), directed=False, indices=grid_ids)[:, grid_ids]
    pruned = kept = 0
    for v in range(cells.size):
        for i in range(offs[v], offs[v + 1]):
            assert fwd[i]  # every edge has a walk: h-reachable
            for j in range(i + 1, offs[v + 1]):
                x, y = nbr[i], nbr[j]
                via = length[i] + length[j]
                if TABLE[fwd[i], fwd[j]] & free[v]:
                    pruned += 1
                    assert dist[x, y] < via - 1e-9, (v, x, y)
                else:
                    kept += 1
    assert pruned > 0 and kept > 0
