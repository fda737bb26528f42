"""The prefetch hint: compiles for 1-D and 2-D arrays, changes nothing, refuses others."""

import numpy as np
import pytest
from numba import njit
from numba.core.errors import TypingError

from skyroute.search.cache_lines import LINE, aligned_empty, line_aligned, prefetch_row


@njit
def _sum_after_prefetch(a, idx):
    s = 0.0
    for i in idx:
        prefetch_row(a, i)
    for i in idx:
        s += a.ravel()[i % a.size]
    return s


@pytest.mark.parametrize("shape", [(1000,), (250, 4), (50, 16)])
def test_prefetch_leaves_results_alone_even_outside_the_array(shape):
    rng = np.random.default_rng(0)
    a = rng.random(shape)
    # rows past the end and negative ones: a prefetch never faults
    idx = np.concatenate([rng.integers(0, shape[0], 50), [shape[0] + 10**6, -5]])
    expected = sum(a.ravel()[i % a.size] for i in idx)
    assert _sum_after_prefetch(a, idx) == pytest.approx(expected, rel=1e-12)


def test_prefetch_is_compiled_to_a_prefetch_instruction():
    # the hint must survive to the machine code (an intrinsic LLVM dropped or misnamed
    # would leave the kernels as slow as before, with every result still right)
    _sum_after_prefetch(np.zeros((4, 16)), np.arange(4))
    asm = _sum_after_prefetch.inspect_asm(_sum_after_prefetch.signatures[0])
    # the instructions themselves (x86-64 prefetcht0, arm64 prfm), not the symbol names
    ops = [line.split()[0] for line in asm.splitlines() if line.strip()]
    assert any(op.startswith("prefetch") or op == "prfm" for op in ops)


def test_prefetch_refuses_a_three_dimensional_array():
    @njit
    def bad(a):
        prefetch_row(a, 0)

    with pytest.raises(TypingError):
        bad(np.zeros((2, 2, 2)))


@pytest.mark.parametrize("dtype", [np.float64, np.int32, np.uint8])
def test_line_aligned_copies_onto_a_cache_line(dtype):
    a = (np.arange(5000 * 16) % 251).astype(dtype).reshape(5000, 16)
    b = line_aligned(a)
    assert b.ctypes.data % LINE == 0 and b.flags.c_contiguous
    assert b.shape == a.shape and b.dtype == a.dtype and np.array_equal(a, b)
    assert line_aligned(b) is b  # already aligned: no copy
    odd = np.frombuffer(np.zeros(8 * 100 + 8, np.uint8)[8:].tobytes(), np.float64)
    assert line_aligned(odd[1:]).ctypes.data % LINE == 0


def test_a_jump_index_keeps_its_pivot_rows_on_cache_lines(tmp_path):
    from skyroute.bench.random_maps import random_grid
    from skyroute.search.prepared import load_index, prepare

    grid = random_grid(64, 0.2, 0)
    built = prepare(grid, method="jump")
    assert built._arrays["piv"].ctypes.data % LINE == 0  # built aligned: no copy
    loaded = load_index(built.save(tmp_path / "g.idx"), grid)
    piv = loaded._arrays["piv"]
    assert piv.ctypes.data % LINE == 0 and np.array_equal(piv, built._arrays["piv"])
    free = np.argwhere(~grid.blocked)[:, ::-1].tolist()  # (x, y) cells
    for s, t in zip(free[:20], free[::-1][:20], strict=True):
        assert loaded.plan(tuple(s), tuple(t)).cost == built.plan(tuple(s), tuple(t)).cost


def test_aligned_empty_has_the_shape_and_type_asked_for():
    a = aligned_empty((7, 3), np.int32)
    assert a.shape == (7, 3) and a.dtype == np.int32 and a.flags.c_contiguous
    assert a.ctypes.data % LINE == 0
