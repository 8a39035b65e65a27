"""The explicit MPM time step for scenes with cracks (CRAMP), as Numba kernels.

A template like ``step_kernels``: ``kernel_build`` writes a copy whose base import
names the scene's generated step module (its materials and shape functions) and
whose traction import is a dispatcher over the scene's traction-law envelopes.
Scenes without cracks never load it, so they keep the fused no-crack step.

What a crack adds to the step (shared notes CRAMP.md, JINTEGRAL.md section 7):

* every node has ``NF`` velocity fields: 0 = particles on the node's side of every
  crack, 1 = across the crack in the node's slot 0, 2 = across the crack in slot 1,
  3 = across both (``NF`` is 2 when the scene has one crack).  A node's slots are the
  two lowest-numbered cracks with a chord near it, so field choice is the same on
  every thread.  Each particle's field at each of its nodes (``vfld``) is found
  once per step by the CRAMP line-crossing test and reused by every pass;
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
  then the crack lists per cell are rebuilt for the next particle pass.

Grid damping, particle damping, boundary conditions and symmetry planes act on every
field as on the single field of a scene without cracks.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from nairnmpm_py.core.step_kernels import KIND, NA, FAST, USF, USL, STATUS_OK, STATUS_NONFINITE, STATUS_LEFT_GRID, STATUS_RUNAWAY, bc_active, bc_value, node_x, node_y, particle_rotation, face_node, _stress_update, _stress_updates, _store_weights  # KERNEL-BASE
from nairnmpm_py.traction.dispatch_default import traction_envelope  # KERNEL-TRACTION
from nairnmpm_py.cracks.crossing import segment_crossing_side
from nairnmpm_py.cracks.chords import _chord, _chord_cells

STATUS_CRACK_LEFT_GRID = 4

# rows of one velocity field
GM, GPX, GPY, GFX, GFY, GUX, GUY, GNX, GNY, GSD = 0, 1, 2, 3, 4, 5, 6, 7, 8, 9
NR = 10
# a particle's nodes are within two cells of its cell, and a node has a crack slot
# when a cell next to it lists a chord: particles farther than this from every
# listed cell touch no crack node
NEAR_CELLS = 2
NUDGE = 1e-4  # cells: a crack surface is tested from just off the plane, on its side

# counters (``ccount``): pairs whose crack is not in the node's slots, surfaces with
# no field on either side, failed traction particles, blocked crack moves
C_CONFLICT, C_LOST, C_FAILED, C_BLOCKED = 0, 1, 2, 3


# ---- field choice -------------------------------------------------------------------
@njit(cache=True, inline="always")
def _pair_field(x, y, xn, yn, node, cell, cstart, chords, cxy, cpx, cpy, cfirst, clast, cext0,
                cext1, ccrack, nslot, nf):
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


# ---- particles -> grid ----------------------------------------------------------------
# Fields 1-3 and the contact rows (displacement, normal, side) exist only at crack
# nodes (nodes with a slot, ``cnodes``).  Their chunk-buffer entries are read and
# zeroed by the reductions, so they never need clearing; ``g`` keeps them zero away
# from the current crack nodes (``clear_crack_nodes``).  A particle in a cell with no
# chord within two cells (``cnear`` 0) touches no crack node: it takes the no-crack
# path (field 0, no crossing tests, ``cut`` 0).

@njit(cache=True, inline="always")
def _scatter_particle(p, buf, pos, pos0, vel, mass, geom, wij, wc, vfld, cut, nnx, ncx, ncy,
                      cstart, chords, cxy, cnear, cpx, cpy, cfirst, clast, cext0, cext1, ccrack,
                      nslot, nf, use_position, conflicts):
    """Field choice at each node of particle p, then its mass and momentum (and at crack
    nodes its displacement or position, and for crossed pairs the crack normal and
    side) onto the grid."""
    r = wc[p]
    i0 = wij[p, 0]
    j0 = wij[p, 1]
    m = mass[p]
    x = pos[0, p]
    y = pos[1, p]
    mvx = m * vel[0, p]
    mvy = m * vel[1, p]
    cell = _cell_of(x, y, geom, ncx, ncy)
    if cnear[cell] == 0:
        cut[p] = 0
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
    if use_position:
        mux = m * x
        muy = m * y
    else:
        mux = m * (x - pos0[0, p])
        muy = m * (y - pos0[1, p])
    has_chords = cstart[1, cell] > cstart[0, cell]
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
                f, k0, s0, k1, s1, bad = _pair_field(x, y, xn, yn, k, cell, cstart, chords, cxy,
                                                     cpx, cpy, cfirst, clast, cext0, cext1,
                                                     ccrack, nslot, nf)
                conflicts += bad
                w = s * m
                if k0 >= 0:
                    ex = cpx[k0 + 1] - cpx[k0]
                    ey = cpy[k0 + 1] - cpy[k0]
                    el = math.sqrt(ex * ex + ey * ey)
                    buf[1, GNX, k] += w * ey / el   # (dy, -dx): toward the below side
                    buf[1, GNY, k] -= w * ex / el
                    buf[1, GSD, k] += w * s0
                if k1 >= 0:
                    ex = cpx[k1 + 1] - cpx[k1]
                    ey = cpy[k1 + 1] - cpy[k1]
                    el = math.sqrt(ex * ex + ey * ey)
                    buf[2, GNX, k] += w * ey / el
                    buf[2, GNY, k] -= w * ex / el
                    buf[2, GSD, k] += w * s1
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


@njit(cache=True, parallel=True, fastmath=FAST, error_model="numpy")
def weights_and_mass(pos, pos0, vel, mass, lp, geom, wij, wc, vfld, cut, gbuf, nch, ncx, ncy,
                     cstart, chords, cxy, cnear, cpx, cpy, cfirst, clast, cext0, cext1, ccrack,
                     nslot, nf, use_position, counts):
    n = pos.shape[1]
    nnx = int(geom[4])
    idx = 1.0 / geom[2]
    idy = 1.0 / geom[3]
    for c in prange(nch):
        buf = gbuf[c]
        buf[0, GM] = 0.0
        buf[0, GPX] = 0.0
        buf[0, GPY] = 0.0
        lo = c * n // nch
        hi = (c + 1) * n // nch
        conflicts = 0
        for p in range(lo, hi):
            _store_weights(p, pos, lp, geom, idx, idy, wij, wc)
            conflicts = _scatter_particle(p, buf, pos, pos0, vel, mass, geom, wij, wc, vfld,
                                          cut, nnx, ncx, ncy, cstart, chords, cxy, cnear, cpx, cpy,
                                          cfirst, clast, cext0, cext1, ccrack, nslot, nf,
                                          use_position, conflicts)
        counts[c] = conflicts


@njit(cache=True, parallel=True, fastmath=FAST, error_model="numpy")
def reduce_extrapolation(gbuf, g, gv, nch, cnodes):
    """Sum the chunks' extrapolated rows: field 0's mass and momentum everywhere, the
    rest at the crack nodes (zeroing those buffer entries); velocities."""
    nf = g.shape[0]
    nn = g.shape[2]
    for k in prange(nn):
        m = 0.0
        px = 0.0
        py = 0.0
        for c in range(nch):
            m += gbuf[c, 0, GM, k]
            px += gbuf[c, 0, GPX, k]
            py += gbuf[c, 0, GPY, k]
        g[0, GM, k] = m
        g[0, GPX, k] = px
        g[0, GPY, k] = py
        if m > 0.0:
            gv[0, 0, k] = px / m
            gv[0, 1, k] = py / m
        else:
            gv[0, 0, k] = 0.0
            gv[0, 1, k] = 0.0
    for q in range(cnodes.size):
        k = cnodes[q]
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


@njit(cache=True, error_model="numpy")
def clear_crack_nodes(g, gv, ga, gvn, cnodes):
    """Zero fields 1-3 and the contact rows at the crack nodes before the cracks move
    and the crack nodes change, so away from crack nodes those stay zero."""
    nf = g.shape[0]
    for q in range(cnodes.size):
        k = cnodes[q]
        for f in range(nf):
            for row in range(g.shape[1]):
                if f == 0 and row <= GFY:
                    continue
                g[f, row, k] = 0.0
            if f > 0:
                for d in range(2):
                    gv[f, d, k] = 0.0
                    ga[f, d, k] = 0.0
                    gvn[f, d, k] = 0.0


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


# ---- conditions on every field ----------------------------------------------------------
@njit(cache=True, error_model="numpy")
def momentum_conditions(g, gv, geom, gbc_node, gbc_dir, gbc_rec, rec_style, rec_value, rec_t0,
                        rec_ftime, sym_out, sym_in, sym_dir, t):
    nf = g.shape[0]
    for q in range(gbc_node.size):
        r = gbc_rec[q]
        if bc_active(rec_style[r], rec_t0[r], t):
            for f in range(nf):
                g[f, GPX + gbc_dir[q], gbc_node[q]] = 0.0
    for q in range(gbc_node.size):
        r = gbc_rec[q]
        if bc_active(rec_style[r], rec_t0[r], t):
            k = gbc_node[q]
            v = bc_value(r, rec_style[r], rec_value[r], rec_t0[r], rec_ftime[r], t,
                         node_x(k, geom), node_y(k, geom), 0.0)
            for f in range(nf):
                g[f, GPX + gbc_dir[q], k] += g[f, GM, k] * v
    for q in range(sym_out.size):
        ko = sym_out[q]
        ki = sym_in[q]
        d = sym_dir[q]
        for f in range(nf):
            fi = f if g[f, GM, ki] > 0.0 else 0
            if g[fi, GM, ki] > 0.0:
                g[f, GPX + d, ko] = -g[f, GM, ko] * g[fi, GPX + d, ki] / g[fi, GM, ki]
            else:
                g[f, GPX + d, ko] = 0.0
    for q in range(gbc_node.size):
        k = gbc_node[q]
        for f in range(nf):
            m = g[f, GM, k]
            gv[f, 0, k] = g[f, GPX, k] / m if m > 0.0 else 0.0
            gv[f, 1, k] = g[f, GPY, k] / m if m > 0.0 else 0.0
    for q in range(sym_out.size):
        k = sym_out[q]
        for f in range(nf):
            m = g[f, GM, k]
            gv[f, 0, k] = g[f, GPX, k] / m if m > 0.0 else 0.0
            gv[f, 1, k] = g[f, GPY, k] / m if m > 0.0 else 0.0


@njit(cache=True, error_model="numpy")
def velocity_conditions_after(g, geom, ga, gvn, gtmp, gbc_node, gbc_dir, gbc_rec, rec_style,
                              rec_value, rec_t0, rec_ftime, rec_force, rec_work,
                              sym_out, sym_in, sym_dir, t, dt):
    """v(t+dt) on conditioned nodes in every field; the summed change of force is the
    reaction."""
    nf = g.shape[0]
    for q in range(gbc_node.size):
        r = gbc_rec[q]
        if bc_active(rec_style[r], rec_t0[r], t):
            gtmp[gbc_dir[q], gbc_node[q]] = 0.0
    for q in range(gbc_node.size):
        r = gbc_rec[q]
        if bc_active(rec_style[r], rec_t0[r], t):
            k = gbc_node[q]
            gtmp[gbc_dir[q], k] += bc_value(r, rec_style[r], rec_value[r], rec_t0[r],
                                            rec_ftime[r], t + dt, node_x(k, geom),
                                            node_y(k, geom), 0.0)
    for q in range(gbc_node.size):
        r = gbc_rec[q]
        if not bc_active(rec_style[r], rec_t0[r], t):
            continue
        k = gbc_node[q]
        d = gbc_dir[q]
        v_new = gtmp[d, k]
        for f in range(nf):
            m = g[f, GM, k]
            if m <= 0.0:
                continue
            v_old = g[f, GPX + d, k] / m
            f_needed = m * (v_new - v_old) / dt
            reaction = f_needed - g[f, GFX + d, k]
            g[f, GFX + d, k] = f_needed
            ga[f, d, k] = f_needed / m
            gvn[f, d, k] = v_new
            rec_force[r] += reaction
            rec_work[r] += reaction * 0.5 * (v_old + v_new) * dt
    for q in range(sym_out.size):
        ko = sym_out[q]
        ki = sym_in[q]
        d = sym_dir[q]
        for f in range(nf):
            m = g[f, GM, ko]
            if m > 0.0:
                fi = f if g[f, GM, ki] > 0.0 else 0
                v_new = -gvn[fi, d, ki]
                v_old = g[f, GPX + d, ko] / m
                gvn[f, d, ko] = v_new
                ga[f, d, ko] = (v_new - v_old) / dt


# ---- forces ------------------------------------------------------------------------------
@njit(cache=True, error_model="numpy")
def scatter_loads(pos, lp, F, geom, g, wij, wc, vfld, cut, pbc_part, pbc_dir, pbc_scale, pbc_face, pbc_rec,
                  rec_style, rec_value, rec_t0, rec_ftime, rec_force, t, pload):
    nnx = int(geom[4])
    for q in range(pbc_part.size):
        r = pbc_rec[q]
        p = pbc_part[q]
        f = pbc_scale[q] * bc_value(r, rec_style[r], rec_value[r], rec_t0[r], rec_ftime[r], t,
                                    pos[0, p], pos[1, p], particle_rotation(F, p))
        pload[q] = f
        rec_force[r] += f
        row_c = GFX + pbc_dir[q]
        if pbc_face[q] > 0:
            # a traction: on the face's nodes that have mass, in the field the particle
            # uses at that node (field 0 outside its nodes)
            for m in range(8):
                i, j, sw = face_node(pos, lp, F, geom, g.shape[2] // nnx, p, pbc_face[q], m)
                pa = i - wij[p, 0]
                pb = j - wij[p, 1]
                fld = 0
                if cut[p] and 0 <= pa < NA and 0 <= pb < NA:
                    fld = vfld[p, pb * NA + pa]
                if g[fld, GM, j * nnx + i] > 0.0:
                    g[fld, row_c, j * nnx + i] += sw * f
            continue
        w = wc[p]
        for b in range(NA):
            row = (wij[p, 1] + b) * nnx + wij[p, 0]
            for a in range(NA):
                fld = vfld[p, b * NA + a] if cut[p] else 0
                g[fld, row_c, row + a] += w[3 + b] * w[a] * f


@njit(cache=True, parallel=True, fastmath=FAST, error_model="numpy")
def stress_force(mass, vol0, mat, F, stress, hist, w, mat_params, plane_stress, geom, wij, wc,
                 vfld, cut, gv, gbuf, nch, dt_pre, dt_stress, scatter, n):
    """Stress update from each particle's own fields' velocities, internal forces into
    the same fields (particles not cut by a crack: field 0 only, as without cracks)."""
    nnx = int(geom[4])
    gv0 = gv[0]
    for c in prange(nch):
        buf = gbuf[c]
        b0 = buf[0]
        if scatter:
            b0[GFX] = 0.0
            b0[GFY] = 0.0
        lo = c * n // nch
        hi = (c + 1) * n // nch
        for p in range(lo, hi):
            r = wc[p]
            i0 = wij[p, 0]
            j0 = wij[p, 1]
            cp_ = cut[p]
            if dt_stress > 0.0 or dt_pre > 0.0:
                L00 = 0.0
                L01 = 0.0
                L10 = 0.0
                L11 = 0.0
                for b in range(NA):
                    sy = r[3 + b]
                    dy = r[9 + b]
                    row = (j0 + b) * nnx + i0
                    for a in range(NA):
                        k = row + a
                        gx = r[6 + a] * sy
                        gy = r[a] * dy
                        if cp_:
                            f = vfld[p, b * NA + a]
                            vx = gv[f, 0, k]
                            vy = gv[f, 1, k]
                        else:
                            vx = gv0[0, k]
                            vy = gv0[1, k]
                        L00 += vx * gx
                        L01 += vx * gy
                        L10 += vy * gx
                        L11 += vy * gy
                _stress_updates(p, dt_pre, dt_stress, L00, L01, L10, L11, F, stress, hist, w,
                                mat, mat_params, plane_stress)
            if not scatter:
                continue
            vol = vol0[p] * (F[0, p] * F[3, p] - F[1, p] * F[2, p]) * F[4, p]
            sxx = stress[0, p] * vol
            syy = stress[1, p] * vol
            sxy = stress[2, p] * vol
            for b in range(NA):
                sy = r[3 + b]
                dy = r[9 + b]
                row = (j0 + b) * nnx + i0
                for a in range(NA):
                    k = row + a
                    gx = r[6 + a] * sy
                    gy = r[a] * dy
                    if cp_:
                        fb = buf[vfld[p, b * NA + a]]
                        fb[GFX, k] -= sxx * gx + sxy * gy
                        fb[GFY, k] -= sxy * gx + syy * gy
                    else:
                        b0[GFX, k] -= sxx * gx + sxy * gy
                        b0[GFY, k] -= sxy * gx + syy * gy


@njit(cache=True, parallel=True, fastmath=FAST, error_model="numpy")
def reduce_forces(gbuf, g, nch, cnodes):
    """Add the chunks' internal forces: field 0 everywhere, fields 1-3 at the crack
    nodes (zeroing those buffer entries)."""
    nf = g.shape[0]
    nn = g.shape[2]
    for k in prange(nn):
        fx = 0.0
        fy = 0.0
        for c in range(nch):
            fx += gbuf[c, 0, GFX, k]
            fy += gbuf[c, 0, GFY, k]
        g[0, GFX, k] += fx
        g[0, GFY, k] += fy
    for q in range(cnodes.size):
        k = cnodes[q]
        for f in range(1, nf):
            fx = 0.0
            fy = 0.0
            for c in range(nch):
                fx += gbuf[c, f, GFX, k]
                fy += gbuf[c, f, GFY, k]
                gbuf[c, f, GFX, k] = 0.0
                gbuf[c, f, GFY, k] = 0.0
            g[f, GFX, k] += fx
            g[f, GFY, k] += fy


@njit(cache=True, inline="always")
def _accelerate(g, ga, gvn, f, k, dt):
    m = g[f, GM, k]
    if m > 0.0:
        inv = 1.0 / m
        ga[f, 0, k] = g[f, GFX, k] * inv
        ga[f, 1, k] = g[f, GFY, k] * inv
        gvn[f, 0, k] = (g[f, GPX, k] + g[f, GFX, k] * dt) * inv
        gvn[f, 1, k] = (g[f, GPY, k] + g[f, GFY, k] * dt) * inv
    else:
        ga[f, 0, k] = 0.0
        ga[f, 1, k] = 0.0
        gvn[f, 0, k] = 0.0
        gvn[f, 1, k] = 0.0


@njit(cache=True, parallel=True, fastmath=FAST, error_model="numpy")
def accelerations(g, ga, gvn, dt, cnodes):
    nf = g.shape[0]
    nn = g.shape[2]
    for k in prange(nn):
        _accelerate(g, ga, gvn, 0, k, dt)
    for q in range(cnodes.size):
        for f in range(1, nf):
            _accelerate(g, ga, gvn, f, cnodes[q], dt)


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


@njit(cache=True, inline="always")
def _surface_nodes(sx, sy, ux, uy, sgn, geom, ncx, ncy, cstart, chords, cxy, cpx, cpy, cfirst,
                   clast, cext0, cext1, ccrack, nslot, nf, nodes, fields, weights, g, tested):
    """Classic linear shape functions at a crack surface point and the field on the
    surface's side at each of the four nodes; weights are S * m of that field (0 when
    the field is empty).  Returns the sum of the weights."""
    nnx = int(geom[4])
    i0, j0, rx, ry = _surface_cell(sx, sy, geom)
    # test from just off the plane on the surface's own side
    tx_ = sx + sgn * NUDGE * geom[2] * ux
    ty_ = sy + sgn * NUDGE * geom[3] * uy
    cell = _cell_of(tx_, ty_, geom, ncx, ncy)
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
                f, k0, s0, k1, s1, bad = _pair_field(tx_, ty_, xn, yn, node, cell, cstart,
                                                     chords, cxy, cpx, cpy, cfirst, clast, cext0,
                                                     cext1, ccrack, nslot, nf)
                fields[q] = f
                weights[q] = s * g[f, GM, node]
                total += weights[q]
            q += 1
    return total


@njit(cache=True, inline="always")
def _near_crack_end(k, cpx, cpy, ccrack, cfirst, clast, geom):
    """Within 2.5 cells of an end of its crack, where a surface-node line can pass
    beyond the end, so the two surfaces' fields are not mirror images."""
    c = ccrack[k]
    reach = 2.5 * max(geom[2], geom[3])
    for e in (cfirst[c], clast[c]):
        dx = cpx[k] - cpx[e]
        dy = cpy[k] - cpy[e]
        if dx * dx + dy * dy < reach * reach:
            return True
    return False


