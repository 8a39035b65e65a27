"""The explicit MPM time step as fused Numba kernels.

This file is a template as well as a module: ``kernel_build`` copies it into a cache
folder with the ``material_update`` import replaced by a dispatcher over the
materials of one scene, so the stress update of any material plugin is inlined in the
particle loops and everything stays ``cache=True``.  Imported directly it dispatches
to the isotropic material only (used by tests of the kernels themselves).

One step (``advance`` runs many without returning to Python):

1. particles -> grid: mass and momentum (pass A), then particle loads;
2. grid velocity conditions on momentum;
3. USF / USAVG: velocity gradient from the grid, stress update (dt or dt/2), and the
   internal forces back to the grid (pass B, fused);
4. momentum update, velocity conditions on the new momentum (reactions recorded);
5. grid -> particles: velocity (FLIP) and position with grid and particle damping
   (as NairnMPM applies them), and for USL- / USAVG- the stress update from the
   updated grid velocities (pass C, fused);
6. for USL+ / USAVG+ (NairnMPM's default): momenta extrapolated again from the
   updated particles and the last stress update from those.

Particle loops run as fixed chunks, each with its own grid buffer, reduced in a fixed
order: results do not depend on thread scheduling.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from nairnmpm_py.core.shape import weights_1d
from nairnmpm_py.core.material_dispatch_default import material_update  # KERNEL-MATERIALS

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
def bc_value(style, value, t0, ftime, t):
    """Value of a boundary condition at time t (ms).

    style 1 constant, 2 linear ramp value*(t - t0) (value per ms),
    3 value*sin(ftime*t), 4 value*cos(ftime*t) (ftime in rad/ms).
    """
    if style == 1:
        return value if t >= t0 else 0.0
    if style == 2:
        return value * (t - t0) if t >= t0 else 0.0
    if style == 3:
        return value * math.sin(ftime * t)
    if style == 4:
        return value * math.cos(ftime * t)
    return 0.0


@njit(cache=True, parallel=True)
def _pass_mass_momentum(pos, vel, mass, lp, geom, kind, gbuf, nch):
    n = pos.shape[1]
    nnx = int(geom[4])
    na = 2 if kind == 0 else 3
    for c in prange(nch):
        buf = gbuf[c]
        buf[:] = 0.0
        lo = c * n // nch
        hi = (c + 1) * n // nch
        for p in range(lo, hi):
            xi = (pos[0, p] - geom[0]) / geom[2]
            eta = (pos[1, p] - geom[1]) / geom[3]
            i0, sx0, sx1, sx2, dx0, dx1, dx2 = weights_1d(xi, kind, lp[0, p])
            j0, sy0, sy1, sy2, dy0, dy1, dy2 = weights_1d(eta, kind, lp[1, p])
            m = mass[p]
            mvx = m * vel[0, p]
            mvy = m * vel[1, p]
            for b in range(na):
                sy = sy0 if b == 0 else (sy1 if b == 1 else sy2)
                row = (j0 + b) * nnx + i0
                for a in range(na):
                    s = sy * (sx0 if a == 0 else (sx1 if a == 1 else sx2))
                    k = row + a
                    buf[GM, k] += s * m
                    buf[GPX, k] += s * mvx
                    buf[GPY, k] += s * mvy


@njit(cache=True, parallel=True)
def _reduce(gbuf, g, first, last, nch):
    nn = g.shape[1]
    for k in prange(nn):
        for r in range(first, last):
            acc = 0.0
            for c in range(nch):
                acc += gbuf[c, r, k]
            g[r, k] = acc


@njit(cache=True)
def _scatter_loads(pos, lp, geom, kind, g, pbc_part, pbc_dir, pbc_scale, pbc_rec,
                   rec_style, rec_value, rec_t0, rec_ftime, rec_force, t, pload):
    """Particle loads (N) at time t onto the grid; pload keeps them for the work."""
    nnx = int(geom[4])
    na = 2 if kind == 0 else 3
    for q in range(pbc_part.size):
        r = pbc_rec[q]
        f = pbc_scale[q] * bc_value(rec_style[r], rec_value[r], rec_t0[r], rec_ftime[r], t)
        pload[q] = f
        rec_force[r] += f
        p = pbc_part[q]
        row_c = GFX + pbc_dir[q]
        xi = (pos[0, p] - geom[0]) / geom[2]
        eta = (pos[1, p] - geom[1]) / geom[3]
        i0, sx0, sx1, sx2, dx0, dx1, dx2 = weights_1d(xi, kind, lp[0, p])
        j0, sy0, sy1, sy2, dy0, dy1, dy2 = weights_1d(eta, kind, lp[1, p])
        for b in range(na):
            sy = sy0 if b == 0 else (sy1 if b == 1 else sy2)
            row = (j0 + b) * nnx + i0
            for a in range(na):
                s = sy * (sx0 if a == 0 else (sx1 if a == 1 else sx2))
                g[row_c, row + a] += s * f


@njit(cache=True)
def _momentum_conditions(g, gbc_node, gbc_dir, gbc_rec, rec_style, rec_value, rec_t0,
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
            v = bc_value(rec_style[r], rec_value[r], rec_t0[r], rec_ftime[r], t)
            g[GPX + gbc_dir[q], k] += g[GM, k] * v
    for q in range(sym_out.size):
        ko = sym_out[q]
        ki = sym_in[q]
        d = sym_dir[q]
        if g[GM, ki] > 0.0:
            g[GPX + d, ko] = -g[GM, ko] * g[GPX + d, ki] / g[GM, ki]
        else:
            g[GPX + d, ko] = 0.0


@njit(cache=True, parallel=True)
def _grid_velocity(g, gv, mass_tol):
    nn = g.shape[1]
    for k in prange(nn):
        m = g[GM, k]
        if m > mass_tol:
            gv[0, k] = g[GPX, k] / m
            gv[1, k] = g[GPY, k] / m
        else:
            gv[0, k] = 0.0
            gv[1, k] = 0.0


@njit(cache=True, inline="always")
def _stress_update(p, dt, L00, L01, L10, L11, F, stress, hist, w, mat, mat_params,
                   plane_stress):
    # F_new = exp(L dt) F_old: exact for rigid rotations, so no spurious volume change
    a = L00 * dt
    b = L01 * dt
    c = L10 * dt
    d = L11 * dt
    half = 0.5 * (a + d)
    disc = 0.25 * (a - d) * (a - d) + b * c
    if disc > 1e-14:
        q = math.sqrt(disc)
        ch = math.cosh(q)
        sh = math.sinh(q) / q
    elif disc < -1e-14:
        q = math.sqrt(-disc)
        ch = math.cos(q)
        sh = math.sin(q) / q
    else:
        ch = 1.0 + 0.5 * disc
        sh = 1.0 + disc / 6.0
    e = math.exp(half)
    e00 = e * (ch + sh * (a - half))
    e01 = e * sh * b
    e10 = e * sh * c
    e11 = e * (ch + sh * (d - half))
    f00 = F[0, p]
    f01 = F[1, p]
    f10 = F[2, p]
    f11 = F[3, p]
    F[0, p] = e00 * f00 + e01 * f10
    F[1, p] = e00 * f01 + e01 * f11
    F[2, p] = e10 * f00 + e11 * f10
    F[3, p] = e10 * f01 + e11 * f11
    m = mat[p]
    material_update(m, p, dt, L00, L01, L10, L11, F, stress, hist, w, mat_params[m],
                    plane_stress)


@njit(cache=True, parallel=True)
def _pass_stress_force(pos, mass, vol0, lp, mat, F, stress, hist, w, mat_params,
                       plane_stress, geom, kind, gv, gbuf, nch, dt_pending, dt_stress,
                       scatter):
    """Velocity gradient from grid velocities ``gv``; stress updates over
    ``dt_pending`` (the last update of the previous step, whose velocity gradient is
    this one) and ``dt_stress``; and (if ``scatter``) internal forces to the grid."""
    n = pos.shape[1]
    nnx = int(geom[4])
    idx = 1.0 / geom[2]
    idy = 1.0 / geom[3]
    na = 2 if kind == 0 else 3
    for c in prange(nch):
        buf = gbuf[c]
        buf[GFX] = 0.0
        buf[GFY] = 0.0
        lo = c * n // nch
        hi = (c + 1) * n // nch
        for p in range(lo, hi):
            xi = (pos[0, p] - geom[0]) * idx
            eta = (pos[1, p] - geom[1]) * idy
            i0, sx0, sx1, sx2, dx0, dx1, dx2 = weights_1d(xi, kind, lp[0, p])
            j0, sy0, sy1, sy2, dy0, dy1, dy2 = weights_1d(eta, kind, lp[1, p])
            if dt_stress > 0.0 or dt_pending > 0.0:
                L00 = 0.0
                L01 = 0.0
                L10 = 0.0
                L11 = 0.0
                for b in range(na):
                    sy = sy0 if b == 0 else (sy1 if b == 1 else sy2)
                    dy = (dy0 if b == 0 else (dy1 if b == 1 else dy2)) * idy
                    row = (j0 + b) * nnx + i0
                    for a in range(na):
                        sx = sx0 if a == 0 else (sx1 if a == 1 else sx2)
                        dx = (dx0 if a == 0 else (dx1 if a == 1 else dx2)) * idx
                        k = row + a
                        gx = dx * sy
                        gy = sx * dy
                        L00 += gv[0, k] * gx
                        L01 += gv[0, k] * gy
                        L10 += gv[1, k] * gx
                        L11 += gv[1, k] * gy
                if dt_pending > 0.0:
                    _stress_update(p, dt_pending, L00, L01, L10, L11, F, stress, hist, w,
                                   mat, mat_params, plane_stress)
                if dt_stress > 0.0:
                    _stress_update(p, dt_stress, L00, L01, L10, L11, F, stress, hist, w,
                                   mat, mat_params, plane_stress)
            if not scatter:
                continue
            # current volume (thickness changes with F22 in plane stress)
            vol = vol0[p] * (F[0, p] * F[3, p] - F[1, p] * F[2, p]) * F[4, p]
            sxx = stress[0, p] * vol
            syy = stress[1, p] * vol
            sxy = stress[2, p] * vol
            for b in range(na):
                sy = sy0 if b == 0 else (sy1 if b == 1 else sy2)
                dy = (dy0 if b == 0 else (dy1 if b == 1 else dy2)) * idy
                row = (j0 + b) * nnx + i0
                for a in range(na):
                    sx = sx0 if a == 0 else (sx1 if a == 1 else sx2)
                    dx = (dx0 if a == 0 else (dx1 if a == 1 else dx2)) * idx
                    k = row + a
                    gx = dx * sy
                    gy = sx * dy
                    buf[GFX, k] -= sxx * gx + sxy * gy
                    buf[GFY, k] -= sxy * gx + syy * gy


@njit(cache=True, parallel=True)
def _add_forces(gbuf, g, nch):
    """Add the chunks' internal forces onto the loads already on the grid."""
    nn = g.shape[1]
    for k in prange(nn):
        fx = 0.0
        fy = 0.0
        for c in range(nch):
            fx += gbuf[c, GFX, k]
            fy += gbuf[c, GFY, k]
        g[GFX, k] += fx
        g[GFY, k] += fy


