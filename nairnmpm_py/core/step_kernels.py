"""The explicit MPM time step as fused Numba kernels.

This file is a template as well as a module: ``kernel_build`` copies it into a cache
folder with the ``material_update`` import replaced by a dispatcher over the
materials of one scene and ``KIND`` set to its shape functions, so the stress update
of any material plugin is inlined in the particle loops, the shape function is known
at compile time, and everything stays ``cache=True``.  Imported directly it runs
uGIMP with the isotropic material only.

One step (``advance`` runs many without returning to Python):

1. particle loads onto the grid; stress update from the grid velocities (USF /
   USAVG first half, plus a carried-over USAVG+ / USL+ last half) fused with the
   internal forces back to the grid;
2. forces summed, momenta updated, velocity conditions on the new momenta
   (reactions recorded);
3. grid -> particles: FLIP velocity and position with grid and particle damping (as
   NairnMPM applies them), the USL- / USAVG- stress update, then the particle's new
   weights and its mass and momentum back to the grid for the next step;
4. mass and momentum summed, velocity conditions at the new time.

Particle loops run as fixed chunks, each with its own grid buffer, reduced in a fixed
order: results do not depend on thread scheduling.  ``FAST`` allows reassociation and
fused multiply-adds but keeps NaN and infinity semantics, so blow-ups are still caught.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from nairnmpm_py.core.shape import weights_1d
from nairnmpm_py.core.material_dispatch_default import material_update  # KERNEL-MATERIALS
from nairnmpm_py.core.conditions import no_condition_function as condition_function  # KERNEL-FUNCTIONS

KIND = 1  # KERNEL-SHAPE: 0 classic linear, 1 uGIMP
NA = 2 if KIND == 0 else 3  # nodes per axis a particle touches
FAST = {"contract", "reassoc", "nsz", "arcp", "afn"}

USF = 0
USAVG = 2
USL = 3

STATUS_OK = 0
STATUS_NONFINITE = 1
STATUS_LEFT_GRID = 2
STATUS_RUNAWAY = 3

# grid component rows
GM, GPX, GPY, GFX, GFY = 0, 1, 2, 3, 4


@njit(cache=True, inline="always")
def bc_active(style, t0, t):
    """Constant and ramp conditions start at t0 (node free before); sine and
    cosine act from t = 0, as NairnMPM does."""
    if style == 1 or style == 2:
        return t >= t0
    return True


@njit(cache=True, inline="always")
def bc_value(r, style, value, t0, ftime, t, x, y, q):
    """Value of boundary condition record r at time t (ms).

    style 1 constant, 2 linear ramp value*(t - t0) (value per ms),
    3 value*sin(ftime*t), 4 value*cos(ftime*t) (ftime in rad/ms), 6 value times the
    record's expression of t - t0 (ms; zero before t0), of the position x, y (mm) of
    the node or particle and of the particle's rotation q (radians).
    """
    if style == 1:
        return value if t >= t0 else 0.0
    if style == 2:
        return value * (t - t0) if t >= t0 else 0.0
    if style == 3:
        return value * math.sin(ftime * t)
    if style == 4:
        return value * math.cos(ftime * t)
    if style == 6:
        return value * condition_function(r, t - t0, x, y, q) if t >= t0 else 0.0
    return 0.0


@njit(cache=True, inline="always")
def node_x(k, geom):
    return geom[0] + (k % int(geom[4])) * geom[2]


@njit(cache=True, inline="always")
def node_y(k, geom):
    return geom[1] + (k // int(geom[4])) * geom[3]


@njit(cache=True, inline="always")
def particle_rotation(F, p):
    """Rotation (radians, counter-clockwise) of the polar decomposition of F."""
    return math.atan2(F[2, p] - F[1, p], F[0, p] + F[3, p])


@njit(cache=True, inline="always")
def face_corner(pos, lp, F, geom, p, face, corner):
    """Corner 0 or 1 of face ``face`` (1 bottom, 2 right, 3 top, 4 left) of particle p,
    its half-widths turned and stretched by F (NairnMPM loads the deformed face)."""
    hx = lp[0, p] * geom[2]
    hy = lp[1, p] * geom[3]
    s = 1.0 if corner == 1 else -1.0
    if face == 1:
        ox, oy = s * hx, -hy
    elif face == 2:
        ox, oy = hx, s * hy
    elif face == 3:
        ox, oy = s * hx, hy
    else:
        ox, oy = -hx, s * hy
    return (pos[0, p] + F[0, p] * ox + F[1, p] * oy, pos[1, p] + F[2, p] * ox + F[3, p] * oy)


@njit(cache=True, inline="always")
def face_node(pos, lp, F, geom, nny, p, face, m):
    """(column, row, weight) of the m-th (0-7) node a traction on face ``face`` of
    particle p loads: node m % 4 of the cell holding corner m // 4, with half the
    corner's linear weight there (the eight weights add up to 1).  The cell is kept
    inside the grid of nny node rows."""
    cx, cy = face_corner(pos, lp, F, geom, p, face, m // 4)
    xi = (cx - geom[0]) / geom[2]
    eta = (cy - geom[1]) / geom[3]
    i = min(max(int(math.floor(xi)), 0), int(geom[4]) - 2)
    j = min(max(int(math.floor(eta)), 0), nny - 2)
    fx = min(max(xi - i, 0.0), 1.0)
    fy = min(max(eta - j, 0.0), 1.0)
    a = m % 2
    b = (m // 2) % 2
    return i + a, j + b, 0.5 * (fx if a == 1 else 1.0 - fx) * (fy if b == 1 else 1.0 - fy)


@njit(cache=True, error_model="numpy")
def _scatter_loads(pos, lp, F, geom, g, pbc_part, pbc_dir, pbc_scale, pbc_face, pbc_rec,
                   rec_style, rec_value, rec_t0, rec_ftime, rec_force, t, pload):
    """Particle loads (N) at time t onto the grid; pload keeps them for the work."""
    nnx = int(geom[4])
    na = NA
    for q in range(pbc_part.size):
        r = pbc_rec[q]
        p = pbc_part[q]
        f = pbc_scale[q] * bc_value(r, rec_style[r], rec_value[r], rec_t0[r], rec_ftime[r], t,
                                    pos[0, p], pos[1, p], particle_rotation(F, p))
        pload[q] = f
        rec_force[r] += f
        row_c = GFX + pbc_dir[q]
        if pbc_face[q] > 0:
            # a traction: on the face's nodes that have mass
            for m in range(8):
                i, j, sw = face_node(pos, lp, F, geom, g.shape[1] // nnx, p, pbc_face[q], m)
                if g[GM, j * nnx + i] > 0.0:
                    g[row_c, j * nnx + i] += sw * f
            continue
        xi = (pos[0, p] - geom[0]) / geom[2]
        eta = (pos[1, p] - geom[1]) / geom[3]
        i0, sx0, sx1, sx2, dx0, dx1, dx2 = weights_1d(xi, KIND, lp[0, p])
        j0, sy0, sy1, sy2, dy0, dy1, dy2 = weights_1d(eta, KIND, lp[1, p])
        for b in range(na):
            sy = sy0 if b == 0 else (sy1 if b == 1 else sy2)
            row = (j0 + b) * nnx + i0
            for a in range(na):
                s = sy * (sx0 if a == 0 else (sx1 if a == 1 else sx2))
                g[row_c, row + a] += s * f


@njit(cache=True, error_model="numpy")
def _momentum_conditions(g, geom, gbc_node, gbc_dir, gbc_rec, rec_style, rec_value, rec_t0,
                         rec_ftime, sym_out, sym_in, sym_dir, t):
    """Impose velocity conditions on the extrapolated momenta.

    Several conditions on one node and direction add up (zero first, then add).
    Nodes just outside a symmetry plane mirror the normal velocity of the node
    inside it."""
    for q in range(gbc_node.size):
        r = gbc_rec[q]
        if bc_active(rec_style[r], rec_t0[r], t):
            g[GPX + gbc_dir[q], gbc_node[q]] = 0.0
    for q in range(gbc_node.size):
        r = gbc_rec[q]
        if bc_active(rec_style[r], rec_t0[r], t):
            k = gbc_node[q]
            v = bc_value(r, rec_style[r], rec_value[r], rec_t0[r], rec_ftime[r], t,
                         node_x(k, geom), node_y(k, geom), 0.0)
            g[GPX + gbc_dir[q], k] += g[GM, k] * v
    for q in range(sym_out.size):
        ko = sym_out[q]
        ki = sym_in[q]
        d = sym_dir[q]
        if g[GM, ki] > 0.0:
            g[GPX + d, ko] = -g[GM, ko] * g[GPX + d, ki] / g[GM, ki]
        else:
            g[GPX + d, ko] = 0.0


@njit(cache=True, inline="always")
def _increment_exp(L00, L01, L10, L11, dt):
    """exp(L dt) of a 2x2 velocity gradient: exact for rigid rotations, so no spurious
    volume change."""
    a = L00 * dt
    b = L01 * dt
    c = L10 * dt
    d = L11 * dt
    half = 0.5 * (a + d)
    disc = 0.25 * (a - d) * (a - d) + b * c
    # cosh(sqrt(disc)) and sinh(sqrt(disc))/sqrt(disc) (cos, sin for disc < 0) as their
    # series in disc: exact to rounding for |disc| < 1e-4 (next term < 1e-20), which is
    # every step of a stable explicit run; the libm calls only for large increments
    if abs(disc) < 1e-4:
        ch = 1.0 + disc * (0.5 + disc * (1.0 / 24.0 + disc * (1.0 / 720.0)))
        sh = 1.0 + disc * (1.0 / 6.0 + disc * (1.0 / 120.0 + disc * (1.0 / 5040.0)))
    elif disc > 0.0:
        q = math.sqrt(disc)
        ch = math.cosh(q)
        sh = math.sinh(q) / q
    else:
        q = math.sqrt(-disc)
        ch = math.cos(q)
        sh = math.sin(q) / q
    if abs(half) < 1e-3:
        e = 1.0 + half * (1.0 + half * (0.5 + half * (1.0 / 6.0 + half * (1.0 / 24.0 + half * (1.0 / 120.0)))))
    else:
        e = math.exp(half)
    return e * (ch + sh * (a - half)), e * sh * b, e * sh * c, e * (ch + sh * (d - half))


@njit(cache=True, inline="always")
def _apply_increment(p, e00, e01, e10, e11, F):
    f00 = F[0, p]
    f01 = F[1, p]
    f10 = F[2, p]
    f11 = F[3, p]
    F[0, p] = e00 * f00 + e01 * f10
    F[1, p] = e00 * f01 + e01 * f11
    F[2, p] = e10 * f00 + e11 * f10
    F[3, p] = e10 * f01 + e11 * f11


@njit(cache=True, inline="always")
def _stress_update(p, dt, L00, L01, L10, L11, F, stress, hist, w, mat, mat_params,
                   plane_stress):
    e00, e01, e10, e11 = _increment_exp(L00, L01, L10, L11, dt)
    _apply_increment(p, e00, e01, e10, e11, F)
    m = mat[p]
    material_update(m, p, dt, L00, L01, L10, L11, F, stress, hist, w, mat_params[m],
                    plane_stress)


@njit(cache=True, inline="always")
def _stress_updates(p, dt_pre, dt_stress, L00, L01, L10, L11, F, stress, hist, w, mat,
                    mat_params, plane_stress):
    """The stress updates of one particle's stress pass with one velocity gradient: a
    carried-over USAVG+ / USL+ update of dt_pre, then this step's of dt_stress (either
    may be 0).  USAVG+ has dt_pre = dt_stress = dt/2, so the increment exponential is
    found once and applied twice (the same numbers as two separate updates)."""
    if dt_pre == dt_stress and dt_pre > 0.0:
        e00, e01, e10, e11 = _increment_exp(L00, L01, L10, L11, dt_pre)
        m = mat[p]
        _apply_increment(p, e00, e01, e10, e11, F)
        material_update(m, p, dt_pre, L00, L01, L10, L11, F, stress, hist, w, mat_params[m],
                        plane_stress)
        _apply_increment(p, e00, e01, e10, e11, F)
        material_update(m, p, dt_pre, L00, L01, L10, L11, F, stress, hist, w, mat_params[m],
                        plane_stress)
        return
    if dt_pre > 0.0:
        _stress_update(p, dt_pre, L00, L01, L10, L11, F, stress, hist, w, mat, mat_params,
                       plane_stress)
    if dt_stress > 0.0:
        _stress_update(p, dt_stress, L00, L01, L10, L11, F, stress, hist, w, mat, mat_params,
                       plane_stress)


@njit(cache=True, error_model="numpy")
def _velocity_conditions_after(g, geom, ga, gvn, gtmp, gbc_node, gbc_dir, gbc_rec, rec_style,
                               rec_value, rec_t0, rec_ftime, rec_force, rec_work,
                               sym_out, sym_in, sym_dir, t, dt, mass_tol):
    """Impose v(t+dt) on conditioned nodes; the force that takes is the reaction."""
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
        k = gbc_node[q]
        d = gbc_dir[q]
        m = g[GM, k]
        if m <= mass_tol or not bc_active(rec_style[r], rec_t0[r], t):
            continue
        v_new = gtmp[d, k]
        v_old = g[GPX + d, k] / m
        f_needed = m * (v_new - v_old) / dt
        # a node shared by several conditions credits its reaction to the first one
        reaction = f_needed - g[GFX + d, k]
        g[GFX + d, k] = f_needed
        ga[d, k] = f_needed / m
        gvn[d, k] = v_new
        rec_force[r] += reaction
        rec_work[r] += reaction * 0.5 * (v_old + v_new) * dt
    for q in range(sym_out.size):
        ko = sym_out[q]
        d = sym_dir[q]
        m = g[GM, ko]
        if m > mass_tol:
            v_new = -gvn[d, sym_in[q]]
            v_old = g[GPX + d, ko] / m
            gvn[d, ko] = v_new
            ga[d, ko] = (v_new - v_old) / dt


@njit(cache=True, error_model="numpy")
def _load_work(pos, pbc_part, pbc_dir, pload, pos_before, rec_work, pbc_rec):
    for q in range(pbc_part.size):
        p = pbc_part[q]
        d = pbc_dir[q]
        rec_work[pbc_rec[q]] += pload[q] * (pos[d, p] - pos_before[q])



# ---- cached weights ------------------------------------------------------------------
# wc[p] = (sx0, sx1, sx2, sy0, sy1, sy2, gx0, gx1, gx2, gy0, gy1, gy2) with the
# derivatives already divided by the cell size; wij[p] = (i0, j0)


@njit(cache=True, inline="always")
def _store_weights(p, pos, lp, geom, idx, idy, wij, wc):
    xi = (pos[0, p] - geom[0]) * idx
    eta = (pos[1, p] - geom[1]) * idy
    i0, sx0, sx1, sx2, dx0, dx1, dx2 = weights_1d(xi, KIND, lp[0, p])
    j0, sy0, sy1, sy2, dy0, dy1, dy2 = weights_1d(eta, KIND, lp[1, p])
    wij[p, 0] = i0
    wij[p, 1] = j0
    r = wc[p]
    r[0] = sx0
    r[1] = sx1
    r[2] = sx2
    r[3] = sy0
    r[4] = sy1
    r[5] = sy2
    r[6] = dx0 * idx
    r[7] = dx1 * idx
    r[8] = dx2 * idx
    r[9] = dy0 * idy
    r[10] = dy1 * idy
    r[11] = dy2 * idy


@njit(cache=True, parallel=True, fastmath=FAST, error_model="numpy")
def _weights_and_mass(pos, vel, mass, lp, geom, wij, wc, gbuf, nch):
    """Weights of every particle (cached) and their mass and momentum on the grid."""
    n = pos.shape[1]
    nnx = int(geom[4])
    idx = 1.0 / geom[2]
    idy = 1.0 / geom[3]
    for c in prange(nch):
        buf = gbuf[c]
        buf[:] = 0.0
        lo = c * n // nch
        hi = (c + 1) * n // nch
        for p in range(lo, hi):
            _store_weights(p, pos, lp, geom, idx, idy, wij, wc)
            r = wc[p]
            m = mass[p]
            mvx = m * vel[0, p]
            mvy = m * vel[1, p]
            for b in range(NA):
                sy = r[3 + b]
                row = (wij[p, 1] + b) * nnx + wij[p, 0]
                for a in range(NA):
                    s = sy * r[a]
                    k = row + a
                    buf[GM, k] += s * m
                    buf[GPX, k] += s * mvx
                    buf[GPY, k] += s * mvy


@njit(cache=True, parallel=True, fastmath=FAST, error_model="numpy")
def _reduce_velocity(gbuf, g, gv, mass_tol, nch):
    """Sum the chunks' mass and momentum and the grid velocities (before conditions)."""
    nn = g.shape[1]
    for k in prange(nn):
        m = 0.0
        px = 0.0
        py = 0.0
        for c in range(nch):
            m += gbuf[c, GM, k]
            px += gbuf[c, GPX, k]
            py += gbuf[c, GPY, k]
        g[GM, k] = m
        g[GPX, k] = px
        g[GPY, k] = py
        if m > mass_tol:
            gv[0, k] = px / m
            gv[1, k] = py / m
        else:
            gv[0, k] = 0.0
            gv[1, k] = 0.0