@njit(cache=True, inline="always")
def _mirror_surface_nodes(sx, sy, geom, crack, nslot, nf, ref_nodes, ref_fields, ref_tested,
                          nodes, fields, weights, g):
    """The second surface of a crack particle away from the crack's ends, when it lies
    in the same cell as the first: each node's field is the first surface's with the
    bit of this crack's slot flipped (the two surfaces sit on opposite sides of their
    own crack and, so close together, on the same side of everything else), which
    saves its crossing tests.
    Returns -1 when that does not apply (another cell, or a node the first surface
    did not test)."""
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
                if nslot[0, node] == crack:
                    f ^= 1
                elif nslot[1, node] == crack:
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
    mirror-surface counterparts (four nodes each)."""
    return (np.empty(4, dtype=np.int64), np.empty(4, dtype=np.int64), np.empty(4),
            np.empty(4, dtype=np.bool_), np.empty(4, dtype=np.int64),
            np.empty(4, dtype=np.int64), np.empty(4, dtype=np.bool_))


@njit(cache=True, inline="always")
def _side_nodes(k, side, sx, sy, ux, uy, sgn, geom, ncx, ncy, cstart, chords, cxy, cpx, cpy,
                cfirst, clast, cext0, cext1, ccrack, nslot, nf, g, nodes, fields, weights,
                tested, ref_nodes, ref_fields, ref_tested):
    """Nodes, fields and weights of one surface of crack particle k: the second surface
    (side 1) mirrors the first where it can, else both run the crossing tests; the
    first surface's result is kept in ``ref_*`` for the second."""
    total = -1.0
    if side == 1 and not _near_crack_end(k, cpx, cpy, ccrack, cfirst, clast, geom):
        total = _mirror_surface_nodes(sx, sy, geom, ccrack[k], nslot, nf, ref_nodes,
                                      ref_fields, ref_tested, nodes, fields, weights, g)
    if total < 0.0:
        total = _surface_nodes(sx, sy, ux, uy, sgn, geom, ncx, ncy, cstart, chords, cxy, cpx, cpy,
                               cfirst, clast, cext0, cext1, ccrack, nslot, nf, nodes, fields,
                               weights, g, tested)
        if side == 0:
            ref_nodes[:] = nodes
            ref_fields[:] = fields
            ref_tested[:] = tested
    return total


