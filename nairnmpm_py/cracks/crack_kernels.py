"""The crack tasks of the time step (CRAMP), as Numba kernels.

``core/tasks.py`` inserts these into the step of a scene with cracks; the shared
tasks of ``core/step_kernels`` then run with several velocity fields per node and
call ``assign_and_scatter`` here for each particle's field choice.  A template like
``step_kernels``: ``kernel_build`` writes a copy with the scene's shape functions
(``KIND``) and a dispatcher over its traction-law envelopes.

What a crack adds to the step (shared notes CRAMP.md, JINTEGRAL.md section 7):

* every node has up to four velocity fields: 0 = particles on the node's side of
  every crack, 1 = across the crack in the node's slot 0, 2 = across the crack in
  slot 1, 3 = across both (two fields when the scene has one crack).  A node's slots
  are the two lowest-numbered cracks with a chord near it, so field choice is the
  same on every thread.  Each particle's field at each of its nodes (``K.vfld``) is
  found once per step by the CRAMP line-crossing test and reused by every pass;
* each field carries mass, momentum, force and the mass-weighted particle
  displacement (for contact), and the two slot rows of fields 1 and 2 carry the
  crack normal and the side of the crossing particles;
* frictionless contact between the fields of a node after extrapolation and after
  the momentum update (approaching and overlapping only);
* traction-law crack particles pull their two surfaces together with
  -A (T_n n + T_t t); the framework keeps the history (maximum COD per mode),
  unloads to the origin and fails the particle at delta_c;
* crack surfaces move with the field on their side (mean of old and new grid
  velocity, as particles move), the crack plane with the mean of its two surfaces;
  then the crack lists are rebuilt for the next particle pass (``crack_lists``).

Fields 1-3 and the contact rows exist only at crack nodes (``K.cnodes``).  Their
chunk-buffer entries are read and zeroed by the reductions, so they never need
clearing; ``G.g`` keeps them zero away from the current crack nodes
(``clear_crack_nodes``).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from nairnmpm_py.core.state import (GM, GPX, GPY, GFX, GFY, STATUS_CRACK_LEFT_GRID,
                                    STATUS_CRACK_LISTS_FULL)
from nairnmpm_py.core.grid_ops import accelerate_node
from nairnmpm_py.core.step_kernels import FAST
from nairnmpm_py.cracks.bundle import GUX, GUY, GNX, GNY, GSD, N_CHORDS, N_CNODES, N_CNODES_OLD
from nairnmpm_py.cracks.crack_lists import build_crack_lists
from nairnmpm_py.cracks.crossing import segment_crossing_side
from nairnmpm_py.traction.dispatch_default import traction_envelope  # KERNEL-TRACTION

KIND = 1  # KERNEL-SHAPE: 0 classic linear, 1 uGIMP
NA = 2 if KIND == 0 else 3

NUDGE = 1e-4  # cells: a crack surface is tested from just off the plane, on its side

# counters (``K.counts``): pairs whose crack is not in the node's slots, surfaces with
# no field on either side, failed traction particles, blocked crack moves
C_CONFLICT, C_LOST, C_FAILED, C_BLOCKED = 0, 1, 2, 3


# ---- field choice -------------------------------------------------------------------
@njit(cache=True, inline="always")
def _pair_field(x, y, xn, yn, node, cell, cstart, chords, cxy, ccrack, nslot, nf):
    """Velocity field of the particle (x, y) at a node (xn, yn): 1 bit per slot whose
    crack the particle-node line crosses an odd number of times.  Also returns, per
    slot, the last crossed chord (-1 none) and the particle's side (+1 above), and 1
    if a crack outside the node's slots was crossed (that crossing is ignored)."""
    par0 = 0
    par1 = 0
    k0 = -1
    k1 = -1
    s0 = 0
    s1 = 0
    bad = 0
    for q in range(cstart[0, cell], cstart[1, cell]):
        k = chords[q]
        hit = segment_crossing_side(x, y, xn, yn, cxy[q, 0], cxy[q, 1], cxy[q, 2], cxy[q, 3])
        if hit == 0:
            continue
        c = ccrack[k]
        if nslot[0, node] == c:
            par0 ^= 1
            k0 = k
            s0 = hit
        elif nf == 4 and nslot[1, node] == c:
            par1 ^= 1
            k1 = k
            s1 = hit
        else:
            bad = 1
    return par0 + 2 * par1, (k0 if par0 else -1), s0, (k1 if par1 else -1), s1, bad


