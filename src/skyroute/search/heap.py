"""An indexed binary min-heap over flat cell indices, compiled with numba.

One int64 key per entry packs ``f`` (in units of 2**-20, so float noise in g + h never
breaks ties) above a tie-break that prefers the larger ``g`` (in quarter cells): among
equally promising nodes the one nearest the goal is expanded first, which on open grids
cuts expansions several-fold. f's unit is a search's argument ``fs`` (f is stored as
``int(f * fs + 0.5)``): :func:`f_scale` of an upper bound on every f the search can
meet, which is ``F_SCALE`` (2**20, as before) while that bound stays below 2**23 (8
million cells of path: every map the tests and benchmarks use) and the largest power of
two that fits the key's 43 bits above (2**15 to 2**16 on 8192x8192 grids: f rounded to
some 3e-5 there, as to 1e-6 before). A search whose f would need units coarser than 1
is refused before it starts (an absurd ``weight``). Before, the shift wrapped past
f = 2**23 and a long search popped keys out of f order. (The unit, not the tie-break's
width, is the argument: a shift by a variable cost the A* kernel 3-4% on random 512
maps, a variable multiplier nothing measurable.)

The heap shares the searches' per-cell ``state`` array: ``state[c] = i + 1`` while c sits
in heap slot i, so improving a node is a decrease-key, not a duplicate entry; 0 means
never seen and -1 closed (``pop`` closes what it returns). Sifting moves a hole, writing
each level once.

The A* and JPS kernels write out a 4-ary form of this heap in their loops (children of
slot i at 4i+1..4i+4, parent (i-1) >> 2: half the levels per pop), because numba
wraps every call that takes an array in atomic reference-count updates
(docs/architecture.md); the same keys and the same ``state`` convention. (Pop and
sift-up as ``inline="always"`` functions shared by both kernels ran 10-25% slower on
random 512x512 maps, CPU time, 2026-11-23, so the copies stay.)
"""

from __future__ import annotations

import numpy as np
from numba import njit

from skyroute.result import NO_PATH

F_SCALE = 1048576.0  # 2**20: f's finest unit, a search's whenever its keys allow
TIE_BITS = 20
TIE_MAX = (1 << TIE_BITS) - 1
F_BITS = 63 - TIE_BITS  # a key is a nonnegative int64: f takes the 43 bits above the tie
CLOSED = -1


def f_scale(f_max: float) -> float:
    """The unit ``fs`` of the keys of a search whose every f is at most ``f_max``:
    ``F_SCALE`` when ``int(f_max * F_SCALE + 0.5)`` fits in ``F_BITS`` bits, else the
    largest power of two that fits; 0.0 when not even 1 would (or ``f_max`` is not
    finite). ``F_SCALE`` is read at each call, so a test may raise it to bring the f
    limit down to a small grid's."""
    fs = F_SCALE
    if not f_max < 2.0 ** F_BITS:  # NaN and inf too
        return 0.0
    while fs >= 1.0 and int(f_max * fs + 0.5) >> F_BITS:  # as the kernels round
        fs /= 2.0
    return fs if fs >= 1.0 else 0.0


@njit(cache=True)
def key(f, g, fs):
    """Pack f (in units of 1 / ``fs``, from :func:`f_scale`) and the g tie-break into
    one comparable int64."""
    tie = TIE_MAX - min(int(g * 4.0), TIE_MAX)
    return (int(f * fs + 0.5) << TIE_BITS) | tie


@njit(cache=True, inline="always")
def _put(hc, hk, state, i, cell, k):
    """Write ``cell`` with key ``k`` into heap slot i and note the slot in ``state``."""
    hc[i] = cell
    hk[i] = k
    state[cell] = i + 1


@njit(cache=True)
def push(hc, hk, state, size, cell, k):
    """Insert ``cell`` with key ``k`` (or lower its key if present); return the new size."""
    i = state[cell] - 1
    if i < 0:
        i = size
        size += 1
    while i > 0:
        p = (i - 1) >> 1
        kp = hk[p]
        if k < kp:
            _put(hc, hk, state, i, hc[p], kp)
            i = p
        else:
            break
    _put(hc, hk, state, i, cell, k)
    return size


@njit(cache=True)
def pop(hc, hk, state, size):
    """Remove the minimum and mark it closed; return (cell, new size)."""
    top = hc[0]
    state[top] = CLOSED
    size -= 1
    if size > 0:
        last = hc[size]
        lk = hk[size]
        i = 0
        while True:
            b = 2 * i + 1
            if b >= size:
                break
            r = b + 1
            if r < size and hk[r] < hk[b]:
                b = r
            if hk[b] < lk:
                _put(hc, hk, state, i, hc[b], hk[b])
                i = b
            else:
                break
        _put(hc, hk, state, i, last, lk)
    return int(top), size


