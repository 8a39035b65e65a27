"""The tasks of the explicit MPM time step, as Numba kernels.

``core/tasks.py`` lists them in order; this file is their one source.  Every task
has the signature ``task(P, G, C, K, S)`` over the state bundles of ``core/state``.

This file is a template as well as a module: ``kernel_build`` copies it into a cache
folder with the scene's material dispatcher, shape functions (``KIND``), velocity
fields and build flags filled in at the marked lines, so the stress update of any
material plugin is inlined in the particle loops and everything stays
``cache=True``.  The driver, composed from the task list, is a module of its own that
calls these tasks through their addresses (``core/linking``).  Imported directly this
file runs uGIMP with the isotropic material and one field.

Fields: a scene without cracks has one velocity field per node (``MULTI_FIELD``
False: every field index below is the constant 0 and compiles away).  A scene with
cracks builds this file with ``MULTI_FIELD`` True and the crack module's
``assign_and_scatter``, which chooses each particle's field at each of its nodes
(``K.vfld``; ``K.cut`` 0 for a particle that touches no crack node); every pass here
then reads and writes the particle's own field.

Every task is compiled without a Python entry point (``no_cpython_wrapper``): only
the driver calls them, and the unboxing code of five bundles would cost about a
second of compiling each.

Particle loops run as fixed chunks, each with its own grid buffer, reduced in a fixed
order: results do not depend on thread scheduling.  A parallel task first takes the
arrays it needs out of the bundles into plain locals, and its ``prange`` body (and
the inline helpers it calls) uses only those.  Both reasons measured: Numba 0.68
loses writes made in a ``prange`` body through a named tuple's arrays, also when
they are unpacked (``a, b = P``) or regrouped into a tuple there (numba#7135,
numba#10338); and a body that calls a function taking the bundles ran the beam
1.6-2.2x slower.  Reading an array out of a tuple costs reference counting at each
access, so nothing a particle loop reads for every particle comes from a tuple.

A scene that runs as one chunk builds with ``PARALLEL`` False: no parallel loops,
which Numba compiles as separate functions through a long pipeline (the beam
compiled in 20 s instead of 34, the DCB in 70 s instead of 88), and no reference
counting (``NRT``).  Without parallel loops Numba counts references to each array an
inlined helper receives, at every particle, and those atomic counts ran the beam
1.4-1.6x slower; these tasks allocate nothing, so nothing needs counting.  (The
crack tasks, which allocate scratch arrays, are compiled on their own with it: the
driver calls every task through its address.)

``FAST`` allows reassociation and fused multiply-adds but keeps NaN and infinity
semantics, so blow-ups are still caught.
"""
from __future__ import annotations

import math

from numba import njit, prange
from numba.types import boolean, float64

from nairnmpm_py.core.grid_ops import accelerate_node
from nairnmpm_py.core.shape import weights_1d
from nairnmpm_py.core.state import (GM, GPX, GPY, GFX, GFY, CLOCK_T, CLOCK_PENDING, STATUS_OK,
                                    STATUS_NONFINITE, STATUS_LEFT_GRID, STATUS_RUNAWAY)
from nairnmpm_py.core.material_dispatch_default import material_update  # KERNEL-MATERIALS
from nairnmpm_py.core.expressions import call_condition
from nairnmpm_py.core.linking import call_task
from nairnmpm_py.core.single_field import assign_and_scatter, field_lists  # KERNEL-FIELDS

KIND = 1  # KERNEL-SHAPE: 0 classic linear, 1 uGIMP
MULTI_FIELD = False  # KERNEL-MULTI-FIELD: more than one velocity field per node
UPDATE_STRESS = True  # KERNEL-UPDATE-STRESS: the particle update updates stresses (USL- / USAVG-)
PARALLEL = True  # KERNEL-PARALLEL: loops on threads (False: a one-chunk build)
NRT = PARALLEL  # reference counting: only a build with parallel loops needs it (docstring)
NA = 2 if KIND == 0 else 3  # nodes per axis a particle touches
FAST = {"contract", "reassoc", "nsz", "arcp", "afn"}
# how every task compiles (no Python entry point: only the driver calls them), and the
# particle and node loops over chunks or nodes
TASK = dict(cache=True, _nrt=NRT, error_model="numpy", no_cpython_wrapper=True)
PARALLEL_TASK = dict(TASK, parallel=PARALLEL, fastmath=FAST)


