"""The crack bundle ``K`` every step task receives in a scene with cracks.

Crack particles (plane and the two surfaces), their laws and history, each particle's
velocity field at each of its nodes, and the crack lists the grid passes read: chords
per cell, crack slots per node and the crack nodes.  The lists are rebuilt every step
into arrays of fixed capacity (``nlist`` says how much is in use), so the bundle never
changes shape while the cracks keep theirs; a crack that grows gets a new bundle.
"""
from __future__ import annotations

from collections import namedtuple

CrackArrays = namedtuple("CrackArrays", [
    "cp", "ca", "cb",                  # (2, n) plane, above and below surface (mm)
    "cfirst", "clast", "cext0", "cext1", "ccrack", "cfixed",   # crack of each particle
    "claw", "cstate", "chist",         # traction law, state, largest opening per mode
    "law1", "law2",                    # law tables for mode I and II envelopes
    "vfld", "cut",                     # field of each particle at each node; 1 if any > 0
    "nslot", "cstart", "cnear", "cbox",   # node slots, chords per cell, near origins, box
    "chords", "cxy", "cnodes", "cnodes_old",   # crack lists (capacity arrays)
    "nlist",                           # (3,) chords, crack nodes, old crack nodes in use
    "counts", "chunk_counts",          # counters (C_*) and per-chunk conflicts
    "thickness", "use_position", "cutoff_cells", "ncx", "ncy",
    "edge_hist", "openings",           # edge maxima and openings at the last J evaluation
    "watch", "wgeom", "wstep",         # the growth watch (``growth_watch``)
])

# grid rows a crack scene adds to each velocity field, after the core's five: the
# mass-weighted displacement (contact), and in fields 1 and 2 the accumulated crack
# normal and side of the particles crossing that slot's crack
GUX, GUY, GNX, GNY, GSD = 5, 6, 7, 8, 9
NR = 10

# ``nlist`` entries
N_CHORDS, N_CNODES, N_CNODES_OLD = 0, 1, 2