@njit(cache=True, error_model="numpy")
def _velocity_at(g, gv, nodes, mass_tol):
    for q in range(nodes.size):
        k = nodes[q]
        m = g[GM, k]
        if m > mass_tol:
            gv[0, k] = g[GPX, k] / m
            gv[1, k] = g[GPY, k] / m
        else:
            gv[0, k] = 0.0
            gv[1, k] = 0.0


@njit(cache=True, parallel=True, fastmath=FAST, error_model="numpy")
def _stress_force_cached(mass, vol0, mat, F, stress, hist, w, mat_params, plane_stress,
                         geom, wij, wc, gv, gbuf, nch, dt_pre, dt_stress, scatter, n):
    nnx = int(geom[4])
    for c in prange(nch):
        buf = gbuf[c]
        if scatter:
            buf[GFX] = 0.0
            buf[GFY] = 0.0
        lo = c * n // nch
        hi = (c + 1) * n // nch
        for p in range(lo, hi):
            r = wc[p]
            i0 = wij[p, 0]
            j0 = wij[p, 1]
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
                        L00 += gv[0, k] * gx
                        L01 += gv[0, k] * gy
                        L10 += gv[1, k] * gx
                        L11 += gv[1, k] * gy
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
                    buf[GFX, k] -= sxx * gx + sxy * gy
                    buf[GFY, k] -= sxy * gx + syy * gy