# ---- condition values ----------------------------------------------------------------
@njit(cache=True, inline="always")
def bc_active(style, t0, t):
    """Constant and ramp conditions start at t0 (node free before); sine and
    cosine act from t = 0, as NairnMPM does."""
    if style == 1 or style == 2:
        return t >= t0
    return True


@njit(cache=True, _nrt=NRT)
def bc_value(C, r, t, x, y, q):
    """Value of boundary condition record r at time t (ms).

    style 1 constant, 2 linear ramp value*(t - t0) (value per ms),
    3 value*sin(ftime*t), 4 value*cos(ftime*t) (ftime in rad/ms), 6 value times the
    record's expression of t - t0 (ms; zero before t0), of the position x, y (mm) of
    the node or particle and of the particle's rotation q (radians).
    """
    style = C.rec_style[r]
    value = C.rec_value[r]
    t0 = C.rec_t0[r]
    if style == 1:
        return value if t >= t0 else 0.0
    if style == 2:
        return value * (t - t0) if t >= t0 else 0.0
    if style == 3:
        return value * math.sin(C.rec_ftime[r] * t)
    if style == 4:
        return value * math.cos(C.rec_ftime[r] * t)
    if style == 6:
        if t < t0:
            return 0.0
        return value * call_condition(C.faddr[0], r, t - t0, x, y, q, C.fconst)
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
def field_at(cut, vfld, p, slot):
    """The velocity field particle p uses at the ``slot``-th node of its stencil
    (``K.cut``, ``K.vfld``)."""
    if MULTI_FIELD:
        if cut[p]:
            return vfld[p, slot]
    return 0


# Each particle loop over a particle's nodes exists in two builds: the particle's own
# fields (a cut particle, multi-field builds only) and field 0, chosen once per particle
# by a ``_for_fields`` dispatcher.  With ``cut_p`` a literal the field-0 loop compiles
# with constant indices, as in a build without cracks (choosing the field at every
# node made the crack block's particle update 1.8x slower).
@njit(cache=True, inline="always")
def _field(vfld, p, slot, cut_p):
    if MULTI_FIELD and cut_p:
        return vfld[p, slot]
    return 0


@njit(cache=True, inline="always")
def _gradient_loop(p, r, i0, j0, nnx, gv, vfld, cut_p):
    """Velocity gradient of particle p from its fields' grid velocities."""
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
            f = _field(vfld, p, b * NA + a, cut_p)
            gx = r[6 + a] * sy
            gy = r[a] * dy
            vx = gv[f, 0, k]
            vy = gv[f, 1, k]
            L00 += vx * gx
            L01 += vx * gy
            L10 += vy * gx
            L11 += vy * gy
    return L00, L01, L10, L11


@njit(cache=True, inline="always")
def _velocity_gradient(p, r, i0, j0, nnx, gv, vfld, cut):
    if MULTI_FIELD:
        if cut[p]:
            return _gradient_loop(p, r, i0, j0, nnx, gv, vfld, True)
    return _gradient_loop(p, r, i0, j0, nnx, gv, vfld, False)


@njit(cache=True, inline="always")
def _forces_loop(buf, p, r, i0, j0, nnx, vfld, cut_p, sxx, syy, sxy):
    """Internal force of particle p's stress (times its volume) on its fields."""
    for b in range(NA):
        sy = r[3 + b]
        dy = r[9 + b]
        row = (j0 + b) * nnx + i0
        for a in range(NA):
            k = row + a
            f = _field(vfld, p, b * NA + a, cut_p)
            gx = r[6 + a] * sy
            gy = r[a] * dy
            buf[f, GFX, k] -= sxx * gx + sxy * gy
            buf[f, GFY, k] -= sxy * gx + syy * gy


@njit(cache=True, inline="always")
def _internal_forces(buf, p, r, i0, j0, nnx, vfld, cut, sxx, syy, sxy):
    if MULTI_FIELD:
        if cut[p]:
            _forces_loop(buf, p, r, i0, j0, nnx, vfld, True, sxx, syy, sxy)
            return
    _forces_loop(buf, p, r, i0, j0, nnx, vfld, False, sxx, syy, sxy)