@njit(cache=True, inline="always")
def _cell_of(x, y, geom, ncx, ncy):
    ci = min(max(int(math.floor((x - geom[0]) / geom[2])), 0), ncx - 1)
    cj = min(max(int(math.floor((y - geom[1]) / geom[3])), 0), ncy - 1)
    return cj * ncx + ci


@njit(cache=True, inline="always")
def _add_normal(fb, k, w, side, chord, cp):
    """A crossing particle's weight times its chord's normal (toward the below side)
    and its side, into a slot's accumulator rows."""
    ex = cp[0, chord + 1] - cp[0, chord]
    ey = cp[1, chord + 1] - cp[1, chord]
    el = math.sqrt(ex * ex + ey * ey)
    fb[GNX, k] += w * ey / el
    fb[GNY, k] -= w * ex / el
    fb[GSD, k] += w * side


@njit(cache=True)
def field_lists(P, K):
    """What ``assign_and_scatter`` reads for a particle near a crack, as a plain tuple
    the core's parallel loops can take (not the bundles: module docstring of
    ``core.step_kernels``).  Reading an array out of a tuple costs reference counting
    each time, so the test every particle makes (``K.cnear``) is not in it."""
    return (K.nslot, K.cstart, K.chords, K.cxy, K.ccrack, K.cp, K.use_position, P.pos0)


@njit(cache=True, inline="always")
def assign_and_scatter(buf, p, r, i0, j0, geom, m, x, y, mvx, mvy, vfld, cut, cnear,
                       crack_lists, conflicts):
    """Field choice at each node of particle p (weights ``r`` from node (i0, j0); mass
    m at (x, y) with momentum (mvx, mvy)), then its mass and momentum (and at crack
    nodes its displacement or position, and for crossed pairs the crack normal and
    side) onto its chunk buffer.  A particle that can touch no crack node (``cnear`` 0
    at its first stencil node: ``crack_lists.ORIGIN_BELOW``) takes field 0 at every
    node, with no crossing tests, and ``cut`` 0."""
    nnx = int(geom[4])
    if cnear[j0 * nnx + i0] != 0:
        return _assign_near_crack(buf, p, r, i0, j0, geom, m, x, y, mvx, mvy, vfld, cut,
                                  crack_lists, conflicts)
    cut[p] = 0
    # step_kernels.scatter_mass_momentum's loop, written here because this module's NA
    # is its own build's (the template's copy would always have uGIMP's 3)
    b0 = buf[0]
    for b in range(NA):
        sy = r[3 + b]
        row = (j0 + b) * nnx + i0
        for a in range(NA):
            s = sy * r[a]
            k = row + a
            b0[GM, k] += s * m
            b0[GPX, k] += s * mvx
            b0[GPY, k] += s * mvy
    return conflicts