@njit(cache=True, parallel=True, fastmath=FAST, error_model="numpy")
def _forces_update(gbuf, g, ga, gvn, dt, mass_tol, nch):
    nn = g.shape[1]
    for k in prange(nn):
        fx = 0.0
        fy = 0.0
        for c in range(nch):
            fx += gbuf[c, GFX, k]
            fy += gbuf[c, GFY, k]
        fx = g[GFX, k] + fx
        fy = g[GFY, k] + fy
        g[GFX, k] = fx
        g[GFY, k] = fy
        m = g[GM, k]
        if m > mass_tol:
            ga[0, k] = fx / m
            ga[1, k] = fy / m
            gvn[0, k] = (g[GPX, k] + fx * dt) / m
            gvn[1, k] = (g[GPY, k] + fy * dt) / m
        else:
            ga[0, k] = 0.0
            ga[1, k] = 0.0
            gvn[0, k] = 0.0
            gvn[1, k] = 0.0


@njit(cache=True, parallel=True, fastmath=FAST, error_model="numpy")
def _update_and_extrapolate(pos, vel, mass, lp, mat, F, stress, hist, w, mat_params,
                            plane_stress, geom, ga, gvn, dt, dt_stress, damping,
                            pdamp, bounds, vmax, left, bad, wij, wc, gbuf, nch):
    """Grid -> particles (FLIP, positions), then the particles' new weights and their
    mass and momentum back to the grid (the next extrapolation)."""
    n = pos.shape[1]
    nnx = int(geom[4])
    idx = 1.0 / geom[2]
    idy = 1.0 / geom[3]
    for c in prange(nch):
        buf = gbuf[c]
        buf[GM] = 0.0
        buf[GPX] = 0.0
        buf[GPY] = 0.0
        lo = c * n // nch
        hi = (c + 1) * n // nch
        bad[c, 0] = -1
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
            for b in range(NA):
                sy = r[3 + b]
                dy = r[9 + b]
                row = (j0 + b) * nnx + i0
                for a in range(NA):
                    k = row + a
                    s = r[a] * sy
                    ax += s * ga[0, k]
                    ay += s * ga[1, k]
                    vnx = gvn[0, k]
                    vny = gvn[1, k]
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
            # the next extrapolation, from the new position and velocity
            _store_weights(p, pos, lp, geom, idx, idy, wij, wc)
            m = mass[p]
            mvx = m * nvx
            mvy = m * nvy
            i0 = wij[p, 0]
            j0 = wij[p, 1]
            for b in range(NA):
                sy = r[3 + b]
                row = (j0 + b) * nnx + i0
                for a in range(NA):
                    s = sy * r[a]
                    k = row + a
                    buf[GM, k] += s * m
                    buf[GPX, k] += s * mvx
                    buf[GPY, k] += s * mvy


