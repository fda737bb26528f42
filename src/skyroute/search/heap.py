"""An indexed binary min-heap over flat cell indices, compiled with numba.

Keys are ``f`` quantised to 2**-20 (so float noise in g + h never breaks ties) with
ties broken towards the larger ``g``: among equally promising nodes the one nearest the
goal is expanded first, which on open grids cuts expansions several-fold. ``pos[c]``
holds the cell's heap slot (-1 when not in the heap), so improving a node is a
decrease-key, not a duplicate entry. Sifting moves a hole, writing each level once.
"""

from __future__ import annotations

from numba import njit

KEY_SCALE = 1048576.0  # 2**20


@njit(cache=True)
def push(hc, hk, hg, pos, size, cell, f, g):
    """Insert ``cell`` (or lower its key if present); return the new size."""
    key = int(f * KEY_SCALE + 0.5)
    i = pos[cell]
    if i < 0:
        i = size
        size += 1
    while i > 0:
        p = (i - 1) >> 1
        kp = hk[p]
        if key < kp or (key == kp and g > hg[p]):
            moved = hc[p]
            hc[i] = moved
            hk[i] = kp
            hg[i] = hg[p]
            pos[moved] = i
            i = p
        else:
            break
    hc[i] = cell
    hk[i] = key
    hg[i] = g
    pos[cell] = i
    return size


@njit(cache=True)
def pop(hc, hk, hg, pos, size):
    """Remove the minimum; return (cell, new size)."""
    top = hc[0]
    pos[top] = -1
    size -= 1
    if size > 0:
        last = hc[size]
        lk = hk[size]
        lg = hg[size]
        i = 0
        while True:
            b = 2 * i + 1
            if b >= size:
                break
            r = b + 1
            if r < size and (hk[r] < hk[b] or (hk[r] == hk[b] and hg[r] > hg[b])):
                b = r
            if hk[b] < lk or (hk[b] == lk and hg[b] > lg):
                moved = hc[b]
                hc[i] = moved
                hk[i] = hk[b]
                hg[i] = hg[b]
                pos[moved] = i
                i = b
            else:
                break
        hc[i] = last
        hk[i] = lk
        hg[i] = lg
        pos[last] = i
    return top, size