@njit(cache=True)
def reset(state, touched, count):
    """Return ``state`` to all zeros by clearing the ``count`` cells a search touched."""
    for j in range(count):
        state[touched[j]] = 0


@njit(cache=True)
def finish(code, state, touched, count):
    """A kernel's last step: clear the cells it touched, and turn "still searching" (a
    negative code: the open list ran dry) into NO_PATH."""
    reset(state, touched, count)
    return NO_PATH if code < 0 else code


@njit(cache=True)
def push_plain(hk, hn, size, k, node):
    """Insert ``node`` with key ``k`` into a plain heap of ``size`` entries (no index: a
    node may sit in it several times, for searches that re-queue instead of
    decreasing a key)."""
    i = size
    while i > 0:
        p = (i - 1) >> 1
        if k < hk[p]:
            hk[i] = hk[p]
            hn[i] = hn[p]
            i = p
        else:
            break
    hk[i] = k
    hn[i] = node


@njit(cache=True)
def pop_plain(hk, hn, size):
    """Remove the minimum of a plain heap of ``size`` entries; return its node."""
    top = hn[0]
    size -= 1
    if size > 0:
        hk[0], hn[0] = hk[size], hn[size]
        sift_down(hk, hn, 0, size)
    return top


@njit(cache=True, inline="always")
def sift_down(hk, hn, i, size):
    """Restore the min-heap on ``hk[:size]`` (``hn`` alongside) below slot ``i``: a pop's
    second half, and with ``i`` from ``size // 2 - 1`` down to 0 a heapify."""
    k, node = hk[i], hn[i]
    while True:
        b = 2 * i + 1
        if b >= size:
            break
        if b + 1 < size and hk[b + 1] < hk[b]:
            b += 1
        if not hk[b] < k:
            break
        hk[i] = hk[b]
        hn[i] = hn[b]
        i = b
    hk[i] = k
    hn[i] = node


@njit(cache=True)
def grow(a, n):
    """``a`` itself when it holds at least ``n`` entries, else a copy twice as long (or
    ``n`` long): growable arrays for searches that cannot size them in advance."""
    if n <= a.shape[0]:
        return a
    b = np.empty(max(2 * a.shape[0], n), a.dtype)
    _copy_into(b, a)
    return b


@njit(cache=True)
def grow_zeroed(a, n):
    """:func:`grow`, with the new entries zero (False): flags of nodes not seen yet."""
    if n <= a.shape[0]:
        return a
    b = np.zeros(max(2 * a.shape[0], n), a.dtype)
    _copy_into(b, a)
    return b


@njit(cache=True)
def grow_rows(a, n):
    """:func:`grow` for each row of a (rows, k) array: ``a`` when a row holds at least
    ``n`` entries, else a copy whose rows are twice as long (or ``n``)."""
    if n <= a.shape[1]:
        return a
    b = np.empty((a.shape[0], max(2 * a.shape[1], n)), a.dtype)
    for r in range(a.shape[0]):
        _copy_into(b[r], a[r])
    return b


@njit(cache=True, inline="always")
def _copy_into(b, a):
    """b[:len(a)] = a as a loop: numba's slice assignment checks shapes with an error
    message built from them, and compiling that formatting costs seconds the first time
    in a process (docs/benchmarks.md section 3)."""
    for i in range(a.shape[0]):
        b[i] = a[i]


@njit(cache=True, inline="always")
def indexed_up(hk, hn, pos, i, k, v):
    """Indexed binary heap (float keys ``hk``, nodes ``hn``, each node's slot in ``pos``):
    move entry (k, v), to be written at slot i, up to its place."""
    while i > 0:
        p = (i - 1) >> 1
        if hk[p] <= k:
            break
        hk[i], hn[i] = hk[p], hn[p]
        pos[hn[i]] = i
        i = p
    hk[i], hn[i] = k, v
    pos[v] = i


@njit(cache=True, inline="always")
def indexed_pop(hk, hn, pos, size):
    """Remove the first entry of an indexed heap (see :func:`indexed_up`); return (its
    node, the new size). The removed node's ``pos`` is left for the caller."""
    top = hn[0]
    size -= 1
    if size > 0:
        k, v = hk[size], hn[size]
        i = 0
        while True:
            b = 2 * i + 1
            if b >= size:
                break
            if b + 1 < size and hk[b + 1] < hk[b]:
                b += 1
            if hk[b] >= k:
                break
            hk[i], hn[i] = hk[b], hn[b]
            pos[hn[i]] = i
            i = b
        hk[i], hn[i] = k, v
        pos[v] = i
    return top, size