@njit(cache=True, fastmath=FAST, error_model="numpy", no_cpython_wrapper=True)
def _assign_near_crack(buf, p, r, i0, j0, geom, m, x, y, mvx, mvy, vfld, cut,
                       crack_lists, conflicts):
    """``assign_and_scatter`` of a particle near a crack: linked, not inlined (few
    particles take it, and inlined it made the particle pass compile for about 20 s
    longer); compiled like the particle pass that calls it."""
    nnx = int(geom[4])
    nslot, cstart, chords, cxy, ccrack, cp, use_position, pos0 = crack_lists
    ncx = nnx - 1               # cells per row (``CrackScene``)
    cell = _cell_of(x, y, geom, ncx, cstart.shape[1] // ncx)
    if use_position:
        mux = m * x
        muy = m * y
    else:
        mux = m * (x - pos0[0, p])
        muy = m * (y - pos0[1, p])
    has_chords = cstart[1, cell] > cstart[0, cell]
    nf = buf.shape[0]
    any_cut = 0
    for b in range(NA):
        sy = r[3 + b]
        row = (j0 + b) * nnx + i0
        for a in range(NA):
            s = sy * r[a]
            k = row + a
            f = 0
            slotted = nslot[0, k] >= 0
            if slotted and has_chords:
                xn = geom[0] + (i0 + a) * geom[2]
                yn = geom[1] + (j0 + b) * geom[3]
                f, k0, s0, k1, s1, bad = _pair_field(x, y, xn, yn, k, cell, cstart, chords,
                                                     cxy, ccrack, nslot, nf)
                conflicts += bad
                w = s * m
                if k0 >= 0:
                    _add_normal(buf[1], k, w, s0, k0, cp)
                if k1 >= 0:
                    _add_normal(buf[2], k, w, s1, k1, cp)
            vfld[p, b * NA + a] = f
            any_cut |= f
            fb = buf[f]
            fb[GM, k] += s * m
            fb[GPX, k] += s * mvx
            fb[GPY, k] += s * mvy
            if slotted:
                fb[GUX, k] += s * mux
                fb[GUY, k] += s * muy
    cut[p] = 1 if any_cut else 0
    return conflicts


# ---- crack nodes ------------------------------------------------------------------------
@njit(cache=True, error_model="numpy", no_cpython_wrapper=True)
def reduce_crack_fields(P, G, C, K, S):
    """Sum the chunks' extrapolated rows at the crack nodes (fields 1-3, and field 0's
    contact rows), zeroing those buffer entries; velocities there.  Adds the chunks'
    field conflicts to the counter."""
    g = G.g
    gv = G.gv
    gbuf = G.gbuf
    nch = S.nch
    nf = g.shape[0]
    for c in range(nch):
        K.counts[C_CONFLICT] += K.chunk_counts[c]
    for q in range(K.nlist[N_CNODES]):
        k = K.cnodes[q]
        for f in range(nf):
            for row in (GM, GPX, GPY, GUX, GUY, GNX, GNY, GSD):
                if f == 0 and row <= GPY:
                    continue
                s = 0.0
                for c in range(nch):
                    s += gbuf[c, f, row, k]
                    gbuf[c, f, row, k] = 0.0
                g[f, row, k] = s
            m = g[f, GM, k]
            if m > 0.0:
                gv[f, 0, k] = g[f, GPX, k] / m
                gv[f, 1, k] = g[f, GPY, k] / m
            else:
                gv[f, 0, k] = 0.0
                gv[f, 1, k] = 0.0


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True)
def clear_crack_nodes(P, G, C, K, S):
    """Zero fields 1-3 and the contact rows at the previous step's crack nodes (the
    cracks have moved and the crack nodes changed), so away from crack nodes those
    stay zero."""
    g = G.g
    nf = g.shape[0]
    for q in range(K.nlist[N_CNODES_OLD]):
        k = K.cnodes_old[q]
        for f in range(nf):
            for row in range(g.shape[1]):
                if f == 0 and row <= GFY:
                    continue
                g[f, row, k] = 0.0
            if f > 0:
                for d in range(2):
                    G.gv[f, d, k] = 0.0
                    G.ga[f, d, k] = 0.0
                    G.gvn[f, d, k] = 0.0


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True)
def reduce_crack_forces(P, G, C, K, S):
    """Add the chunks' internal forces of fields 1-3 at the crack nodes (zeroing those
    buffer entries)."""
    g = G.g
    gbuf = G.gbuf
    nf = g.shape[0]
    for q in range(K.nlist[N_CNODES]):
        k = K.cnodes[q]
        for f in range(1, nf):
            fx = 0.0
            fy = 0.0
            for c in range(S.nch):
                fx += gbuf[c, f, GFX, k]
                fy += gbuf[c, f, GFY, k]
                gbuf[c, f, GFX, k] = 0.0
                gbuf[c, f, GFY, k] = 0.0
            g[f, GFX, k] += fx
            g[f, GFY, k] += fy


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True)
def accelerate_crack_fields(P, G, C, K, S):
    """Accelerations and updated velocities of fields 1-3 at the crack nodes."""
    for q in range(K.nlist[N_CNODES]):
        for f in range(1, G.g.shape[0]):
            accelerate_node(G.g, G.ga, G.gvn, f, K.cnodes[q], S.dt, S.mass_tol)