@njit(cache=True, inline="always")
def _gather_loop(p, r, i0, j0, nnx, ga, gvn, vfld, cut_p, gradient):
    """Particle p's acceleration and updated velocity from its fields, and with
    ``gradient`` the velocity gradient of the updated grid velocities."""
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
            f = _field(vfld, p, b * NA + a, cut_p)
            s = r[a] * sy
            ax += s * ga[f, 0, k]
            ay += s * ga[f, 1, k]
            vnx = gvn[f, 0, k]
            vny = gvn[f, 1, k]
            vx += s * vnx
            vy += s * vny
            if gradient:
                gx = r[6 + a] * sy
                gy = r[a] * dy
                L00 += vnx * gx
                L01 += vnx * gy
                L10 += vny * gx
                L11 += vny * gy
    return ax, ay, vx, vy, L00, L01, L10, L11


@njit(cache=True, inline="always")
def _grid_to_particle(p, r, i0, j0, nnx, ga, gvn, vfld, cut, gradient):
    if MULTI_FIELD:
        if cut[p]:
            return _gather_loop(p, r, i0, j0, nnx, ga, gvn, vfld, True, gradient)
    return _gather_loop(p, r, i0, j0, nnx, ga, gvn, vfld, False, gradient)


# ---- particle loads ------------------------------------------------------------------
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


