"""Crack chords as the grid kernels see them (``cracks/crack_lists``, ``cracks/crack_kernels``).

* ``_chord``: the end points of chord k (crack particles k and k+1), an exterior
  crack end extended four chord lengths beyond the edge of the body, so a line from
  a particle to a node near that end still crosses it;
* ``_chord_cells``: the range of cells whose particles may have a node line cut by
  chord k (the cells it passes, padded), from which the kernels build their chord
  lists per cell.
"""
from __future__ import annotations

import math

from numba import njit

from .crossing import extended_chord

# a chord that cuts a particle-node line lies within the cells next to the particle's
# cell (uGIMP nodes are at most 1.5 cells away) and within the cells next to the
# node's four cells, so one cell of padding finds every chord that can matter
SEARCH_PAD_CELLS = 1


@njit(cache=True, inline="always")
def _chord(k, px, py, first_of, last_of, ext_start, ext_end, crack_of):
    """End points of chord k (particles k, k+1), exterior ends extended 4x."""
    c = crack_of[k]
    return extended_chord(px[k], py[k], px[k + 1], py[k + 1],
                          k == first_of[c] and ext_start[c], k + 1 == last_of[c] and ext_end[c])


@njit(cache=True, inline="always")
def _chord_cells(k, px, py, first_of, last_of, ext_start, ext_end, crack_of, geom, ncx, ncy):
    """Range of cells (i0, i1, j0, j1) a particle near chord k may sit in."""
    x3, y3, x4, y4 = _chord(k, px, py, first_of, last_of, ext_start, ext_end, crack_of)
    i0 = max(int(math.floor((min(x3, x4) - geom[0]) / geom[2])) - SEARCH_PAD_CELLS, 0)
    i1 = min(int(math.floor((max(x3, x4) - geom[0]) / geom[2])) + SEARCH_PAD_CELLS, ncx - 1)
    j0 = max(int(math.floor((min(y3, y4) - geom[1]) / geom[3])) - SEARCH_PAD_CELLS, 0)
    j1 = min(int(math.floor((max(y3, y4) - geom[1]) / geom[3])) + SEARCH_PAD_CELLS, ncy - 1)
    return i0, i1, j0, j1