# ---- contact --------------------------------------------------------------------------
@njit(cache=True, inline="always")
def _contact_pair(g, k, fa, fb, nx, ny, dt, after_update, use_position, cutoff):
    """Frictionless contact of field fa (above) and fb (below) at node k; n points from
    above to below.  Before the update it corrects momenta, after it the forces (so
    the updated momenta change by the same amount)."""
    ma = g[fa, GM, k]
    mb = g[fb, GM, k]
    if ma <= 0.0 or mb <= 0.0:
        return
    pax = g[fa, GPX, k]
    pay = g[fa, GPY, k]
    pbx = g[fb, GPX, k]
    pby = g[fb, GPY, k]
    if after_update:
        pax += g[fa, GFX, k] * dt
        pay += g[fa, GFY, k] * dt
        pbx += g[fb, GFX, k] * dt
        pby += g[fb, GFY, k] * dt
    msum = ma + mb
    dpx = (ma * pbx - mb * pax) / msum
    dpy = (ma * pby - mb * pay) / msum
    dpn = dpx * nx + dpy * ny
    if dpn >= 0.0:
        return  # separating
    sep = ((g[fb, GUX, k] / mb - g[fa, GUX, k] / ma) * nx
           + (g[fb, GUY, k] / mb - g[fa, GUY, k] / ma) * ny)
    if use_position:
        sep -= cutoff
    if after_update:
        sep += dt * dpn * msum / (ma * mb)
    if sep >= 0.0:
        return  # not touching
    cx = dpn * nx
    cy = dpn * ny
    if after_update:
        g[fa, GFX, k] += cx / dt
        g[fa, GFY, k] += cy / dt
        g[fb, GFX, k] -= cx / dt
        g[fb, GFY, k] -= cy / dt
    else:
        g[fa, GPX, k] += cx
        g[fa, GPY, k] += cy
        g[fb, GPX, k] -= cx
        g[fb, GPY, k] -= cy