@njit(cache=True, error_model="numpy")
def crack_tractions(g, geom, ncx, ncy, cstart, chords, cxy, cp, ca, cb, cfirst, clast, cext0, cext1,
                    ccrack, nslot, claw, cstate, chist, law1, law2, thickness, counts):
    """Traction forces of the law particles on both surfaces' fields (the force is
    shared by S * m, all of it delivered), with history, unloading to the origin and
    failure at delta_c per mode."""
    nf = g.shape[0]
    nodes, fields, weights, tested, ref_nodes, ref_fields, ref_tested = _side_scratch()
    cpx = cp[0]
    cpy = cp[1]
    for k in range(cp.shape[1]):
        law = claw[k]
        if law < 0 or cstate[k] != 1:
            continue
        tx, ty, ux, uy, half = crack_frame(k, cpx, cpy, ccrack, cfirst, clast)
        ddx = ca[0, k] - cb[0, k]
        ddy = ca[1, k] - cb[1, k]
        dn = ddx * ux + ddy * uy
        dt_ = ddx * tx + ddy * ty
        tn = 0.0
        tt = 0.0
        failed = False
        if law1[law, 0] >= 0.0 and dn > 0.0:
            par = law1[law, 1:]
            h = max(chist[0, k], dn)
            chist[0, k] = h
            if h >= par[0]:
                failed = True
            else:
                tn = traction_envelope(int(law1[law, 0]), h, par) / h * dn
        if law2[law, 0] >= 0.0 and dt_ != 0.0:
            par = law2[law, 1:]
            a = abs(dt_)
            h = max(chist[1, k], a)
            chist[1, k] = h
            if h >= par[0]:
                failed = True
            else:
                tt = traction_envelope(int(law2[law, 0]), h, par) / h * dt_
        if failed:
            cstate[k] = 2
            counts[C_FAILED] += 1
            continue
        area = half * thickness
        fx = -area * (tn * ux + tt * tx)
        fy = -area * (tn * uy + tt * ty)
        if fx == 0.0 and fy == 0.0:
            continue
        for side in range(2):
            sgn = 1.0 if side == 0 else -1.0
            sx = ca[0, k] if side == 0 else cb[0, k]
            sy = ca[1, k] if side == 0 else cb[1, k]
            total = _side_nodes(k, side, sx, sy, ux, uy, sgn, geom, ncx, ncy, cstart, chords, cxy,
                                cpx, cpy, cfirst, clast, cext0, cext1, ccrack, nslot, nf, g,
                                nodes, fields, weights, tested, ref_nodes, ref_fields,
                                ref_tested)
            if total <= 0.0:
                continue
            for q in range(4):
                if weights[q] > 0.0:
                    share = sgn * weights[q] / total
                    g[fields[q], GFX, nodes[q]] += share * fx
                    g[fields[q], GFY, nodes[q]] += share * fy


