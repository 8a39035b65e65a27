"""The state bundles every step task takes: particles, grid, conditions, settings.

Numba passes a named tuple of arrays to a ``cache=True`` kernel as cheaply as the
arrays themselves, so each task has the one signature ``task(P, G, C, K, S)``
instead of dozens of positional arrays.  ``K`` is the crack bundle of a scene with
cracks (``cracks.bundle``) or ``NO_CRACKS`` here; the core reads only its field
choice (``vfld``, ``cut``, ``chunk_counts``, and ``cnear``: stencil origins near a crack), and
only in builds with more than one velocity field.

Grid arrays carry a field axis: ``g[field, row, node]``.  A scene without cracks
has one field and the five rows below; a scene with cracks has NairnMPM's up to
four fields and extra rows for contact (``cracks.crack_kernels``).
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np

# rows of a velocity field on the grid (a crack scene adds its contact rows after these)
GM, GPX, GPY, GFX, GFY = 0, 1, 2, 3, 4
N_ROWS = 5

# status codes (``S.status[0]``; ``S.status[1]`` the particle or crack particle)
STATUS_OK = 0
STATUS_NONFINITE = 1
STATUS_LEFT_GRID = 2
STATUS_RUNAWAY = 3
STATUS_CRACK_LEFT_GRID = 4
STATUS_CRACK_LISTS_FULL = 5
# not an error: a watched crack tip may grow, Python's full propagation check is due
# (``cracks.growth_watch``); the step that set it is complete
STATUS_TIP_CHECK = -1

# ``S.clock``: time (ms) at the start of the next step, and the USAVG+ / USL+ stress
# half carried into the next stress pass (ms of update still owed)
CLOCK_T, CLOCK_PENDING = 0, 1

ParticleArrays = namedtuple("ParticleArrays", [
    "pos", "pos0", "vel", "mass", "vol0", "lp", "mat", "F", "stress", "hist", "w", "pdamp",
    "left",            # 1 once a particle has tried to leave the grid
    "wij", "wc",       # cached shape-function nodes and weights (``_store_weights``)
])

GridArrays = namedtuple("GridArrays", [
    "geom",            # (x0, y0, dx, dy, nodes per row)
    "bounds",          # (xmin, xmax, ymin, ymax) particles must stay inside
    "g",               # (fields, rows, nodes): mass, momentum, force (+ crack rows)
    "gbuf",            # (chunks, fields, rows, nodes): one buffer per particle chunk
    "gv", "ga", "gvn",   # (fields, 2, nodes): velocity, acceleration, updated velocity
    "gtmp",            # (2, nodes) scratch of the velocity conditions
    "bad",             # (chunks, 4): first bad particle, its status, left count, last left
])

ConditionArrays = namedtuple("ConditionArrays", [
    "gbc_node", "gbc_dir", "gbc_rec",                              # grid velocity conditions
    "pbc_part", "pbc_dir", "pbc_scale", "pbc_face", "pbc_rec",     # particle loads
    "rec_style", "rec_value", "rec_t0", "rec_ftime",               # one row per record
    "rec_force", "rec_work",                                       # results per record
    "sym_out", "sym_in", "sym_dir",                                # symmetry-plane mirrors
    "pload", "pos_before",                                         # load work scratch
    "fconst", "faddr",          # style-6 constants; (1,) address of their condition_cfunc
])

Settings = namedtuple("Settings", [
    "dt", "dt_first", "dt_last", "dt_update", "plus",   # ms; the stress-update split
    "plane_stress", "damping", "mass_tol", "vmax", "leave_limit", "nch",
    "mat_params",      # material table: row m = [update index, parameters...]
    "clock",           # (2,) CLOCK_T, CLOCK_PENDING
    "status",          # (2,) status code, particle
])

NoCracks = namedtuple("NoCracks", ["vfld", "cut", "chunk_counts", "cnear"])
NO_CRACKS = NoCracks(np.zeros((0, 0), dtype=np.int8), np.zeros(0, dtype=np.int8),
                     np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.uint8))


def stress_split(method: int, post_extrapolate: bool, dt: float):
    """(dt_first, dt_last, dt_update, plus): the stress update before the momentum
    update, the one after it, the part of that done in the particle update (the "-"
    variants), and whether it is carried into the next stress pass (USL+ / USAVG+)."""
    if method == 0:        # USF
        first, last = dt, 0.0
    elif method == 3:      # USL
        first, last = 0.0, dt
    else:                  # USAVG
        first = 0.5 * dt
        last = dt - first
    plus = bool(post_extrapolate and last > 0.0)
    return first, last, (0.0 if post_extrapolate else last), plus