@njit(cache=True, parallel=True)
def _grid_update(g, gv, ga, gvn, dt, mass_tol):
    nn = g.shape[1]
    for k in prange(nn):
        m = g[GM, k]
        if m > mass_tol:
            fx = g[GFX, k]
            fy = g[GFY, k]
            ga[0, k] = fx / m
            ga[1, k] = fy / m
            gvn[0, k] = (g[GPX, k] + fx * dt) / m
            gvn[1, k] = (g[GPY, k] + fy * dt) / m
        else:
            ga[0, k] = 0.0
            ga[1, k] = 0.0
            gvn[0, k] = 0.0
            gvn[1, k] = 0.0


@njit(cache=True)
def _velocity_conditions_after(g, ga, gvn, gtmp, gbc_node, gbc_dir, gbc_rec, rec_style,
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
            gtmp[gbc_dir[q], gbc_node[q]] += bc_value(rec_style[r], rec_value[r], rec_t0[r],
                                                      rec_ftime[r], t + dt)
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


@njit(cache=True, parallel=True)
def _pass_update_particles(pos, vel, mass, lp, mat, F, stress, hist, w, mat_params,
                           plane_stress, geom, kind, ga, gvn, dt, dt_stress, damping,
                           pdamp, bounds, vmax, left, bad, gbuf, nch):
    """FLIP velocity and position update with grid and particle damping; with
    ``dt_stress > 0`` also the USL half of the stress update (the "-" variant).
    Each updated particle then extrapolates its mass and momentum into ``gbuf``:
    that is the next step's first extrapolation (and NairnMPM's post-update
    extrapolation for USL+/USAVG+), done while the particle is in registers."""
    n = pos.shape[1]
    nnx = int(geom[4])
    idx = 1.0 / geom[2]
    idy = 1.0 / geom[3]
    na = 2 if kind == 0 else 3
    for c in prange(nch):
        lo = c * n // nch
        hi = (c + 1) * n // nch
        bad[c, 0] = -1
        buf = gbuf[c]
        buf[GM] = 0.0
        buf[GPX] = 0.0
        buf[GPY] = 0.0
        for p in range(lo, hi):
            xi = (pos[0, p] - geom[0]) * idx
            eta = (pos[1, p] - geom[1]) * idy
            i0, sx0, sx1, sx2, dx0, dx1, dx2 = weights_1d(xi, kind, lp[0, p])
            j0, sy0, sy1, sy2, dy0, dy1, dy2 = weights_1d(eta, kind, lp[1, p])
            ax = 0.0
            ay = 0.0
            vx = 0.0
            vy = 0.0
            L00 = 0.0
            L01 = 0.0
            L10 = 0.0
            L11 = 0.0
            for b in range(na):
                sy = sy0 if b == 0 else (sy1 if b == 1 else sy2)
                dy = (dy0 if b == 0 else (dy1 if b == 1 else dy2)) * idy
                row = (j0 + b) * nnx + i0
                for a in range(na):
                    sx = sx0 if a == 0 else (sx1 if a == 1 else sx2)
                    dx = (dx0 if a == 0 else (dx1 if a == 1 else dx2)) * idx
                    k = row + a
                    s = sx * sy
                    gx = dx * sy
                    gy = sx * dy
                    ax += s * ga[0, k]
                    ay += s * ga[1, k]
                    vnx = gvn[0, k]
                    vny = gvn[1, k]
                    vx += s * vnx
                    vy += s * vny
                    L00 += vnx * gx
                    L01 += vnx * gy
                    L10 += vny * gx
                    L11 += vny * gy
            # grid velocity at the particle before the update, then damped FLIP
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
                # NairnMPM's LeaveLimit rule: push the particle back where it was and
                # count it; the run stops once too many distinct particles have left
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
            xi = (x - geom[0]) * idx
            eta = (y - geom[1]) * idy
            i0, sx0, sx1, sx2, dx0, dx1, dx2 = weights_1d(xi, kind, lp[0, p])
            j0, sy0, sy1, sy2, dy0, dy1, dy2 = weights_1d(eta, kind, lp[1, p])
            m = mass[p]
            mvx = m * nvx
            mvy = m * nvy
            for b in range(na):
                sy = sy0 if b == 0 else (sy1 if b == 1 else sy2)
                row = (j0 + b) * nnx + i0
                for a in range(na):
                    sw = sy * (sx0 if a == 0 else (sx1 if a == 1 else sx2))
                    k = row + a
                    buf[GM, k] += sw * m
                    buf[GPX, k] += sw * mvx
                    buf[GPY, k] += sw * mvy
            if bad[c, 0] < 0:
                if not (math.isfinite(nvx) and math.isfinite(nvy) and math.isfinite(x)
                        and math.isfinite(y) and math.isfinite(stress[0, p])):
                    bad[c, 0] = p
                    bad[c, 1] = STATUS_NONFINITE
                elif nvx * nvx + nvy * nvy > vmax * vmax:
                    bad[c, 0] = p
                    bad[c, 1] = STATUS_RUNAWAY


@njit(cache=True)
def _load_work(pos, pbc_part, pbc_dir, pload, pos_before, rec_work, pbc_rec):
    for q in range(pbc_part.size):
        p = pbc_part[q]
        d = pbc_dir[q]
        rec_work[pbc_rec[q]] += pload[q] * (pos[d, p] - pos_before[q])


@njit(cache=True)
def advance(nsteps, t, dt, method, post_extrapolate, kind, plane_stress,
            pos, vel, mass, vol0, lp, mat, F, stress, hist, w, pdamp, mat_params,
            geom, bounds, g, gbuf, gv, ga, gvn, gtmp, damping, mass_tol, vmax, left,
            leave_limit,
            gbc_node, gbc_dir, gbc_rec, pbc_part, pbc_dir, pbc_scale, pbc_rec,
            rec_style, rec_value, rec_t0, rec_ftime, rec_force, rec_work,
            sym_out, sym_in, sym_dir, bad, nch):
    """Run up to ``nsteps`` steps from time ``t`` (ms).

    ``post_extrapolate`` selects NairnMPM's USL+/USAVG+ over the "-" variant.  In
    "+" the last stress update of a step uses momenta extrapolated from the updated
    particles, with the conditions at the new time: exactly the next step's first
    grid.  So it is carried over and done in the next step's stress pass, with the
    same velocity gradient, and only the chunk's last step does it on its own.
    Returns (steps done, status, offending particle).  ``rec_force`` holds each
    condition's force (N) on the last step; ``rec_work`` accumulates its work (mJ).
    """
    pload = np.zeros(pbc_part.size)
    pos_before = np.zeros(pbc_part.size)
    if method == USF:
        dt_first = dt
        dt_last = 0.0
    elif method == USL:
        dt_first = 0.0
        dt_last = dt
    else:
        dt_first = 0.5 * dt
        dt_last = dt - dt_first
    dt_pending = 0.0
    dt_in_update = 0.0 if post_extrapolate else dt_last
    _pass_mass_momentum(pos, vel, mass, lp, geom, kind, gbuf, nch)
    _reduce(gbuf, g, GM, GPY + 1, nch)
    _momentum_conditions(g, gbc_node, gbc_dir, gbc_rec, rec_style, rec_value, rec_t0,
                         rec_ftime, sym_out, sym_in, sym_dir, t)
    _grid_velocity(g, gv, mass_tol)
    for step in range(nsteps):
        rec_force[:] = 0.0
        _pass_stress_force(pos, mass, vol0, lp, mat, F, stress, hist, w, mat_params,
                           plane_stress, geom, kind, gv, gbuf, nch, dt_pending, dt_first,
                           True)
        g[GFX] = 0.0
        g[GFY] = 0.0
        _scatter_loads(pos, lp, geom, kind, g, pbc_part, pbc_dir, pbc_scale, pbc_rec,
                       rec_style, rec_value, rec_t0, rec_ftime, rec_force, t, pload)
        for q in range(pbc_part.size):
            pos_before[q] = pos[pbc_dir[q], pbc_part[q]]
        _add_forces(gbuf, g, nch)
        _grid_update(g, gv, ga, gvn, dt, mass_tol)
        _velocity_conditions_after(g, ga, gvn, gtmp, gbc_node, gbc_dir, gbc_rec, rec_style,
                                   rec_value, rec_t0, rec_ftime, rec_force, rec_work,
                                   sym_out, sym_in, sym_dir, t, dt, mass_tol)
        _pass_update_particles(pos, vel, mass, lp, mat, F, stress, hist, w, mat_params,
                               plane_stress, geom, kind, ga, gvn, dt, dt_in_update,
                               damping, pdamp, bounds, vmax, left, bad, gbuf, nch)
        _load_work(pos, pbc_part, pbc_dir, pload, pos_before, rec_work, pbc_rec)
        t += dt
        _reduce(gbuf, g, GM, GPY + 1, nch)
        _momentum_conditions(g, gbc_node, gbc_dir, gbc_rec, rec_style, rec_value, rec_t0,
                             rec_ftime, sym_out, sym_in, sym_dir, t)
        _grid_velocity(g, gv, mass_tol)
        dt_pending = dt_last if post_extrapolate else 0.0
        n_left = 0
        stop = False
        status = STATUS_OK
        who = -1
        for c in range(nch):
            if bad[c, 0] >= 0:
                stop = True
                status = bad[c, 1]
                who = bad[c, 0]
                break
            n_left += bad[c, 2]
        if not stop and n_left >= leave_limit:
            for c in range(nch):
                if bad[c, 2] > 0:
                    stop = True
                    status = STATUS_LEFT_GRID
                    who = bad[c, 3]
        if stop or step == nsteps - 1:
            if dt_pending > 0.0:
                _pass_stress_force(pos, mass, vol0, lp, mat, F, stress, hist, w, mat_params,
                                   plane_stress, geom, kind, gv, gbuf, nch, 0.0, dt_pending,
                                   False)
            if stop:
                return step + 1, status, who
    return nsteps, STATUS_OK, -1