@njit(cache=True, error_model="numpy")
def advance(nsteps, t, dt, method, post_extrapolate, plane_stress,
            pos, vel, mass, vol0, lp, mat, F, stress, hist, w, pdamp, mat_params,
            geom, bounds, g, gbuf, gv, ga, gvn, gtmp, damping, mass_tol, vmax, left,
            leave_limit,
            gbc_node, gbc_dir, gbc_rec, pbc_part, pbc_dir, pbc_scale, pbc_face, pbc_rec,
            rec_style, rec_value, rec_t0, rec_ftime, rec_force, rec_work,
            sym_out, sym_in, sym_dir, bad, nch):
    """Run up to ``nsteps`` steps from time ``t`` (ms).

    Every extrapolation after the chunk's first is fused into the particle update:
    it is the next step's extrapolation in every method (positions and velocities do
    not change in between), and in USL+/USAVG+ also NairnMPM's post-update one, whose
    stress update is carried over (``pending``) into the next stress pass, which has
    the same velocity gradient.  Shape-function weights are computed once per step.
    Returns (steps done, status, offending particle).  ``rec_force`` holds each
    condition's force (N) on the last step; ``rec_work`` accumulates its work (mJ).
    """
    n = pos.shape[1]
    pload = np.zeros(pbc_part.size)
    pos_before = np.zeros(pbc_part.size)
    wij = np.empty((n, 2), dtype=np.int64)
    wc = np.empty((n, 12))
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
    _weights_and_mass(pos, vel, mass, lp, geom, wij, wc, gbuf, nch)
    _reduce_velocity(gbuf, g, gv, mass_tol, nch)
    _momentum_conditions(g, geom, gbc_node, gbc_dir, gbc_rec, rec_style, rec_value, rec_t0,
                         rec_ftime, sym_out, sym_in, sym_dir, t)
    _velocity_at(g, gv, gbc_node, mass_tol)
    _velocity_at(g, gv, sym_out, mass_tol)
    pending = 0.0
    for step in range(nsteps):
        rec_force[:] = 0.0
        g[GFX] = 0.0
        g[GFY] = 0.0
        _scatter_loads(pos, lp, F, geom, g, pbc_part, pbc_dir, pbc_scale, pbc_face, pbc_rec,
                       rec_style, rec_value, rec_t0, rec_ftime, rec_force, t, pload)
        for q in range(pbc_part.size):
            pos_before[q] = pos[pbc_dir[q], pbc_part[q]]
        _stress_force_cached(mass, vol0, mat, F, stress, hist, w, mat_params, plane_stress,
                             geom, wij, wc, gv, gbuf, nch, pending, dt_first, True, n)
        pending = 0.0
        _forces_update(gbuf, g, ga, gvn, dt, mass_tol, nch)
        _velocity_conditions_after(g, geom, ga, gvn, gtmp, gbc_node, gbc_dir, gbc_rec, rec_style,
                                   rec_value, rec_t0, rec_ftime, rec_force, rec_work,
                                   sym_out, sym_in, sym_dir, t, dt, mass_tol)
        _update_and_extrapolate(pos, vel, mass, lp, mat, F, stress, hist, w, mat_params,
                                plane_stress, geom, ga, gvn, dt,
                                0.0 if post_extrapolate else dt_last, damping, pdamp,
                                bounds, vmax, left, bad, wij, wc, gbuf, nch)
        _load_work(pos, pbc_part, pbc_dir, pload, pos_before, rec_work, pbc_rec)
        t += dt
        _reduce_velocity(gbuf, g, gv, mass_tol, nch)
        _momentum_conditions(g, geom, gbc_node, gbc_dir, gbc_rec, rec_style, rec_value,
                             rec_t0, rec_ftime, sym_out, sym_in, sym_dir, t)
        _velocity_at(g, gv, gbc_node, mass_tol)
        _velocity_at(g, gv, sym_out, mass_tol)
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
            if pending > 0.0:
                _stress_force_cached(mass, vol0, mat, F, stress, hist, w, mat_params,
                                     plane_stress, geom, wij, wc, gv, gbuf, nch, 0.0, pending,
                                     False, n)
            if status != STATUS_OK:
                return step + 1, status, who
    return nsteps, STATUS_OK, -1
