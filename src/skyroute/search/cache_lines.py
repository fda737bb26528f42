"""Cache lines for compiled kernels: a prefetch hint, and arrays whose rows start on a line.

numba has no prefetch of its own: :func:`prefetch_row` emits LLVM's ``llvm.prefetch``.
JPS reads each new jump point's state and g (2 MB arrays each on a 512x512 map) and, in
a prepared "jump" index, its row of pivot distances (128 bytes of a 34 MB table: almost
always a cache miss); asking for all of an expansion's jump points before relaxing them
lets those misses overlap instead of stalling one after another (docs/benchmarks.md
section 12, round 8). numpy places a large array's data 16 bytes past a page boundary,
so each 128-byte row of pivot distances would straddle three lines; :func:`line_aligned`
makes it two.
"""

from __future__ import annotations

import numpy as np
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

LINE = 64  # bytes per cache line on the x86-64 and arm64 machines skyroute runs on


@intrinsic
def prefetch_row(typingctx, arr, row):
    """Hint that item ``row`` of a 1-D array (its cache line), or row ``row`` of a 2-D
    array (its first two lines), will be read soon. No effect on results: a prefetch
    never faults, even for an address outside the array."""
    if not (isinstance(arr, types.Array) and arr.ndim in (1, 2)
            and isinstance(row, types.Integer)):
        return None
    offsets = (0,) if arr.ndim == 1 else (0, LINE)

    def codegen(context, builder, sig, args):
        ary = context.make_array(sig.args[0])(context, builder, args[0])
        stride = cgutils.unpack_tuple(builder, ary.strides, sig.args[0].ndim)[0]
        r = context.cast(builder, args[1], sig.args[1], types.intp)
        i64, i32 = ir.IntType(64), ir.IntType(32)
        addr = builder.add(builder.ptrtoint(ary.data, i64), builder.mul(r, stride))
        ptr = ir.PointerType(ir.IntType(8))
        fn = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(ir.VoidType(), [ptr, i32, i32, i32]),
            "llvm.prefetch.p0")
        read, keep, data = ir.Constant(i32, 0), ir.Constant(i32, 3), ir.Constant(i32, 1)
        for off in offsets:
            p = builder.inttoptr(builder.add(addr, ir.Constant(i64, off)), ptr)
            builder.call(fn, [p, read, keep, data])
        return context.get_dummy_value()

    return types.none(arr, row), codegen


def aligned_empty(shape, dtype=np.float64) -> np.ndarray:
    """An uninitialised C-contiguous array whose data starts on a cache line."""
    dtype = np.dtype(dtype)
    nbytes = int(np.prod(shape)) * dtype.itemsize
    buf = np.empty(nbytes + LINE, np.uint8)
    start = -buf.ctypes.data % LINE
    return buf[start:start + nbytes].view(dtype).reshape(shape)


def line_aligned(a: np.ndarray) -> np.ndarray:
    """``a`` itself when it is C-contiguous with its data on a cache line, else such a
    copy (same shape, dtype and values)."""
    if a.ctypes.data % LINE == 0 and a.flags.c_contiguous:
        return a
    out = aligned_empty(a.shape, a.dtype)
    out[...] = a
    return out