@njit(cache=True, error_model="numpy")
def contact(g, gv, nslot, cnodes, dt, after_update, use_position, cutoff_cells, geom):
    """Contact across each slot's crack: fields (0, 1) and (2, 3) across slot 0,
    (0, 2) and (1, 3) across slot 1.  The slot's accumulated side says which field is
    above; its accumulated normal is the contact normal."""
    nf = g.shape[0]
    for q in range(cnodes.size):
        k = cnodes[q]
        touched = False
        for s in range(2):
            if nslot[s, k] < 0 or (s == 1 and nf < 4):
                continue
            acc = 1 + s
            nx = g[acc, GNX, k]
            ny = g[acc, GNY, k]
            ln = math.sqrt(nx * nx + ny * ny)
            if ln == 0.0:
                continue
            nx /= ln
            ny /= ln
            cutoff = cutoff_cells * (abs(nx) * geom[2] + abs(ny) * geom[3])
            bit = 1 << s
            crossed_above = g[acc, GSD, k] > 0.0
            for base in range(2):
                lo = 0 if base == 0 else (1 << (1 - s))
                if lo >= nf:
                    continue
                hi = lo | bit
                if crossed_above:
                    _contact_pair(g, k, hi, lo, nx, ny, dt, after_update, use_position, cutoff)
                else:
                    _contact_pair(g, k, lo, hi, nx, ny, dt, after_update, use_position, cutoff)
                touched = True
        if touched and not after_update:
            for f in range(nf):
                m = g[f, GM, k]
                if m > 0.0:
                    gv[f, 0, k] = g[f, GPX, k] / m
                    gv[f, 1, k] = g[f, GPY, k] / m


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True)
def contact_momenta(P, G, C, K, S):
    """Contact on the extrapolated momenta (and their velocities)."""
    # after_update as a runtime False / True: literals would compile contact twice
    contact(G.g, G.gv, K.nslot, K.cnodes[:K.nlist[N_CNODES]], S.dt, S.nch < 0,
            K.use_position, K.cutoff_cells, G.geom)


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True)
def contact_forces(P, G, C, K, S):
    """Contact on the updated momenta, as a change of the forces."""
    contact(G.g, G.gv, K.nslot, K.cnodes[:K.nlist[N_CNODES]], S.dt, S.nch > 0,
            K.use_position, K.cutoff_cells, G.geom)


# ---- crack particles ------------------------------------------------------------------
@njit(cache=True, inline="always")
def crack_frame(k, cpx, cpy, ccrack, cfirst, clast):
    """Unit tangent (first -> last), unit normal toward the above side, and the chord
    length this particle represents (half of each adjacent chord)."""
    c = ccrack[k]
    kp = k - 1 if k > cfirst[c] else k
    kn = k + 1 if k < clast[c] else k
    tx = cpx[kn] - cpx[kp]
    ty = cpy[kn] - cpy[kp]
    tl = math.sqrt(tx * tx + ty * ty)
    tx /= tl
    ty /= tl
    return tx, ty, -ty, tx, 0.5 * tl


@njit(cache=True, inline="always")
def _surface_cell(sx, sy, geom):
    """Lower-left node (column, row) of the cell holding a surface point and the
    point's fractions across it (classic linear shape functions)."""
    xi = (sx - geom[0]) / geom[2]
    eta = (sy - geom[1]) / geom[3]
    i0 = int(math.floor(xi))
    j0 = int(math.floor(eta))
    return i0, j0, xi - i0, eta - j0


@njit(cache=True, no_cpython_wrapper=True)
def _surface_nodes(sx, sy, ux, uy, sgn, G, K, scratch):
    """Classic linear shape functions at a crack surface point and the field on the
    surface's side at each of the four nodes; weights are S * m of that field (0 when
    the field is empty).  Returns the sum of the weights."""
    nodes, fields, weights, tested = scratch[0], scratch[1], scratch[2], scratch[3]
    geom = G.geom
    g = G.g
    nnx = int(geom[4])
    i0, j0, rx, ry = _surface_cell(sx, sy, geom)
    # test from just off the plane on the surface's own side
    tx_ = sx + sgn * NUDGE * geom[2] * ux
    ty_ = sy + sgn * NUDGE * geom[3] * uy
    cell = _cell_of(tx_, ty_, geom, K.ncx, K.ncy)
    total = 0.0
    q = 0
    for b in range(2):
        for a in range(2):
            s = (rx if a == 1 else 1.0 - rx) * (ry if b == 1 else 1.0 - ry)
            node = (j0 + b) * nnx + i0 + a
            nodes[q] = node
            fields[q] = 0
            weights[q] = 0.0
            tested[q] = s > 0.0
            if s > 0.0:
                xn = geom[0] + (i0 + a) * geom[2]
                yn = geom[1] + (j0 + b) * geom[3]
                f, k0, s0, k1, s1, bad = _pair_field(tx_, ty_, xn, yn, node, cell, K.cstart,
                                                     K.chords, K.cxy, K.ccrack, K.nslot,
                                                     g.shape[0])
                fields[q] = f
                weights[q] = s * g[f, GM, node]
                total += weights[q]
            q += 1
    return total