@njit(cache=True, parallel=True, error_model="numpy")
def move_cracks(g, ga, gvn, geom, ncx, ncy, cstart, chords, cxy, cp, ca, cb, cfirst, clast, cext0,
                cext1, ccrack, cfixed, nslot, dt, bounds, counts, nch):
    """Each surface moves with the mean of the old and new velocity of the field on its
    side (mass-weighted, classic shape functions); a side that finds no field copies
    the other; the plane moves with the mean of the two surfaces.  All moves use the
    positions before the step (each crack particle's move is found independently, in
    ``nch`` chunks).  Returns a crack particle that left the grid, or -1."""
    nf = g.shape[0]
    nc = cp.shape[1]
    moves = np.zeros((nc, 2, 2))
    found = np.zeros((nc, 2), dtype=np.bool_)
    blocked = np.zeros(nch, dtype=np.int64)
    limit = 0.5 * min(geom[2], geom[3])
    cpx = cp[0]
    cpy = cp[1]
    for c in prange(nch):
        nodes, fields, weights, tested, ref_nodes, ref_fields, ref_tested = _side_scratch()
        for k in range(c * nc // nch, (c + 1) * nc // nch):
            if cfixed[ccrack[k]]:
                continue
            tx, ty, ux, uy, half = crack_frame(k, cpx, cpy, ccrack, cfirst, clast)
            for side in range(2):
                sgn = 1.0 if side == 0 else -1.0
                sx = ca[0, k] if side == 0 else cb[0, k]
                sy = ca[1, k] if side == 0 else cb[1, k]
                total = _side_nodes(k, side, sx, sy, ux, uy, sgn, geom, ncx, ncy, cstart, chords,
                                    cxy, cpx, cpy, cfirst, clast, cext0, cext1, ccrack, nslot,
                                    nf, g, nodes, fields, weights, tested, ref_nodes,
                                    ref_fields, ref_tested)
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
    counts[C_BLOCKED] += blocked.sum()
    out = -1
    for k in range(nc):
        if cfixed[ccrack[k]]:
            continue
        if not found[k, 0] and not found[k, 1]:
            counts[C_LOST] += 1
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
    return out


# ---- grid -> particles ------------------------------------------------------------------
@njit(cache=True, parallel=True, fastmath=FAST, error_model="numpy")
def update_and_extrapolate(pos, pos0, vel, mass, lp, mat, F, stress, hist, w, mat_params,
                           plane_stress, geom, ga, gvn, dt, dt_stress, damping, pdamp, bounds,
                           vmax, left, bad, wij, wc, vfld, cut, gbuf, nch, ncx, ncy, cstart,
                           chords, cxy, cnear, cpx, cpy, cfirst, clast, cext0, cext1, ccrack, nslot,
                           use_position, counts):
    """Grid -> particles from each particle's own fields, then its new weights, fields
    (crossing the moved cracks) and mass and momentum back to the grid."""
    n = pos.shape[1]
    nnx = int(geom[4])
    nf = gbuf.shape[1]
    idx = 1.0 / geom[2]
    idy = 1.0 / geom[3]
    ga0 = ga[0]
    gvn0 = gvn[0]
    for c in prange(nch):
        buf = gbuf[c]
        buf[0, GM] = 0.0
        buf[0, GPX] = 0.0
        buf[0, GPY] = 0.0
        lo = c * n // nch
        hi = (c + 1) * n // nch
        bad[c, 0] = -1
        conflicts = 0
        for p in range(lo, hi):
            r = wc[p]
            i0 = wij[p, 0]
            j0 = wij[p, 1]
            ax = 0.0
            ay = 0.0
            vx = 0.0
            vy = 0.0
            L00 = 0.0
            L01 = 0.0
            L10 = 0.0
            L11 = 0.0
            cp_ = cut[p]
            for b in range(NA):
                sy = r[3 + b]
                dy = r[9 + b]
                row = (j0 + b) * nnx + i0
                for a in range(NA):
                    k = row + a
                    s = r[a] * sy
                    if cp_:
                        f = vfld[p, b * NA + a]
                        ax += s * ga[f, 0, k]
                        ay += s * ga[f, 1, k]
                        vnx = gvn[f, 0, k]
                        vny = gvn[f, 1, k]
                    else:
                        ax += s * ga0[0, k]
                        ay += s * ga0[1, k]
                        vnx = gvn0[0, k]
                        vny = gvn0[1, k]
                    vx += s * vnx
                    vy += s * vny
                    if dt_stress > 0.0:
                        gx = r[6 + a] * sy
                        gy = r[a] * dy
                        L00 += vnx * gx
                        L01 += vnx * gy
                        L10 += vny * gx
                        L11 += vny * gy
            vmx = vx - ax * dt
            vmy = vy - ay * dt
            dvx = (ax - damping * vmx - pdamp[p] * vel[0, p]) * dt
            dvy = (ay - damping * vmy - pdamp[p] * vel[1, p]) * dt
            nvx = vel[0, p] + dvx
            nvy = vel[1, p] + dvy
            vel[0, p] = nvx
            vel[1, p] = nvy
            x = pos[0, p] + (vmx + 0.5 * dvx) * dt
            y = pos[1, p] + (vmy + 0.5 * dvy) * dt
            if x < bounds[0] or x >= bounds[1] or y < bounds[2] or y >= bounds[3]:
                if left[p] == 0:
                    left[p] = 1
                    bad[c, 2] += 1
                    bad[c, 3] = p
                x = pos[0, p]
                y = pos[1, p]
            pos[0, p] = x
            pos[1, p] = y
            if dt_stress > 0.0:
                _stress_update(p, dt_stress, L00, L01, L10, L11, F, stress, hist, w, mat,
                               mat_params, plane_stress)
            if bad[c, 0] < 0:
                if not (math.isfinite(nvx) and math.isfinite(nvy) and math.isfinite(x)
                        and math.isfinite(y) and math.isfinite(stress[0, p])):
                    bad[c, 0] = p
                    bad[c, 1] = STATUS_NONFINITE
                elif nvx * nvx + nvy * nvy > vmax * vmax:
                    bad[c, 0] = p
                    bad[c, 1] = STATUS_RUNAWAY
            _store_weights(p, pos, lp, geom, idx, idy, wij, wc)
            conflicts = _scatter_particle(p, buf, pos, pos0, vel, mass, geom, wij, wc, vfld,
                                          cut, nnx, ncx, ncy, cstart, chords, cxy, cnear, cpx, cpy,
                                          cfirst, clast, cext0, cext1, ccrack, nslot, nf,
                                          use_position, conflicts)
        counts[c] = conflicts


@njit(cache=True, error_model="numpy")
def _load_work(pos, pbc_part, pbc_dir, pload, pos_before, rec_work, pbc_rec):
    for q in range(pbc_part.size):
        p = pbc_part[q]
        d = pbc_dir[q]
        rec_work[pbc_rec[q]] += pload[q] * (pos[d, p] - pos_before[q])


@njit(cache=True)
def crack_lists(cp, cfirst, clast, cext0, cext1, ccrack, geom, ncx, ncy, nnx, nslot, cstart,
                cnear, cbox):
    """Chords near each cell, the crack slots of every node and the nodes that have
    one (the only nodes where fields can differ), for the current plane.

    Work and writes stay inside the box of cells the chords reach (``cbox``: i0, i1,
    j0, j1, kept between calls so the previous box is cleared first), so the cost
    follows the crack, not the grid.  ``cstart[0, cell]`` to ``cstart[1, cell]`` index
    the cell's chords in the returned ``chords``; every other cell has an empty range.
    ``cxy`` holds each entry's chord end points.
    ``cnear`` marks cells within NEAR_CELLS of a cell with chords; ``nslot`` holds a
    node's two lowest-numbered cracks listed in a cell next to it (-1 none).
    """
    px = cp[0]
    py = cp[1]
    nn = nslot.shape[1]
    nny = nn // nnx
    # clear the previous box (cells with their near margin, nodes of those cells)
    if cbox[0] <= cbox[1]:
        for j in range(max(cbox[2] - NEAR_CELLS, 0), min(cbox[3] + NEAR_CELLS + 1, ncy)):
            for i in range(max(cbox[0] - NEAR_CELLS, 0), min(cbox[1] + NEAR_CELLS + 1, ncx)):
                cell = j * ncx + i
                cstart[0, cell] = 0
                cstart[1, cell] = 0
                cnear[cell] = 0
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
            for jj in range(max(j - NEAR_CELLS, 0), min(j + NEAR_CELLS + 1, ncy)):
                for ii in range(max(i - NEAR_CELLS, 0), min(i + NEAR_CELLS + 1, ncx)):
                    cnear[jj * ncx + ii] = 1
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


@njit(cache=True, error_model="numpy")
def advance(nsteps, t, dt, method, post_extrapolate, plane_stress,
            pos, pos0, vel, mass, vol0, lp, mat, F, stress, hist, w, pdamp, mat_params,
            geom, bounds, g, gbuf, gv, ga, gvn, gtmp, damping, vmax, left, leave_limit,
            gbc_node, gbc_dir, gbc_rec, pbc_part, pbc_dir, pbc_scale, pbc_face, pbc_rec,
            rec_style, rec_value, rec_t0, rec_ftime, rec_force, rec_work,
            sym_out, sym_in, sym_dir, bad, nch,
            cp, ca, cb, cfirst, clast, cext0, cext1, ccrack, cfixed, claw, cstate, chist,
            law1, law2, thickness, use_position, cutoff_cells, vfld, cut, wij, wc, nslot, cstart,
            cnear, cbox, counts, chunk_counts, resume, flush, pend, chords_now, cxy_now,
            cnodes_now):
    """Run up to ``nsteps`` steps of a scene with cracks from time ``t`` (ms).

    Order per step: loads and internal forces into each particle's fields; crack
    tractions; contact after the update; velocity conditions; cracks moved; particles
    updated and extrapolated to the next step's fields (crossing the moved cracks);
    contact on the new momenta; velocity conditions.  Returns (steps done, status,
    offending particle or crack particle, chords, chord ends, crack nodes): the last
    three are the crack lists of the last extrapolation, passed back in for a resumed
    call.

    ``resume``: the previous call's last extrapolation is still current (no crack grew,
    nothing changed), so it is not redone.  ``flush``: apply the carried USAVG+ / USL+
    stress half at the end (needed before stresses or energies are read); otherwise it
    is kept in ``pend`` for the next call.
    """
    n = pos.shape[1]
    nn = g.shape[2]
    nnx = int(geom[4])
    ncx = nnx - 1
    ncy = nn // nnx - 1
    if method == USF:
        dt_first = dt
        dt_last = 0.0
    elif method == USL:
        dt_first = 0.0
        dt_last = dt
    else:
        dt_first = 0.5 * dt
        dt_last = dt - dt_first
    plus = post_extrapolate and dt_last > 0.0
    dt_update = 0.0 if post_extrapolate else dt_last
    cpx = cp[0]
    cpy = cp[1]
    pending = pend[0]
    pend[0] = 0.0
    if resume:
        # the previous call ended with this state's extrapolation and crack lists
        # (``chords_now``, ``cnodes_now``; nothing changed since)
        return _run_steps(nsteps, t, dt, dt_first, dt_last, dt_update, plus, pending, flush,
                          pend, plane_stress, pos, pos0, vel, mass, vol0, lp, mat, F, stress,
                          hist, w, pdamp, mat_params, geom, bounds, g, gbuf, gv, ga, gvn, gtmp,
                          damping, vmax, left, leave_limit, gbc_node, gbc_dir, gbc_rec,
                          pbc_part, pbc_dir, pbc_scale, pbc_face, pbc_rec, rec_style, rec_value, rec_t0,
                          rec_ftime, rec_force, rec_work, sym_out, sym_in, sym_dir, bad, nch,
                          cp, ca, cb, cfirst, clast, cext0, cext1, ccrack, cfixed, claw, cstate,
                          chist, law1, law2, thickness, use_position, cutoff_cells, vfld, cut,
                          wij, wc, nslot, cbox, counts, chunk_counts, cstart, chords_now,
                          cxy_now, cnodes_now, cnear, ncx, ncy, nnx, n)
    chords, cxy, cnodes = crack_lists(cp, cfirst, clast, cext0, cext1, ccrack, geom, ncx, ncy,
                                      nnx, nslot, cstart, cnear, cbox)
    weights_and_mass(pos, pos0, vel, mass, lp, geom, wij, wc, vfld, cut, gbuf, nch, ncx, ncy,
                     cstart, chords, cxy, cnear, cpx, cpy, cfirst, clast, cext0, cext1, ccrack,
                     nslot,
                     g.shape[0], use_position, chunk_counts)
    for c in range(nch):
        counts[C_CONFLICT] += chunk_counts[c]
    reduce_extrapolation(gbuf, g, gv, nch, cnodes)
    contact(g, gv, nslot, cnodes, dt, False, use_position, cutoff_cells, geom)
    momentum_conditions(g, gv, geom, gbc_node, gbc_dir, gbc_rec, rec_style, rec_value, rec_t0,
                        rec_ftime, sym_out, sym_in, sym_dir, t)
    return _run_steps(nsteps, t, dt, dt_first, dt_last, dt_update, plus, pending, flush, pend,
                      plane_stress, pos, pos0, vel, mass, vol0, lp, mat, F, stress, hist, w,
                      pdamp, mat_params, geom, bounds, g, gbuf, gv, ga, gvn, gtmp, damping, vmax,
                      left, leave_limit, gbc_node, gbc_dir, gbc_rec, pbc_part, pbc_dir,
                      pbc_scale, pbc_face, pbc_rec, rec_style, rec_value, rec_t0, rec_ftime, rec_force,
                      rec_work, sym_out, sym_in, sym_dir, bad, nch, cp, ca, cb, cfirst, clast,
                      cext0, cext1, ccrack, cfixed, claw, cstate, chist, law1, law2, thickness,
                      use_position, cutoff_cells, vfld, cut, wij, wc, nslot, cbox, counts,
                      chunk_counts, cstart, chords, cxy, cnodes, cnear, ncx, ncy, nnx, n)


@njit(cache=True, error_model="numpy")
def _run_steps(nsteps, t, dt, dt_first, dt_last, dt_update, plus, pending, flush, pend,
               plane_stress, pos, pos0, vel, mass, vol0, lp, mat, F, stress, hist, w, pdamp,
               mat_params, geom, bounds, g, gbuf, gv, ga, gvn, gtmp, damping, vmax, left,
               leave_limit, gbc_node, gbc_dir, gbc_rec, pbc_part, pbc_dir, pbc_scale, pbc_face, pbc_rec,
               rec_style, rec_value, rec_t0, rec_ftime, rec_force, rec_work, sym_out, sym_in,
               sym_dir, bad, nch, cp, ca, cb, cfirst, clast, cext0, cext1, ccrack, cfixed, claw,
               cstate, chist, law1, law2, thickness, use_position, cutoff_cells, vfld, cut, wij,
               wc, nslot, cbox, counts, chunk_counts, cstart, chords, cxy, cnodes, cnear, ncx, ncy,
               nnx,
               n):
    """The steps themselves, from a current extrapolation.  Without ``flush`` the last
    step's carried USAVG+ stress half is returned in ``pend`` instead of applied."""
    pload = np.zeros(pbc_part.size)
    pos_before = np.zeros(pbc_part.size)
    cpx = cp[0]
    cpy = cp[1]
    for step in range(nsteps):
        rec_force[:] = 0.0
        g[:, GFX] = 0.0
        g[:, GFY] = 0.0
        scatter_loads(pos, lp, F, geom, g, wij, wc, vfld, cut, pbc_part, pbc_dir, pbc_scale, pbc_face, pbc_rec,
                      rec_style, rec_value, rec_t0, rec_ftime, rec_force, t, pload)
        for q in range(pbc_part.size):
            pos_before[q] = pos[pbc_dir[q], pbc_part[q]]
        stress_force(mass, vol0, mat, F, stress, hist, w, mat_params, plane_stress, geom, wij,
                     wc, vfld, cut, gv, gbuf, nch, pending, dt_first, True, n)
        pending = 0.0
        reduce_forces(gbuf, g, nch, cnodes)
        crack_tractions(g, geom, ncx, ncy, cstart, chords, cxy, cp, ca, cb, cfirst, clast, cext0,
                        cext1, ccrack, nslot, claw, cstate, chist, law1, law2, thickness,
                        counts)
        contact(g, gv, nslot, cnodes, dt, True, use_position, cutoff_cells, geom)
        accelerations(g, ga, gvn, dt, cnodes)
        velocity_conditions_after(g, geom, ga, gvn, gtmp, gbc_node, gbc_dir, gbc_rec,
                                  rec_style, rec_value, rec_t0, rec_ftime, rec_force,
                                  rec_work, sym_out, sym_in, sym_dir, t, dt)
        out = move_cracks(g, ga, gvn, geom, ncx, ncy, cstart, chords, cxy, cp, ca, cb, cfirst,
                          clast, cext0, cext1, ccrack, cfixed, nslot, dt, bounds, counts, nch)
        if out >= 0:
            return step + 1, STATUS_CRACK_LEFT_GRID, out, chords, cxy, cnodes
        old_cnodes = cnodes
        chords, cxy, cnodes = crack_lists(cp, cfirst, clast, cext0, cext1, ccrack, geom, ncx, ncy,
                                     nnx, nslot, cstart, cnear, cbox)
        update_and_extrapolate(pos, pos0, vel, mass, lp, mat, F, stress, hist, w, mat_params,
                               plane_stress, geom, ga, gvn, dt, dt_update, damping, pdamp,
                               bounds, vmax, left, bad, wij, wc, vfld, cut, gbuf, nch, ncx,
                               ncy, cstart, chords, cxy, cnear, cpx, cpy, cfirst, clast, cext0,
                               cext1, ccrack, nslot, use_position, chunk_counts)
        for c in range(nch):
            counts[C_CONFLICT] += chunk_counts[c]
        _load_work(pos, pbc_part, pbc_dir, pload, pos_before, rec_work, pbc_rec)
        t += dt
        clear_crack_nodes(g, gv, ga, gvn, old_cnodes)
        reduce_extrapolation(gbuf, g, gv, nch, cnodes)
        contact(g, gv, nslot, cnodes, dt, False, use_position, cutoff_cells, geom)
        momentum_conditions(g, gv, geom, gbc_node, gbc_dir, gbc_rec, rec_style, rec_value,
                            rec_t0, rec_ftime, sym_out, sym_in, sym_dir, t)
        if plus:
            pending = dt_last
        n_left = 0
        stop = -1
        for c in range(nch):
            if bad[c, 0] >= 0:
                stop = c
                break
            n_left += bad[c, 2]
        status = STATUS_OK
        who = -1
        if stop >= 0:
            status = bad[stop, 1]
            who = bad[stop, 0]
        elif n_left >= leave_limit:
            for c in range(nch):
                if bad[c, 2] > 0:
                    status = STATUS_LEFT_GRID
                    who = bad[c, 3]
                    break
        if status != STATUS_OK or step == nsteps - 1:
            if pending > 0.0 and not flush and status == STATUS_OK:
                pend[0] = pending
            elif pending > 0.0:
                stress_force(mass, vol0, mat, F, stress, hist, w, mat_params, plane_stress,
                             geom, wij, wc, vfld, cut, gv, gbuf, nch, 0.0, pending, False, n)
            if status != STATUS_OK:
                return step + 1, status, who, chords, cxy, cnodes
    return nsteps, STATUS_OK, -1, chords, cxy, cnodes
