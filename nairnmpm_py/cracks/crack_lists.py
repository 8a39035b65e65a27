"""The crack lists the grid passes read, rebuilt for the current crack planes.

For each cell, the chords (crack segments) whose particles' node lines it may cut;
for each node, the two lowest-numbered cracks listed next to it (its slots); and the
crack nodes (nodes with a slot, the only nodes where velocity fields can differ).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .chords import _chord, _chord_cells

# ``cnear`` is indexed by a particle's first stencil node i0 (and j0), which the
# particle pass has at hand (its cell would cost two divisions per particle).  The
# particle touches nodes i0 .. i0 + 2 (uGIMP; i0 .. i0 + 1 linear), and the nodes
# with a crack slot are those of the cells that list a chord (i .. i + 1): so only
# particles with i0 in [i - ORIGIN_BELOW, i + ORIGIN_ABOVE] can touch one.  Those
# take the near path (crossing tests); every other particle touches no crack node.
ORIGIN_BELOW = 2
ORIGIN_ABOVE = 1


@njit(cache=True)
def build_crack_lists(cp, cfirst, clast, cext0, cext1, ccrack, geom, ncx, ncy, nnx, nslot, cstart,
                cnear, cbox):
    """Chords near each cell, the crack slots of every node and the nodes that have
    one (the only nodes where fields can differ), for the current plane.

    Work and writes stay inside the box of cells the chords reach (``cbox``: i0, i1,
    j0, j1, kept between calls so the previous box is cleared first), so the cost
    follows the crack, not the grid.  ``cstart[0, cell]`` to ``cstart[1, cell]`` index
    the cell's chords in the returned ``chords``; every other cell has an empty range.
    ``cxy`` holds each entry's chord end points.
    ``cnear`` marks the stencil origins (first nodes) of the particles that can touch
    a node of a cell with chords (ORIGIN_BELOW, ORIGIN_ABOVE); ``nslot`` holds a
    node's two lowest-numbered cracks listed in a cell next to it (-1 none).
    """
    px = cp[0]
    py = cp[1]
    nn = nslot.shape[1]
    nny = nn // nnx
    # clear the previous box (its cells, the origins near them, the nodes of its cells)
    if cbox[0] <= cbox[1]:
        for j in range(cbox[2], cbox[3] + 1):
            for i in range(cbox[0], cbox[1] + 1):
                cell = j * ncx + i
                cstart[0, cell] = 0
                cstart[1, cell] = 0
        for j in range(max(cbox[2] - ORIGIN_BELOW, 0), min(cbox[3] + ORIGIN_ABOVE + 1, nny)):
            for i in range(max(cbox[0] - ORIGIN_BELOW, 0), min(cbox[1] + ORIGIN_ABOVE + 1, nnx)):
                cnear[j * nnx + i] = 0
        for j in range(cbox[2], min(cbox[3] + 2, nny)):
            for i in range(cbox[0], min(cbox[1] + 2, nnx)):
                nslot[0, j * nnx + i] = -1
                nslot[1, j * nnx + i] = -1
    # the new box, from each chord's cells (kept for the two passes below)
    n = px.size
    ranges = np.zeros((max(n - 1, 0), 4), dtype=np.int64)
    ranges[:, 1] = -1                     # empty (i0 > i1) unless set below
    ranges[:, 3] = -1
    i_lo = ncx
    i_hi = -1
    j_lo = ncy
    j_hi = -1
    for k in range(n - 1):
        if ccrack[k] != ccrack[k + 1]:
            continue                      # no chord between two cracks
        i0, i1, j0, j1 = _chord_cells(k, px, py, cfirst, clast, cext0, cext1, ccrack, geom,
                                      ncx, ncy)
        ranges[k, 0] = i0
        ranges[k, 1] = i1
        ranges[k, 2] = j0
        ranges[k, 3] = j1
        i_lo = min(i_lo, i0)
        i_hi = max(i_hi, i1)
        j_lo = min(j_lo, j0)
        j_hi = max(j_hi, j1)
    cbox[0] = i_lo
    cbox[1] = i_hi
    cbox[2] = j_lo
    cbox[3] = j_hi
    if i_lo > i_hi:
        return (np.zeros(0, dtype=np.int64), np.zeros((0, 4)), np.zeros(0, dtype=np.int64))
    bw = i_hi - i_lo + 1
    count = np.zeros(bw * (j_hi - j_lo + 1) + 1, dtype=np.int64)
    for k in range(n - 1):
        for j in range(ranges[k, 2], ranges[k, 3] + 1):
            for i in range(ranges[k, 0], ranges[k, 1] + 1):
                count[(j - j_lo) * bw + i - i_lo + 1] += 1
    for q in range(count.size - 1):
        count[q + 1] += count[q]
    chords = np.empty(count[count.size - 1], dtype=np.int64)
    for j in range(j_lo, j_hi + 1):
        for i in range(i_lo, i_hi + 1):
            b = (j - j_lo) * bw + i - i_lo
            cell = j * ncx + i
            cstart[0, cell] = count[b]
            cstart[1, cell] = count[b]
    for k in range(n - 1):
        for j in range(ranges[k, 2], ranges[k, 3] + 1):
            for i in range(ranges[k, 0], ranges[k, 1] + 1):
                cell = j * ncx + i
                chords[cstart[1, cell]] = k
                cstart[1, cell] += 1
    # near cells and node slots
    nc = 0
    for j in range(j_lo, j_hi + 1):
        for i in range(i_lo, i_hi + 1):
            cell = j * ncx + i
            if cstart[1, cell] == cstart[0, cell]:
                continue
            for jj in range(max(j - ORIGIN_BELOW, 0), min(j + ORIGIN_ABOVE + 1, nny)):
                for ii in range(max(i - ORIGIN_BELOW, 0), min(i + ORIGIN_ABOVE + 1, nnx)):
                    cnear[jj * nnx + ii] = 1
    cnodes = np.empty((bw + 1) * (j_hi - j_lo + 2), dtype=np.int64)
    for j in range(j_lo, min(j_hi + 2, nny)):
        for i in range(i_lo, min(i_hi + 2, nnx)):
            node = j * nnx + i
            a = -1
            b = -1
            for cj in range(j - 1, j + 1):
                if cj < 0 or cj >= ncy:
                    continue
                for ci in range(i - 1, i + 1):
                    if ci < 0 or ci >= ncx:
                        continue
                    cell = cj * ncx + ci
                    for q in range(cstart[0, cell], cstart[1, cell]):
                        c = ccrack[chords[q]]
                        if c == a or c == b:
                            continue
                        if a < 0 or c < a:
                            b = a
                            a = c
                        elif b < 0 or c < b:
                            b = c
            nslot[0, node] = a
            nslot[1, node] = b
            if a >= 0:
                cnodes[nc] = node
                nc += 1
    # each listed chord's end points (exterior ends extended), next to its entry, so
    # the crossing tests read them in order
    cxy = np.empty((chords.size, 4))
    for q in range(chords.size):
        x3, y3, x4, y4 = _chord(chords[q], px, py, cfirst, clast, cext0, cext1, ccrack)
        cxy[q, 0] = x3
        cxy[q, 1] = y3
        cxy[q, 2] = x4
        cxy[q, 3] = y4
    return chords, cxy, cnodes[:nc]