@njit(cache=True, inline="always")
def _near_crack_end(k, K, geom):
    """Within 2.5 cells of an end of its crack, where a surface-node line can pass
    beyond the end, so the two surfaces' fields are not mirror images."""
    c = K.ccrack[k]
    reach = 2.5 * max(geom[2], geom[3])
    for e in (K.cfirst[c], K.clast[c]):
        dx = K.cp[0, k] - K.cp[0, e]
        dy = K.cp[1, k] - K.cp[1, e]
        if dx * dx + dy * dy < reach * reach:
            return True
    return False


@njit(cache=True, no_cpython_wrapper=True)
def _mirror_surface_nodes(sx, sy, crack, G, K, scratch):
    """The second surface of a crack particle away from the crack's ends, when it lies
    in the same cell as the first: each node's field is the first surface's with the
    bit of this crack's slot flipped (the two surfaces sit on opposite sides of their
    own crack and, so close together, on the same side of everything else), which
    saves its crossing tests.
    Returns -1 when that does not apply (another cell, or a node the first surface
    did not test)."""
    nodes, fields, weights = scratch[0], scratch[1], scratch[2]
    ref_nodes, ref_fields, ref_tested = scratch[4], scratch[5], scratch[6]
    geom = G.geom
    g = G.g
    nf = g.shape[0]
    nnx = int(geom[4])
    i0, j0, rx, ry = _surface_cell(sx, sy, geom)
    total = 0.0
    q = 0
    for b in range(2):
        for a in range(2):
            s = (rx if a == 1 else 1.0 - rx) * (ry if b == 1 else 1.0 - ry)
            node = (j0 + b) * nnx + i0 + a
            if node != ref_nodes[q]:
                return -1.0
            nodes[q] = node
            fields[q] = 0
            weights[q] = 0.0
            if s > 0.0:
                if not ref_tested[q]:
                    return -1.0
                f = ref_fields[q]
                if K.nslot[0, node] == crack:
                    f ^= 1
                elif K.nslot[1, node] == crack:
                    f ^= 2
                if f >= nf:
                    return -1.0
                fields[q] = f
                weights[q] = s * g[f, GM, node]
                total += weights[q]
            q += 1
    return total


@njit(cache=True, inline="always")
def _side_scratch():
    """Work arrays of ``_side_nodes``: nodes, fields, weights, tested and their
    first-surface copies (four nodes each)."""
    return (np.empty(4, dtype=np.int64), np.empty(4, dtype=np.int64), np.empty(4),
            np.empty(4, dtype=np.bool_), np.empty(4, dtype=np.int64),
            np.empty(4, dtype=np.int64), np.empty(4, dtype=np.bool_))