@njit(**TASK)
def scatter_loads(P, G, C, K, S):
    """Clear the grid forces, then the particle loads (N) at this time onto the grid,
    in the field the particle uses at each node; ``C.pload`` keeps them for the work,
    ``C.pos_before`` the loaded particles' positions."""
    g = G.g
    geom = G.geom
    pos = P.pos
    C.rec_force[:] = 0.0
    g[:, GFX] = 0.0
    g[:, GFY] = 0.0
    t = S.clock[CLOCK_T]
    nnx = int(geom[4])
    for q in range(C.pbc_part.size):
        r = C.pbc_rec[q]
        p = C.pbc_part[q]
        C.pos_before[q] = pos[C.pbc_dir[q], p]
        f = C.pbc_scale[q] * bc_value(C, r, t, pos[0, p], pos[1, p], particle_rotation(P.F, p))
        C.pload[q] = f
        C.rec_force[r] += f
        row_c = GFX + C.pbc_dir[q]
        if C.pbc_face[q] > 0:
            # a traction: on the face's nodes that have mass, in the field the particle
            # uses at that node (field 0 outside its own nodes)
            for m in range(8):
                i, j, sw = face_node(pos, P.lp, P.F, geom, g.shape[2] // nnx, p, C.pbc_face[q], m)
                pa = i - P.wij[p, 0]
                pb = j - P.wij[p, 1]
                fld = 0
                if 0 <= pa < NA and 0 <= pb < NA:
                    fld = field_at(K.cut, K.vfld, p, pb * NA + pa)
                if g[fld, GM, j * nnx + i] > 0.0:
                    g[fld, row_c, j * nnx + i] += sw * f
            continue
        wq = P.wc[p]
        for b in range(NA):
            row = (P.wij[p, 1] + b) * nnx + P.wij[p, 0]
            for a in range(NA):
                g[field_at(K.cut, K.vfld, p, b * NA + a), row_c, row + a] += wq[3 + b] * wq[a] * f


@njit(**TASK)
def load_work(P, G, C, K, S):
    """Work (mJ) of each particle load over the step just taken."""
    for q in range(C.pbc_part.size):
        p = C.pbc_part[q]
        C.rec_work[C.pbc_rec[q]] += C.pload[q] * (P.pos[C.pbc_dir[q], p] - C.pos_before[q])


# ---- velocity conditions ---------------------------------------------------------------
@njit(**TASK)
def momentum_conditions(P, G, C, K, S):
    """Impose velocity conditions on the extrapolated momenta of every field, then
    the velocities of the conditioned nodes.

    Several conditions on one node and direction add up (zero first, then add).
    Nodes just outside a symmetry plane mirror the normal velocity of the node
    inside it (in the same field, or field 0 where that one is empty)."""
    g = G.g
    gv = G.gv
    nf = g.shape[0]
    t = S.clock[CLOCK_T]
    for q in range(C.gbc_node.size):
        r = C.gbc_rec[q]
        if bc_active(C.rec_style[r], C.rec_t0[r], t):
            for f in range(nf):
                g[f, GPX + C.gbc_dir[q], C.gbc_node[q]] = 0.0
    for q in range(C.gbc_node.size):
        r = C.gbc_rec[q]
        if bc_active(C.rec_style[r], C.rec_t0[r], t):
            k = C.gbc_node[q]
            v = bc_value(C, r, t, node_x(k, G.geom), node_y(k, G.geom), 0.0)
            for f in range(nf):
                g[f, GPX + C.gbc_dir[q], k] += g[f, GM, k] * v
    for q in range(C.sym_out.size):
        ko = C.sym_out[q]
        ki = C.sym_in[q]
        d = C.sym_dir[q]
        for f in range(nf):
            fi = f if g[f, GM, ki] > 0.0 else 0
            if g[fi, GM, ki] > 0.0:
                g[f, GPX + d, ko] = -g[f, GM, ko] * g[fi, GPX + d, ki] / g[fi, GM, ki]
            else:
                g[f, GPX + d, ko] = 0.0
    for nodes in (C.gbc_node, C.sym_out):
        for q in range(nodes.size):
            k = nodes[q]
            for f in range(nf):
                m = g[f, GM, k]
                if m > S.mass_tol:
                    gv[f, 0, k] = g[f, GPX, k] / m
                    gv[f, 1, k] = g[f, GPY, k] / m
                else:
                    gv[f, 0, k] = 0.0
                    gv[f, 1, k] = 0.0


@njit(**TASK)
def velocity_conditions(P, G, C, K, S):
    """Impose v(t+dt) on conditioned nodes in every field; the force that takes is
    the reaction (summed over the fields)."""
    g = G.g
    ga = G.ga
    gvn = G.gvn
    gtmp = G.gtmp
    nf = g.shape[0]
    t = S.clock[CLOCK_T]
    dt = S.dt
    for q in range(C.gbc_node.size):
        r = C.gbc_rec[q]
        if bc_active(C.rec_style[r], C.rec_t0[r], t):
            gtmp[C.gbc_dir[q], C.gbc_node[q]] = 0.0
    for q in range(C.gbc_node.size):
        r = C.gbc_rec[q]
        if bc_active(C.rec_style[r], C.rec_t0[r], t):
            k = C.gbc_node[q]
            gtmp[C.gbc_dir[q], k] += bc_value(C, r, t + dt, node_x(k, G.geom),
                                              node_y(k, G.geom), 0.0)
    for q in range(C.gbc_node.size):
        r = C.gbc_rec[q]
        if not bc_active(C.rec_style[r], C.rec_t0[r], t):
            continue
        k = C.gbc_node[q]
        d = C.gbc_dir[q]
        v_new = gtmp[d, k]
        for f in range(nf):
            m = g[f, GM, k]
            if m <= S.mass_tol:
                continue
            v_old = g[f, GPX + d, k] / m
            f_needed = m * (v_new - v_old) / dt
            # a node shared by several conditions credits its reaction to the first one
            reaction = f_needed - g[f, GFX + d, k]
            g[f, GFX + d, k] = f_needed
            ga[f, d, k] = f_needed / m
            gvn[f, d, k] = v_new
            C.rec_force[r] += reaction
            C.rec_work[r] += reaction * 0.5 * (v_old + v_new) * dt
    for q in range(C.sym_out.size):
        ko = C.sym_out[q]
        ki = C.sym_in[q]
        d = C.sym_dir[q]
        for f in range(nf):
            m = g[f, GM, ko]
            if m > S.mass_tol:
                fi = f if g[f, GM, ki] > 0.0 else 0
                v_new = -gvn[fi, d, ki]
                v_old = g[f, GPX + d, ko] / m
                gvn[f, d, ko] = v_new
                ga[f, d, ko] = (v_new - v_old) / dt


# ---- stress updates --------------------------------------------------------------------
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
def _stress_update(p, dt, L00, L01, L10, L11, mat, F, stress, hist, w, mat_params,
                   plane_stress):
    """One stress update of particle p over dt with its velocity gradient."""
    e00, e01, e10, e11 = _increment_exp(L00, L01, L10, L11, dt)
    _apply_increment(p, e00, e01, e10, e11, F)
    m = mat[p]
    material_update(m, p, dt, L00, L01, L10, L11, F, stress, hist, w, mat_params[m],
                    plane_stress)


@njit(cache=True, inline="always")
def _stress_updates(p, dt_pre, dt_stress, L00, L01, L10, L11, mat, F, stress, hist, w,
                    mat_params, plane_stress):
    """The stress updates of one particle with one velocity gradient: a carried-over
    USAVG+ / USL+ update of dt_pre, then this step's of dt_stress (either may be 0).
    USAVG+ has dt_pre = dt_stress = dt/2, so the increment exponential is found once
    and applied twice (the same numbers as two separate updates).  One call site of
    the material update, so its inlined code exists once per pass."""
    e00 = e01 = e10 = e11 = 0.0
    m = mat[p]
    for i in range(2):
        dt_i = dt_pre if i == 0 else dt_stress
        if dt_i <= 0.0:
            continue
        if i == 0 or dt_pre != dt_stress:
            e00, e01, e10, e11 = _increment_exp(L00, L01, L10, L11, dt_i)
        _apply_increment(p, e00, e01, e10, e11, F)
        material_update(m, p, dt_i, L00, L01, L10, L11, F, stress, hist, w, mat_params[m],
                        plane_stress)


@njit(**PARALLEL_TASK)
def _stress_pass(P, G, K, S, dt_pre, dt_stress, scatter):
    """Each particle's velocity gradient from its own fields' grid velocities, its
    stress updates (``_stress_updates``), and with ``scatter`` its internal forces
    into the same fields of its chunk's buffer."""
    # plain local arrays for the parallel loop (module docstring)
    vol0 = P.vol0
    mat = P.mat
    F = P.F
    stress = P.stress
    hist = P.hist
    w = P.w
    wij = P.wij
    wc = P.wc
    gv = G.gv
    gbuf = G.gbuf
    cut = K.cut
    vfld = K.vfld
    mat_params = S.mat_params
    plane_stress = S.plane_stress
    n = P.pos.shape[1]
    nch = S.nch
    nnx = int(G.geom[4])
    for c in prange(nch):
        buf = gbuf[c]
        if scatter:
            buf[0, GFX] = 0.0
            buf[0, GFY] = 0.0
        for p in range(c * n // nch, (c + 1) * n // nch):
            r = wc[p]
            i0 = wij[p, 0]
            j0 = wij[p, 1]
            if dt_stress > 0.0 or dt_pre > 0.0:
                L00, L01, L10, L11 = _velocity_gradient(p, r, i0, j0, nnx, gv, vfld, cut)
                _stress_updates(p, dt_pre, dt_stress, L00, L01, L10, L11, mat, F, stress, hist,
                                w, mat_params, plane_stress)
            if not scatter:
                continue
            vol = vol0[p] * (F[0, p] * F[3, p] - F[1, p] * F[2, p]) * F[4, p]
            sxx = stress[0, p] * vol
            syy = stress[1, p] * vol
            sxy = stress[2, p] * vol
            _internal_forces(buf, p, r, i0, j0, nnx, vfld, cut, sxx, syy, sxy)


# The passes run as tasks through driver-side wrappers (inlined into the driver): a
# wrapper gets its pass's address (``core/linking``) and the pass's extra arguments
# after (P, G, K, S), whose types ``PASS_ARGS`` names for compiling it.
PASS_ARGS = {"_stress_pass": (float64, float64, boolean), "_particle_pass": (boolean,)}


@njit(cache=True, inline="always")
def stress_and_forces(P, G, C, K, S, stress_pass):
    """Stress update (USF / USAVG first half, plus a carried-over USAVG+ / USL+ last
    half) fused with the internal forces into the chunk buffers."""
    pending = S.clock[CLOCK_PENDING]
    S.clock[CLOCK_PENDING] = 0.0
    call_task(stress_pass, (P, G, K, S, pending, S.dt_first, S.nch > 0))  # a runtime True


@njit(cache=True, inline="always")
def flush_stress(P, G, C, K, S, stress_pass):
    """Apply a carried USAVG+ / USL+ stress half now (before stresses or energies are
    read, or when a run stops)."""
    pending = S.clock[CLOCK_PENDING]
    if pending > 0.0:
        S.clock[CLOCK_PENDING] = 0.0
        call_task(stress_pass, (P, G, K, S, 0.0, pending, S.nch < 0))   # a runtime False


# ---- grid ------------------------------------------------------------------------------
@njit(**PARALLEL_TASK)
def reduce_forces(P, G, C, K, S):
    """Add the chunks' internal forces of field 0 to the grid forces (the loads)."""
    g = G.g
    gbuf = G.gbuf
    nch = S.nch
    for k in prange(g.shape[2]):
        fx = 0.0
        fy = 0.0
        for c in range(nch):
            fx += gbuf[c, 0, GFX, k]
            fy += gbuf[c, 0, GFY, k]
        g[0, GFX, k] += fx
        g[0, GFY, k] += fy


@njit(**PARALLEL_TASK)
def accelerate(P, G, C, K, S):
    """Field 0's accelerations and updated velocities on every node."""
    dt = S.dt
    mass_tol = S.mass_tol
    g = G.g
    ga = G.ga
    gvn = G.gvn
    for k in prange(g.shape[2]):
        accelerate_node(g, ga, gvn, 0, k, dt, mass_tol)


@njit(**PARALLEL_TASK)
def reduce_extrapolation(P, G, C, K, S):
    """Sum the chunks' mass and momentum of field 0 and its velocities (before
    conditions)."""
    g = G.g
    gv = G.gv
    gbuf = G.gbuf
    nch = S.nch
    mass_tol = S.mass_tol
    for k in prange(g.shape[2]):
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
        if m > mass_tol:
            gv[0, 0, k] = px / m
            gv[0, 1, k] = py / m
        else:
            gv[0, 0, k] = 0.0
            gv[0, 1, k] = 0.0


# ---- particles -> grid -----------------------------------------------------------------
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


@njit(cache=True, inline="always")
def scatter_mass_momentum(b0, r, i0, j0, nnx, m, mvx, mvy):
    """A particle's mass and momentum onto one field's buffer rows."""
    for b in range(NA):
        sy = r[3 + b]
        row = (j0 + b) * nnx + i0
        for a in range(NA):
            s = sy * r[a]
            k = row + a
            b0[GM, k] += s * m
            b0[GPX, k] += s * mvx
            b0[GPY, k] += s * mvy


@njit(cache=True, inline="always")
def _scatter_particle(buf, p, r, i0, j0, geom, m, x, y, vx, vy, vfld, cut, cnear,
                      crack_lists, conflicts):
    """Particle p's mass and momentum to the grid: its field choice and crack rows in
    a multi-field build (``crack_lists`` from the field module), else field 0."""
    if MULTI_FIELD:
        return assign_and_scatter(buf, p, r, i0, j0, geom, m, x, y, m * vx, m * vy, vfld, cut,
                                  cnear, crack_lists, conflicts)
    scatter_mass_momentum(buf[0], r, i0, j0, int(geom[4]), m, m * vx, m * vy)
    return conflicts


@njit(**PARALLEL_TASK)
def _particle_pass(P, G, K, S, move):
    """With ``move``: grid -> particles (FLIP velocity and position with grid and
    particle damping, as NairnMPM applies them; the USL- / USAVG- stress update).
    Then, in both cases, each particle's weights (cached) and its mass and momentum
    to the grid.  One function for both: a parallel loop costs seconds to compile."""
    # plain local arrays for the parallel loop (module docstring)
    pos = P.pos
    vel = P.vel
    mass = P.mass
    lp = P.lp
    mat = P.mat
    F = P.F
    stress = P.stress
    hist = P.hist
    w = P.w
    pdamp = P.pdamp
    left = P.left
    wij = P.wij
    wc = P.wc
    geom = G.geom
    bounds = G.bounds
    ga = G.ga
    gvn = G.gvn
    gbuf = G.gbuf
    bad = G.bad
    vfld = K.vfld
    cut = K.cut
    chunk_counts = K.chunk_counts
    cnear = K.cnear
    crack_lists = field_lists(P, K)
    mat_params = S.mat_params
    plane_stress = S.plane_stress
    n = pos.shape[1]
    nch = S.nch
    nnx = int(geom[4])
    idx = 1.0 / geom[2]
    idy = 1.0 / geom[3]
    dt = S.dt
    dt_stress = S.dt_update
    damping = S.damping
    vmax = S.vmax
    for c in prange(nch):
        buf = gbuf[c]
        buf[0, GM] = 0.0
        buf[0, GPX] = 0.0
        buf[0, GPY] = 0.0
        bad[c, 0] = -1
        conflicts = 0
        for p in range(c * n // nch, (c + 1) * n // nch):
            if move:
                ax, ay, vx, vy, L00, L01, L10, L11 = _grid_to_particle(
                    p, wc[p], wij[p, 0], wij[p, 1], nnx, ga, gvn, vfld, cut,
                    UPDATE_STRESS and dt_stress > 0.0)
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
                if UPDATE_STRESS:   # a build constant: the update's inlined code only where used
                    if dt_stress > 0.0:
                        _stress_update(p, dt_stress, L00, L01, L10, L11, mat, F, stress, hist, w,
                                       mat_params, plane_stress)
                if bad[c, 0] < 0:
                    if not (math.isfinite(nvx) and math.isfinite(nvy) and math.isfinite(x)
                            and math.isfinite(y) and math.isfinite(stress[0, p])):
                        bad[c, 0] = p
                        bad[c, 1] = STATUS_NONFINITE
                    elif nvx * nvx + nvy * nvy > vmax * vmax:
                        bad[c, 0] = p
                        bad[c, 1] = STATUS_RUNAWAY
            else:
                x = pos[0, p]
                y = pos[1, p]
                nvx = vel[0, p]
                nvy = vel[1, p]
            _store_weights(p, pos, lp, geom, idx, idy, wij, wc)
            conflicts = _scatter_particle(buf, p, wc[p], wij[p, 0], wij[p, 1], geom,
                                          mass[p], x, y, nvx, nvy, vfld, cut, cnear,
                                          crack_lists, conflicts)
        if MULTI_FIELD:
            chunk_counts[c] = conflicts


@njit(cache=True, inline="always")
def weights_and_mass(P, G, C, K, S, particle_pass):
    """Weights of every particle (cached) and their mass and momentum on the grid."""
    call_task(particle_pass, (P, G, K, S, S.nch < 0))   # a runtime False


# ---- grid -> particles -----------------------------------------------------------------
@njit(cache=True, inline="always")
def update_and_extrapolate(P, G, C, K, S, particle_pass):
    """Grid -> particles, then each particle's new weights and its mass and momentum
    back to the grid (the next extrapolation: in every method positions and
    velocities do not change in between)."""
    call_task(particle_pass, (P, G, K, S, S.nch > 0))   # a runtime True


# ---- bookkeeping -----------------------------------------------------------------------
@njit(**TASK)
def advance_clock(P, G, C, K, S):
    """The step is taken: the time moves on, and USL+ / USAVG+ carry the last stress
    half into the next stress pass (it has the same velocity gradient)."""
    S.clock[CLOCK_T] += S.dt
    if S.plus:
        S.clock[CLOCK_PENDING] = S.dt_last


@njit(**TASK)
def check_status(P, G, C, K, S):
    """The first chunk's bad particle (NaN or runaway), else too many particles that
    tried to leave the grid, into ``S.status``."""
    bad = G.bad
    n_left = 0
    for c in range(S.nch):
        if bad[c, 0] >= 0:
            S.status[0] = bad[c, 1]
            S.status[1] = bad[c, 0]
            return
        n_left += bad[c, 2]
    if n_left >= S.leave_limit:
        for c in range(S.nch):
            if bad[c, 2] > 0:
                S.status[0] = STATUS_LEFT_GRID
                S.status[1] = bad[c, 3]
                return
    S.status[0] = STATUS_OK
