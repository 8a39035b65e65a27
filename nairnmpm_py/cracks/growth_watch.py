"""Watching the growing tips from inside the step (the ``watch_growth`` task).

A propagation check runs every check interval, which on the paper's DCB is every time
step; done in Python it cost a third of the run (J's fields and contour, the tip's
row, and the return from the driver around it).  Most checks find no tip near growth,
so the step watches instead: at each check it raises the edge maxima (as every J
evaluation does) and computes each watched tip's contour J(x), and it hands over to
Python's full check (``CrackScene.propagate``) only when J(x) reaches the tip's
growth threshold.

That is exact, not an estimate: J_tip = J(x) - W_B(x), or J(x) - W_B(root) when the
contour encloses the zone, and W_B >= 0 for a law whose loading envelope is
non-negative and lies above its secant from the origin (the unloading line never
gives back more than loading did).  So J(x) below the threshold means J_tip below it
too, and the full check would have found no growth.  A scene whose criteria have no
threshold, or whose laws fail that test, keeps the full check at every interval
(``CrackScene.watch_table``).  A check that cannot compute J here (the contour leaves
the grid or meets another crack) hands over too, and the full check reports why.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from nairnmpm_py.core.grid import GHOST
from nairnmpm_py.core.state import STATUS_TIP_CHECK
from nairnmpm_py.cracks.jintegral import (_J_OK, CrackPlane, JParticles, JSums, JWindow,
                                          NodalArrays, Square, StepAssignment,
                                          _contour_j, _extrapolate_assigned, _mass_averages,
                                          _MAX_HITS)

# ``K.watch`` columns: crack, end (1 the last particle, 0 the first), growth threshold
# (N/mm of J_tip), contour half-size (cells)
W_CRACK, W_END, W_THRESHOLD, W_SIZE = 0, 1, 2, 3
# ``K.wgeom``: the real grid's node (0, 0), cell size, cells along x and y
# ``K.wstep``: steps taken, steps per check
WSTEP_STEP, WSTEP_EVERY = 0, 1
# J(x) within this fraction of a threshold hands over: covers the rounding of
# W_B >= 0 (a law's linear rising part gives W_B = 0 to the last bit only in exact
# arithmetic) and of J(x) here against the full check's
MARGIN = 1e-6


@njit(cache=True)
def raise_edge_maxima(plane, above, below, crack, first, last, edge_hist, dn):
    """dn[k]: the normal opening of particle k now; edge_hist[0, k] / [1, k]: the largest
    mean normal opening of particle k and its previous / next neighbour so far (the
    particle itself at a crack's ends).  The normal is that of ``CrackScene.cod_at``:
    across the chord of the neighbours."""
    n = plane.shape[1]
    for k in range(n):
        c = crack[k]
        kp = max(k - 1, first[c])
        kn = min(k + 1, last[c])
        tx = plane[0, kn] - plane[0, kp]
        ty = plane[1, kn] - plane[1, kp]
        t = math.hypot(tx, ty)
        dn[k] = (-ty * (above[0, k] - below[0, k]) + tx * (above[1, k] - below[1, k])) / t
    for k in range(n):
        c = crack[k]
        prev_edge = 0.5 * (dn[k] + dn[max(k - 1, first[c])])
        next_edge = 0.5 * (dn[k] + dn[min(k + 1, last[c])])
        edge_hist[0, k] = max(edge_hist[0, k], prev_edge)
        edge_hist[1, k] = max(edge_hist[1, k], next_edge)


@njit(cache=True)
def _contour_value(P, G, K, crack, at_end, s):
    """(ok, J(x) in N/mm) of the tip's square contour of half-size s, from the fields
    the step assigned, as ``CrackScene._tip_row`` computes it; ok False when J cannot
    be computed here."""
    cp = K.cp
    tip = K.clast[crack] if at_end else K.cfirst[crack]
    adj = tip - 1 if at_end else tip + 1
    if K.clast[crack] - K.cfirst[crack] < 1:
        return False, 0.0
    dx = cp[0, tip] - cp[0, adj]
    dy = cp[1, tip] - cp[1, adj]
    ln = math.hypot(dx, dy)
    if ln == 0.0:
        return False, 0.0
    x0, y0, hx, hy = K.wgeom[0], K.wgeom[1], K.wgeom[2], K.wgeom[3]
    nx, ny = int(K.wgeom[4]), int(K.wgeom[5])
    ic = int(math.floor((cp[0, tip] - x0) / hx + 0.5))
    jc = int(math.floor((cp[1, tip] - y0) / hy + 0.5))
    if ic - s < 0 or ic + s > nx or jc - s < 0 or jc + s > ny:
        return False, 0.0
    nnx = int(G.geom[4])
    nny = G.g.shape[2] // nnx
    wi0, wi1 = max(ic - s + GHOST, 0), min(ic + s + GHOST, nnx - 1)
    wj0, wj1 = max(jc - s + GHOST, 0), min(jc + s + GHOST, nny - 1)
    win = JWindow(wi0, wi1, wj0, wj1, np.zeros(0, dtype=np.int64))
    nw = (wi1 - wi0 + 1) * (wj1 - wj0 + 1)
    sums = JSums(np.zeros((2, nw)), np.zeros((2, 4, nw)), np.zeros((2, 3, nw)),
                 np.zeros((2, nw)), np.zeros((2, nw)), np.full(nw, -1, dtype=np.int64),
                 np.zeros(nw, dtype=np.int64), np.zeros(nw, dtype=np.bool_),
                 np.zeros(2, dtype=np.int64))
    parts = JParticles(P.pos, P.vel, P.mass, P.vol0, P.lp, P.F, P.stress, P.w)
    _extrapolate_assigned(parts, G.geom, win, StepAssignment(K.vfld, K.cut, K.nslot, G.g,
                                                             P.wij, P.wc), sums)
    grad, stress, W, KE = _mass_averages(sums.m, sums.g, sums.s, sums.en, sums.ke)
    wnx = wi1 - wi0 + 1
    nodal = NodalArrays(sums.m, grad, stress, W, KE, sums.crack, sums.multi, wi0, wj0, wnx,
                        nw // wnx)
    count = K.clast - K.cfirst + 1
    plane = CrackPlane(cp[0], cp[1], K.cfirst, count)
    status, jx, jy, _, _, _, _, _ = _contour_j(nodal, Square(ic, jc, s, x0, y0, hx, hy), plane,
                                               crack, np.zeros((_MAX_HITS, 5)))
    if status != _J_OK:
        return False, 0.0
    return True, jx * (dx / ln) + jy * (dy / ln)


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True)
def watch_growth(P, G, C, K, S):
    """At each check step: edge maxima raised; the step stops (``STATUS_TIP_CHECK``)
    for Python's full check when a watched tip's J(x) reaches its threshold."""
    K.wstep[WSTEP_STEP] += 1
    if K.watch.shape[0] == 0 or K.wstep[WSTEP_STEP] % K.wstep[WSTEP_EVERY] != 0:
        return
    raise_edge_maxima(K.cp, K.ca, K.cb, K.ccrack, K.cfirst, K.clast, K.edge_hist, K.openings)
    for w in range(K.watch.shape[0]):
        ok, j = _contour_value(P, G, K, int(K.watch[w, W_CRACK]), K.watch[w, W_END] > 0.0,
                               int(K.watch[w, W_SIZE]))
        threshold = K.watch[w, W_THRESHOLD]
        if not ok or j >= threshold - MARGIN * abs(threshold):
            S.status[0] = STATUS_TIP_CHECK
            S.status[1] = w
            return
