"""An indexed binary min-heap over flat cell indices, compiled with numba.

One int64 key per entry packs ``f`` (in units of 2**-20, so float noise in g + h never
breaks ties) above a tie-break that prefers the larger ``g`` (in quarter cells): among
equally promising nodes the one nearest the goal is expanded first, which on open grids
cuts expansions several-fold. f must stay below 2**23 (8 million cells of path).

The heap shares the searches' per-cell ``state`` array: ``state[c] = i + 1`` while c sits
in heap slot i, so improving a node is a decrease-key, not a duplicate entry; 0 means
never seen and -1 closed (``pop`` closes what it returns). Sifting moves a hole, writing
each level once.
"""

from __future__ import annotations

from numba import njit

F_SCALE = 1048576.0  # 2**20
TIE_BITS = 20
TIE_MAX = (1 << TIE_BITS) - 1
CLOSED = -1


@njit(cache=True)
def key(f, g):
    """Pack f and the g tie-break into one comparable int64."""
    tie = TIE_MAX - min(int(g * 4.0), TIE_MAX)
    return (int(f * F_SCALE + 0.5) << TIE_BITS) | tie


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
            moved = hc[p]
            hc[i] = moved
            hk[i] = kp
            state[moved] = i + 1
            i = p
        else:
            break
    hc[i] = cell
    hk[i] = k
    state[cell] = i + 1
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
                moved = hc[b]
                hc[i] = moved
                hk[i] = hk[b]
                state[moved] = i + 1
                i = b
            else:
                break
        hc[i] = last
        hk[i] = lk
        state[last] = i + 1
    return int(top), size


@njit(cache=True)
def reset(state, touched, count):
    """Return ``state`` to all zeros by clearing the ``count`` cells a search touched."""
    for j in range(count):
        state[touched[j]] = 0