@njit(cache=True, no_cpython_wrapper=True)
def _side_nodes(k, side, sx, sy, ux, uy, G, K, scratch):
    """Nodes, fields and weights (``scratch[0:3]``) of one surface of crack particle k:
    the second surface (side 1) mirrors the first where it can, else both run the
    crossing tests; the first surface's result is kept in ``scratch[4:7]``."""
    total = -1.0
    sgn = 1.0 if side == 0 else -1.0
    if side == 1 and not _near_crack_end(k, K, G.geom):
        total = _mirror_surface_nodes(sx, sy, K.ccrack[k], G, K, scratch)
    if total < 0.0:
        total = _surface_nodes(sx, sy, ux, uy, sgn, G, K, scratch)
        if side == 0:
            # element by element: a slice copy compiles Numba's broadcasting (seconds)
            for q in range(4):
                scratch[4][q] = scratch[0][q]
                scratch[5][q] = scratch[1][q]
                scratch[6][q] = scratch[3][q]
    return total


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True)
def crack_tractions(P, G, C, K, S):
    """Traction forces of the law particles on both surfaces' fields (the force is
    shared by S * m, all of it delivered), with history, unloading to the origin and
    failure at delta_c per mode."""
    g = G.g
    scratch = _side_scratch()
    nodes, fields, weights = scratch[0], scratch[1], scratch[2]
    cp = K.cp
    ca = K.ca
    cb = K.cb
    chist = K.chist
    for k in range(cp.shape[1]):
        law = K.claw[k]
        if law < 0 or K.cstate[k] != 1:
            continue
        tx, ty, ux, uy, half = crack_frame(k, cp[0], cp[1], K.ccrack, K.cfirst, K.clast)
        ddx = ca[0, k] - cb[0, k]
        ddy = ca[1, k] - cb[1, k]
        dn = ddx * ux + ddy * uy
        dt_ = ddx * tx + ddy * ty
        tn = 0.0
        tt = 0.0
        failed = False
        if K.law1[law, 0] >= 0.0 and dn > 0.0:
            par = K.law1[law, 1:]
            h = max(chist[0, k], dn)
            chist[0, k] = h
            if h >= par[0]:
                failed = True
            else:
                tn = traction_envelope(int(K.law1[law, 0]), h, par) / h * dn
        if K.law2[law, 0] >= 0.0 and dt_ != 0.0:
            par = K.law2[law, 1:]
            a = abs(dt_)
            h = max(chist[1, k], a)
            chist[1, k] = h
            if h >= par[0]:
                failed = True
            else:
                tt = traction_envelope(int(K.law2[law, 0]), h, par) / h * dt_
        if failed:
            K.cstate[k] = 2
            K.counts[C_FAILED] += 1
            continue
        area = half * K.thickness
        fx = -area * (tn * ux + tt * tx)
        fy = -area * (tn * uy + tt * ty)
        if fx == 0.0 and fy == 0.0:
            continue
        for side in range(2):
            sgn = 1.0 if side == 0 else -1.0
            sx = ca[0, k] if side == 0 else cb[0, k]
            sy = ca[1, k] if side == 0 else cb[1, k]
            total = _side_nodes(k, side, sx, sy, ux, uy, G, K, scratch)
            if total <= 0.0:
                continue
            for q in range(4):
                if weights[q] > 0.0:
                    share = sgn * weights[q] / total
                    g[fields[q], GFX, nodes[q]] += share * fx
                    g[fields[q], GFY, nodes[q]] += share * fy


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True)
def _moves_chunk(G, K, S, c, moves, found, blocked):
    """Chunk c of the crack particles' surface moves over the step: the mean of the
    old and new velocity of the field on each surface's side (mass-weighted, classic
    shape functions), from the positions before the step.  A move beyond half a cell
    is blocked (counted, not taken)."""
    nc = K.cp.shape[1]
    nch = S.nch
    dt = S.dt
    limit = 0.5 * min(G.geom[2], G.geom[3])
    ga = G.ga
    gvn = G.gvn
    scratch = _side_scratch()
    nodes, fields, weights = scratch[0], scratch[1], scratch[2]
    for k in range(c * nc // nch, (c + 1) * nc // nch):
        if K.cfixed[K.ccrack[k]]:
            continue
        tx, ty, ux, uy, half = crack_frame(k, K.cp[0], K.cp[1], K.ccrack, K.cfirst, K.clast)
        for side in range(2):
            sx = K.ca[0, k] if side == 0 else K.cb[0, k]
            sy = K.ca[1, k] if side == 0 else K.cb[1, k]
            total = _side_nodes(k, side, sx, sy, ux, uy, G, K, scratch)
            if total <= 0.0:
                continue
            vx = 0.0
            vy = 0.0
            for q in range(4):
                wq = weights[q]
                if wq > 0.0:
                    f = fields[q]
                    node = nodes[q]
                    vx += wq * (gvn[f, 0, node] - 0.5 * ga[f, 0, node] * dt)
                    vy += wq * (gvn[f, 1, node] - 0.5 * ga[f, 1, node] * dt)
            mx = vx / total * dt
            my = vy / total * dt
            if abs(mx) > limit or abs(my) > limit:
                blocked[c] += 1
                mx = 0.0
                my = 0.0
            moves[k, side, 0] = mx
            moves[k, side, 1] = my
            found[k, side] = True


@njit(cache=True, parallel=True, error_model="numpy", no_cpython_wrapper=True)
def _surface_moves(G, K, S, moves, found, blocked):
    """Each crack particle's surface moves, found independently in ``S.nch`` chunks
    (so they do not depend on the chunking)."""
    for c in prange(S.nch):
        _moves_chunk(G, K, S, np.int64(c), moves, found, blocked)


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True)
def move_cracks(P, G, C, K, S):
    """Surfaces move by ``_surface_moves``; a side that finds no field copies the
    other; the plane moves with the mean of the two surfaces.  A crack particle that
    leaves the grid stops the run."""
    nc = K.cp.shape[1]
    moves = np.zeros((nc, 2, 2))
    found = np.zeros((nc, 2), dtype=np.bool_)
    blocked = np.zeros(S.nch, dtype=np.int64)
    _surface_moves(G, K, S, moves, found, blocked)
    K.counts[C_BLOCKED] += blocked.sum()
    bounds = G.bounds
    ca = K.ca
    cb = K.cb
    cp = K.cp
    out = -1
    for k in range(nc):
        if K.cfixed[K.ccrack[k]]:
            continue
        if not found[k, 0] and not found[k, 1]:
            K.counts[C_LOST] += 1
            continue
        if not found[k, 0]:
            moves[k, 0, 0] = moves[k, 1, 0]
            moves[k, 0, 1] = moves[k, 1, 1]
        if not found[k, 1]:
            moves[k, 1, 0] = moves[k, 0, 0]
            moves[k, 1, 1] = moves[k, 0, 1]
        ca[0, k] += moves[k, 0, 0]
        ca[1, k] += moves[k, 0, 1]
        cb[0, k] += moves[k, 1, 0]
        cb[1, k] += moves[k, 1, 1]
        cp[0, k] += 0.5 * (moves[k, 0, 0] + moves[k, 1, 0])
        cp[1, k] += 0.5 * (moves[k, 0, 1] + moves[k, 1, 1])
        if not (bounds[0] <= cp[0, k] < bounds[1] and bounds[2] <= cp[1, k] < bounds[3]):
            out = k
    if out >= 0:
        S.status[0] = STATUS_CRACK_LEFT_GRID
        S.status[1] = out


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True)
def crack_lists(P, G, C, K, S):
    """Rebuild the crack lists for the current planes (``build_crack_lists``); the
    previous crack nodes are kept for ``clear_crack_nodes``."""
    n_old = K.nlist[N_CNODES]
    K.cnodes_old[:n_old] = K.cnodes[:n_old]
    K.nlist[N_CNODES_OLD] = n_old
    chords, cxy, cnodes = build_crack_lists(K.cp, K.cfirst, K.clast, K.cext0, K.cext1, K.ccrack,
                                            G.geom, K.ncx, K.ncy, int(G.geom[4]), K.nslot,
                                            K.cstart, K.cnear, K.cbox)
    if chords.size > K.chords.size:
        S.status[0] = STATUS_CRACK_LISTS_FULL
        S.status[1] = chords.size
        return
    K.chords[:chords.size] = chords
    K.cxy[:chords.size] = cxy
    K.cnodes[:cnodes.size] = cnodes
    K.nlist[N_CHORDS] = chords.size
    K.nlist[N_CNODES] = cnodes.size
