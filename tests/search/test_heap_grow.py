"""The growable arrays of the compiled searches keep every entry they held."""

import numpy as np

from skyroute.search import heap


def test_grow_keeps_entries_and_grows_at_least_to_n():
    a = np.arange(5, dtype=np.int32)
    assert heap.grow(a, 5) is a
    b = heap.grow(a, 7)
    assert b.dtype == a.dtype and b.shape[0] == 10 and b[:5].tolist() == a.tolist()
    assert heap.grow(a, 23).shape[0] == 23
    z = heap.grow_zeroed(np.ones(3, np.bool_), 4)
    assert z.tolist() == [True, True, True, False, False, False]


def test_grow_rows_keeps_every_row():
    a = np.arange(12, dtype=np.float64).reshape(3, 4)
    assert heap.grow_rows(a, 4) is a
    b = heap.grow_rows(a, 5)
    assert b.shape == (3, 8) and np.array_equal(b[:, :4], a)
    assert heap.grow_rows(a, 17).shape == (3, 17)
