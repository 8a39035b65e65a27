"""Crack-tip J integral and K from the grid, against the exact LEFM near-tip field.

The scene: a 40 x 40 mm square of particles (0.5 mm cells, 2 x 2 particles per cell)
with a straight crack from the edge of the body to the centre.  The crack line is
put 0.01 cell above the node row through the centre (y_crack = 20 mm + 0.005 mm), so
no node or particle is on it, yet the square contours centred on that node cross it
cleanly (almost at a node, f = 0.99 along the crossed edge).  Every particle is
given the exact Williams leading-term (K-dominant) field for the chosen K_I, K_II at
its position (which stays the reference position: the field is small-strain
linear elasticity, displacements are ~1e-3 mm): Cauchy stress (szz = nu (sxx + syy)
in plane strain), F = I + grad u, strain energy density w = 1/2 sigma:eps, zero
velocity.  The crack's above/below surfaces are put at the exact displaced positions
so the COD is the analytic one.  J from the contour must then be
(K_I^2 + K_II^2)/E', E' = E (plane stress) or E/(1 - nu^2) (plane strain), for every
contour size, and K from J + COD must recover the input.

Formulas (Anderson, Fracture Mechanics, Tables 2.1-2.2), crack along -x, tip at the
origin, theta in (-pi, pi], kappa = 3 - 4 nu (plane strain) or (3 - nu)/(1 + nu):

  Mode I:  sxx = K/sqrt(2 pi r) cos(t/2) [1 - sin(t/2) sin(3t/2)]
           syy = K/sqrt(2 pi r) cos(t/2) [1 + sin(t/2) sin(3t/2)]
           sxy = K/sqrt(2 pi r) cos(t/2) sin(t/2) cos(3t/2)
           ux  = K/(2 mu) sqrt(r/2pi) cos(t/2) [kappa - 1 + 2 sin^2(t/2)]
           uy  = K/(2 mu) sqrt(r/2pi) sin(t/2) [kappa + 1 - 2 cos^2(t/2)]
  Mode II: sxx = -K/sqrt(2 pi r) sin(t/2) [2 + cos(t/2) cos(3t/2)]
           syy = K/sqrt(2 pi r) sin(t/2) cos(t/2) cos(3t/2)
           sxy = K/sqrt(2 pi r) cos(t/2) [1 - sin(t/2) sin(3t/2)]
           ux  = K/(2 mu) sqrt(r/2pi) sin(t/2) [kappa + 1 + 2 cos^2(t/2)]
           uy  = -K/(2 mu) sqrt(r/2pi) cos(t/2) [kappa - 1 - 2 sin^2(t/2)]

The displacement gradient is the central difference of the displacement formulas;
the builder checks that its symmetric part equals the strain from Hooke's law and
the stress formulas (which catches a typo in either).

With particles at the 1/4 and 3/4 points of each cell (lp = 1/4) uGIMP weights equal
the linear ones, so the cases are also run with the particle lattice shifted by 0.1
cell, where particle domains straddle nodes and the two shape functions differ.

Run ``python tests/test_jintegral.py`` for the table of J errors per contour size.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from nairnmpm_py.core.grid import Grid
from nairnmpm_py.core.particles import Particles
from nairnmpm_py.core.shape import LINEAR, UGIMP
from nairnmpm_py.cracks.crossing import line_crosses_crack, segment_intersection
from nairnmpm_py.cracks.geometry import CrackSet, EXTERIOR_END
from nairnmpm_py.cracks.jintegral import (j_integral, nodal_fields, stress_intensity,
                                          tip_cod, to_mpa_sqrt_m)

E, NU, RHO = 70000.0, 0.33, 2.7e-3      # MPa, -, g/mm^3
L, H, PPC = 40.0, 0.5, 2                 # mm, mm, particles per cell side
SIZES = range(2, 9)


def elastic(plane_stress):
    mu = E / (2.0 * (1.0 + NU))
    kappa = (3.0 - NU) / (1.0 + NU) if plane_stress else 3.0 - 4.0 * NU
    e_prime = E if plane_stress else E / (1.0 - NU * NU)
    return mu, kappa, e_prime


def williams_displacement(x, y, KI, KII, mu, kappa):
    r = np.hypot(x, y)
    th = np.arctan2(y, x)
    c, s = np.cos(th / 2.0), np.sin(th / 2.0)
    f = np.sqrt(r / (2.0 * np.pi)) / (2.0 * mu)
    ux = f * (KI * c * (kappa - 1.0 + 2.0 * s * s) + KII * s * (kappa + 1.0 + 2.0 * c * c))
    uy = f * (KI * s * (kappa + 1.0 - 2.0 * c * c) - KII * c * (kappa - 1.0 - 2.0 * s * s))
    return ux, uy


def williams_stress(x, y, KI, KII):
    r = np.hypot(x, y)
    th = np.arctan2(y, x)
    c, s = np.cos(th / 2.0), np.sin(th / 2.0)
    c3, s3 = np.cos(1.5 * th), np.sin(1.5 * th)
    a = 1.0 / np.sqrt(2.0 * np.pi * r)
    sxx = a * (KI * c * (1.0 - s * s3) - KII * s * (2.0 + c * c3))
    syy = a * (KI * c * (1.0 + s * s3) + KII * s * c * c3)
    sxy = a * (KI * c * s * c3 + KII * c * (1.0 - s * s3))
    return sxx, syy, sxy


def local_field(x, y, KI, KII, plane_stress):
    """Stress (3, n), displacement gradient (2, 2, n) and strain (3, n) in the tip frame."""
    mu, kappa, _ = elastic(plane_stress)
    sxx, syy, sxy = williams_stress(x, y, KI, KII)
    eps = 1e-7 * np.hypot(x, y)
    grad = np.empty((2, 2) + x.shape)
    for j, (ex, ey) in enumerate(((eps, 0.0), (0.0, eps))):
        up = williams_displacement(x + ex, y + ey, KI, KII, mu, kappa)
        um = williams_displacement(x - ex, y - ey, KI, KII, mu, kappa)
        for i in range(2):
            grad[i, j] = (up[i] - um[i]) / (2.0 * eps)
    # Hooke's law (plane strain: eps_zz = 0; plane stress: s_zz = 0)
    if plane_stress:
        exx = (sxx - NU * syy) / E
        eyy = (syy - NU * sxx) / E
    else:
        exx = ((1 - NU * NU) * sxx - NU * (1 + NU) * syy) / E
        eyy = ((1 - NU * NU) * syy - NU * (1 + NU) * sxx) / E
    exy = sxy / (2.0 * mu)
    scale = np.abs(np.stack([exx, eyy, exy])).max(axis=0)
    err = np.stack([grad[0, 0] - exx, grad[1, 1] - eyy, 0.5 * (grad[0, 1] + grad[1, 0]) - exy])
    assert np.all(np.abs(err) <= 1e-5 * scale), "Williams displacement and stress disagree"
    return np.stack([sxx, syy, sxy]), grad, np.stack([exx, eyy, exy])


def build(kind, KI, KII, angle_deg=0.0, tip_end="end", plane_stress=False, shift=0.0,
          tip_offset=(0.0, 0.01)):
    """Grid, particles and crack for the exact near-tip field (see module doc).

    shift: the particle lattice is moved by shift * cell in x and y.  With shift = 0
    every particle domain lies inside one cell and uGIMP weights equal the linear
    ones; a shift makes domains straddle nodes so uGIMP is really exercised.
    tip_offset: tip position relative to the centre node, in cells.
    """
    n = int(round(L / H))
    grid = Grid(0.0, L, 0.0, L, n, n)
    a = math.radians(angle_deg)
    d = np.array([math.cos(a), math.sin(a)])           # crack-tip direction
    nrm = np.array([-d[1], d[0]])
    tip = np.array([L / 2 + tip_offset[0] * H, L / 2 + tip_offset[1] * H])
    # particles on a regular lattice
    off = (np.arange(PPC) + 0.5) / PPC * H
    xs = (np.arange(n)[:, None] * H + off[None, :]).ravel() + shift * H
    X, Y = np.meshgrid(xs, xs)
    pos = np.vstack([X.ravel(), Y.ravel()])
    rel = pos - tip[:, None]
    xl, yl = d @ rel, nrm @ rel
    sig_l, grad_l, eps_l = local_field(xl, yl, KI, KII, plane_stress)
    R = np.column_stack([d, nrm])                        # local -> global
    S_l = np.array([[sig_l[0], sig_l[2]], [sig_l[2], sig_l[1]]])
    S = np.einsum("ia,abn,jb->ijn", R, S_l, R)
    G = np.einsum("ia,abn,jb->ijn", R, grad_l, R)
    npart = pos.shape[1]
    vol = (H / PPC) ** 2
    p = Particles.allocate(pos, np.zeros((2, npart)), np.full(npart, RHO * vol),
                           np.full(npart, vol), np.full((2, npart), 0.5 / PPC),
                           np.zeros(npart, dtype=np.int32), 1, np.zeros(npart))
    szz = np.zeros(npart) if plane_stress else NU * (S[0, 0] + S[1, 1])
    p.stress[:] = np.stack([S[0, 0], S[1, 1], S[0, 1], szz])
    p.F[0], p.F[1], p.F[2], p.F[3] = 1 + G[0, 0], G[0, 1], G[1, 0], 1 + G[1, 1]
    if plane_stress:
        p.F[4] = 1.0 - NU / E * (sig_l[0] + sig_l[1])
    p.w[:] = 0.5 * (sig_l[0] * eps_l[0] + sig_l[1] * eps_l[1] + 2.0 * sig_l[2] * eps_l[2])
    # crack: from where the ray tip - t d leaves the body to the tip, ~half-cell chords
    ts = []
    for k in range(2):
        if -d[k] < -1e-12:
            ts.append((0.0 - tip[k]) / -d[k])
        elif -d[k] > 1e-12:
            ts.append((L - tip[k]) / -d[k])
    t_max = min(ts)
    nseg = int(math.ceil(t_max / (0.5 * H)))
    t = np.linspace(t_max, 0.0, nseg + 1)                # far end -> tip
    if tip_end == "start":
        t = t[::-1]
    pts = tip[None, :] - t[:, None] * d[None, :]
    tips = (EXTERIOR_END, 1) if tip_end == "end" else (1, EXTERIOR_END)
    cracks = CrackSet.from_polylines([pts], [np.full(len(pts), -1)], [tips])
    # exact surface displacements: "above" (left of first -> last) is the local +y
    # side for an end tip and the local -y side for a start tip
    mu, kappa, _ = elastic(plane_stress)
    above_sign = 1.0 if tip_end == "end" else -1.0
    for sgn, surf in ((above_sign, cracks.above), (-above_sign, cracks.below)):
        ux, uy = williams_displacement(-t, np.full_like(t, math.copysign(0.0, sgn)),
                                       KI, KII, mu, kappa)
        surf += np.outer(d, ux) + np.outer(nrm, uy)
    return grid, p, cracks


def contour_results(kind, KI, KII, angle_deg=0.0, tip_end="end", plane_stress=False,
                    shift=0.0, tip_offset=(0.0, 0.01), sizes=SIZES):
    grid, p, cracks = build(kind, KI, KII, angle_deg, tip_end, plane_stress, shift, tip_offset)
    fields = nodal_fields(grid, p, cracks, kind)
    res = [j_integral(grid, fields, cracks, 0, tip_end, s) for s in sizes]
    return grid, p, cracks, fields, res


KINDS = [pytest.param(LINEAR, id="linear"), pytest.param(UGIMP, id="uGIMP")]


# ------------------------------------------------------------------ crossing test

def _crack(points, ext_start=False, ext_end=False):
    pts = np.asarray(points, dtype=float)
    return pts[:, 0].copy(), pts[:, 1].copy(), 0, len(pts), ext_start, ext_end


def test_crossing_above_below_none():
    cx, cy, f, n, e0, e1 = _crack([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    assert line_crosses_crack(0.5, 0.3, 0.5, -0.3, cx, cy, f, n, e0, e1) == 1     # above
    assert line_crosses_crack(1.5, -0.3, 1.2, 0.4, cx, cy, f, n, e0, e1) == -1    # below
    assert line_crosses_crack(0.5, 0.3, 1.5, 0.1, cx, cy, f, n, e0, e1) == 0      # same side
    assert line_crosses_crack(2.5, 0.3, 2.5, -0.3, cx, cy, f, n, e0, e1) == 0     # beyond the end
    # a node on the crack counts as crossed, a particle on it does not
    assert line_crosses_crack(0.5, 0.3, 0.5, 0.0, cx, cy, f, n, e0, e1) == 1
    assert line_crosses_crack(0.5, 0.0, 0.5, -0.3, cx, cy, f, n, e0, e1) == 0
    # reversed polyline: sides swap
    rx, ry = cx[::-1].copy(), cy[::-1].copy()
    assert line_crosses_crack(0.5, 0.3, 0.5, -0.3, rx, ry, f, n, e0, e1) == -1


def test_crossing_even_number_of_hits_is_no_crossing():
    # a U-shaped crack: the line crosses both arms
    cx, cy, f, n, e0, e1 = _crack([[0.0, 1.0], [0.0, 0.0], [2.0, 0.0], [2.0, 1.0]])
    assert line_crosses_crack(-0.5, 0.5, 2.5, 0.5, cx, cy, f, n, e0, e1) == 0
    assert line_crosses_crack(-0.5, 0.5, 1.0, 0.5, cx, cy, f, n, e0, e1) != 0


def test_crossing_exterior_end_extension():
    pts = [[0.0, 0.0], [1.0, 0.0]]
    for args, expect in (((1.5, 0.5, 1.5, -0.5), 0), ((-1.5, 0.5, -1.5, -0.5), 0)):
        assert line_crosses_crack(*args, *_crack(pts)) == expect
    # extended by 4 x the end chord: to x = 5 at the end, to x = -4 at the start
    assert line_crosses_crack(4.9, 0.5, 4.9, -0.5, *_crack(pts, ext_end=True)) == 1
    assert line_crosses_crack(5.1, 0.5, 5.1, -0.5, *_crack(pts, ext_end=True)) == 0
    assert line_crosses_crack(-3.9, -0.5, -3.9, 0.5, *_crack(pts, ext_start=True)) == -1
    assert line_crosses_crack(-3.9, -0.5, -3.9, 0.5, *_crack(pts, ext_end=True)) == 0
    assert line_crosses_crack(4.9, 0.5, 4.9, -0.5, *_crack(pts, True, True)) == 1
    # a longer crack: only the end chord is extended, by its own length
    pts3 = [[0.0, 0.0], [3.0, 0.0], [3.5, 0.0]]
    assert line_crosses_crack(5.4, 0.5, 5.4, -0.5, *_crack(pts3, ext_end=True)) == 1
    assert line_crosses_crack(5.6, 0.5, 5.6, -0.5, *_crack(pts3, ext_end=True)) == 0


def test_crossing_through_interior_vertex_counted_once():
    # kinked crack with its interior vertex exactly on the particle-node line x = 0
    pts = [[-2.0, -0.5], [0.0, 0.0], [2.0, 0.5]]
    assert line_crosses_crack(0.0, 1.0, 0.0, -1.0, *_crack(pts)) == 1
    assert line_crosses_crack(0.0, -1.0, 0.0, 1.0, *_crack(pts)) == -1
    # straight crack, vertex on the line
    pts = [[-1.0, 0.0], [0.0, 0.0], [1.0, 0.0]]
    assert line_crosses_crack(0.0, 1.0, 0.0, -1.0, *_crack(pts)) == 1
    assert line_crosses_crack(0.0, -0.25, 0.0, 0.5, *_crack(pts)) == -1
    # a line that only touches the polyline at a vertex does not cross
    pts = [[-2.0, -1.0], [0.0, 0.0], [2.0, -1.0]]
    assert line_crosses_crack(-1.0, 0.0, 1.0, 0.0, *_crack(pts)) == 0
    assert line_crosses_crack(1.0, 0.0, -1.0, 0.0, *_crack(pts)) == 0
    pts = [[-2.0, 1.0], [0.0, 0.0], [2.0, 1.0]]
    assert line_crosses_crack(-1.0, 0.0, 1.0, 0.0, *_crack(pts)) == 0


def test_segment_intersection():
    hit, t, u = segment_intersection(0.0, 0.0, 2.0, 0.0, 1.0, -1.0, 1.0, 3.0)
    assert hit and t == pytest.approx(0.5) and u == pytest.approx(0.25)
    hit, t, u = segment_intersection(0.0, 0.0, 2.0, 0.0, 3.0, -1.0, 3.0, 1.0)
    assert not hit and t == pytest.approx(1.5)
    hit, t, u = segment_intersection(0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 1.0)
    assert not hit and math.isnan(t)


# ------------------------------------------------------------------ nodal fields

@pytest.mark.parametrize("kind", KINDS)
def test_nodal_fields_uniform_and_split(kind):
    """Uniform particle values come back exactly at every node that has mass, and
    field 1 of the nodes next to the crack holds only the other side's particles."""
    grid = Grid(0.0, 4.0, 0.0, 4.0, 8, 8)
    xs = (np.arange(16) + 0.5) * 0.25
    X, Y = np.meshgrid(xs, xs)
    pos = np.vstack([X.ravel(), Y.ravel()])
    n = pos.shape[1]
    vol = 0.25 ** 2
    p = Particles.allocate(pos, np.zeros((2, n)), np.full(n, 2.0 * vol), np.full(n, vol),
                           np.full((2, n), 0.25), np.zeros(n, dtype=np.int32), 1, np.zeros(n))
    above = pos[1] > 2.0
    p.vel[0] = np.where(above, 3.0, 1.0)
    p.stress[0] = np.where(above, 5.0, -5.0)
    p.w[:] = 0.7
    p.F[1] = 0.01
    cracks = CrackSet.from_polylines([np.array([[0.0, 2.01], [1.0, 2.01], [2.0, 2.01]])],
                                     [np.full(3, -1)], [(EXTERIOR_END, 1)])
    f = nodal_fields(grid, p, cracks, kind)
    has = f.mass[0] > 0
    assert np.allclose(f.W[0][has], 0.7) and np.allclose(f.grad[0, 1][has], 0.01)
    # node (2, 4) at (1, 2) mm is 0.01 mm below the crack: field 0 = below, field 1 = above
    k = int(grid.node_index(np.array(2), np.array(4)))
    assert f.crack[k] == 0 and f.side[k] == 1
    assert f.stress[0, 0, k] == pytest.approx(-5.0) and f.stress[1, 0, k] == pytest.approx(5.0)
    assert f.K[0, k] == pytest.approx(0.5 * 2.0 * 1.0) and f.K[1, k] == pytest.approx(0.5 * 2.0 * 9.0)
    # ahead of the tip (x = 3 mm) the continuum mixes both sides in field 0
    k = int(grid.node_index(np.array(6), np.array(4)))
    assert f.crack[k] == -1 and -5.0 < f.stress[0, 0, k] < 5.0
    # total mass is conserved over the two fields
    assert f.mass.sum() == pytest.approx(p.mass.sum())


def test_node_seeing_two_cracks_is_an_error():
    grid = Grid(0.0, 4.0, 0.0, 4.0, 8, 8)
    xs = (np.arange(16) + 0.5) * 0.25
    X, Y = np.meshgrid(xs, xs)
    pos = np.vstack([X.ravel(), Y.ravel()])
    n = pos.shape[1]
    p = Particles.allocate(pos, np.zeros((2, n)), np.ones(n), np.ones(n), np.full((2, n), 0.25),
                           np.zeros(n, dtype=np.int32), 1, np.zeros(n))
    cracks = CrackSet.from_polylines(
        [np.array([[0.0, 2.01], [2.0, 2.01]]), np.array([[0.0, 2.2], [2.0, 2.2]])],
        [np.full(2, -1), np.full(2, -1)], [(EXTERIOR_END, 1), (EXTERIOR_END, 1)])
    with pytest.raises(ValueError, match="two different cracks"):
        nodal_fields(grid, p, cracks, LINEAR)
    f = nodal_fields(grid, p, cracks, LINEAR, strict=False)
    assert f.multi.any()
    with pytest.raises(ValueError, match="two cracks|crosses the J contour"):
        j_integral(grid, f, cracks, 0, "end", 2)


# ------------------------------------------------------------------ J and K vs LEFM

def tolerance(size):
    """Allowed |J/J_exact - 1| for a contour of half-size ``size`` cells.

    Nodal values are mass-weighted averages over about a cell, which smooths the
    r^-1/2 field: the error falls like (cell/size)^2.  Measured: 1.0-1.4 % at size 2,
    0.5-0.7 % at 3, < 0.4 % from 4 on, < 0.1 % at 8 (``python tests/test_jintegral.py``).
    """
    return 0.002 + 0.015 * (2.0 / size) ** 2


def _check_J(res, J_exact, J2_exact=0.0):
    for r in res:
        tol = tolerance(r.size_cells)
        assert abs(r.J1 / J_exact - 1.0) < tol, (r.size_cells, r.J1 / J_exact - 1.0)
        assert abs(r.J2 - J2_exact) < tol * J_exact, (r.size_cells, (r.J2 - J2_exact) / J_exact)
    J1 = np.array([r.J1 for r in res])
    assert np.ptp(J1) < 0.015 * J_exact          # path independence, sizes 2..8


SHIFTS = [pytest.param(0.0, id="cell-centred"), pytest.param(0.1, id="shifted")]


@pytest.mark.parametrize("shift", SHIFTS)
@pytest.mark.parametrize("plane_stress", [False, True], ids=["plane_strain", "plane_stress"])
@pytest.mark.parametrize("kind", KINDS)
def test_mode_I(kind, plane_stress, shift):
    KI = 10.0
    mu, kappa, e_prime = elastic(plane_stress)
    grid, p, cracks, fields, res = contour_results(kind, KI, 0.0, plane_stress=plane_stress,
                                                   shift=shift)
    _check_J(res, KI ** 2 / e_prime)
    r = res[0]
    assert np.allclose(r.crossing, [L / 2 - 2 * H, L / 2 + 0.01 * H])
    assert np.allclose(r.direction, [1.0, 0.0]) and r.tip == cracks.count[0] - 1
    assert r.centre == (40, 40) and r.corners.tolist() == [[38, 38], [42, 38], [42, 42], [38, 42]]
    # the crossing lies on the chord crossing_beyond -> crossing_particle, tip side first
    P = cracks.plane
    assert P[0, r.crossing_particle] > P[0, r.crossing_beyond]
    assert np.allclose(P[:, r.crossing_particle] + r.crossing_fraction
                       * (P[:, r.crossing_beyond] - P[:, r.crossing_particle]), r.crossing)
    dn, dt = tip_cod(cracks, 0, "end")
    assert dn > 0 and abs(dt) < 1e-9 * dn
    for rr in res:
        k1, k2 = stress_intensity(rr.J1, dn, dt, mu, NU, plane_stress)
        assert k1 == pytest.approx(KI, rel=0.01) and abs(k2) < 1e-6 * KI
    assert to_mpa_sqrt_m(KI) == pytest.approx(KI * math.sqrt(1e-3))


@pytest.mark.parametrize("shift", SHIFTS)
@pytest.mark.parametrize("kind", KINDS)
def test_mode_II(kind, shift):
    KII = 10.0
    mu, kappa, e_prime = elastic(False)
    grid, p, cracks, fields, res = contour_results(kind, 0.0, KII, shift=shift)
    _check_J(res, KII ** 2 / e_prime)
    dn, dt = tip_cod(cracks, 0, "end")
    assert dt > 0 and abs(dn) < 1e-9 * dt             # positive K_II: above slides forward
    for rr in res:
        k1, k2 = stress_intensity(rr.J1, dn, dt, mu, NU, False)
        assert k2 == pytest.approx(KII, rel=0.01) and abs(k1) < 1e-6 * KII


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("angle, tip_end, tip_offset", [
    (30.0, "end", (0.0, 0.01)),
    (180.0, "start", (0.0, 0.01)),        # crack to the right, tip = first particle
    (-120.0, "end", (0.0, 0.01)),         # crack crosses the top edge of the contour
    (0.0, "end", (0.37, 0.21)),           # tip off the node column; crossing at f = 0.79
], ids=["30deg", "180deg-start", "-120deg", "offset-tip"])
def test_rotated_mixed_mode(kind, angle, tip_end, tip_offset):
    """Whole field and crack rotated, mixed mode: checks the rotation into the tip
    frame, the K_I/K_II split and its signs, and the start-tip conventions.  For a
    mixed-mode K field J2 = -2 K_I K_II / E' (the crack-face terms cancel: W is the
    same on both faces)."""
    KI, KII = 10.0, -4.0
    mu, kappa, e_prime = elastic(False)
    grid, p, cracks, fields, res = contour_results(kind, KI, KII, angle, tip_end,
                                                   shift=0.1, tip_offset=tip_offset)
    _check_J(res, (KI ** 2 + KII ** 2) / e_prime, -2.0 * KI * KII / e_prime)
    a = math.radians(angle)
    assert np.allclose(res[0].direction, [math.cos(a), math.sin(a)])
    dn, dt = tip_cod(cracks, 0, tip_end)
    for rr in res:
        k1, k2 = stress_intensity(rr.J1, dn, dt, mu, NU, False)
        assert k1 == pytest.approx(KI, rel=0.01) and k2 == pytest.approx(KII, rel=0.01)


def test_contour_errors():
    grid, p, cracks = build(LINEAR, 10.0, 0.0)
    fields = nodal_fields(grid, p, cracks, LINEAR)
    with pytest.raises(ValueError, match="leaves the grid"):
        j_integral(grid, fields, cracks, 0, "end", 41)
    with pytest.raises(ValueError, match="leaves the grid"):
        j_integral(grid, fields, cracks, 0, "start", 2)     # the exterior end at x = 0
    with pytest.raises(ValueError, match="tip_end"):
        j_integral(grid, fields, cracks, 0, "middle", 2)
    short = CrackSet.from_polylines([np.array([[19.2, 20.005], [20.0, 20.005]])],
                                    [np.full(2, -1)], [(-1, 1)])
    fs = nodal_fields(grid, p, short, LINEAR)
    with pytest.raises(ValueError, match="crosses crack 0 0 times"):
        j_integral(grid, fs, short, 0, "end", 3)
    assert j_integral(grid, fs, short, 0, "end", 1).J1 != 0.0
    # nodes exactly on a crack: CRAMP's unexpected-side case, reported
    on_line = CrackSet.from_polylines([np.array([[0.0, 20.0], [20.0, 20.0]])],
                                      [np.full(2, -1)], [(EXTERIOR_END, 1)])
    with pytest.warns(RuntimeWarning, match="unexpected side"):
        nodal_fields(grid, p, on_line, LINEAR)
    # a crack chord along a contour edge (x = 19 mm) is refused
    along = CrackSet.from_polylines([np.array([[19.0, 22.0], [19.0, 20.3], [20.0, 20.3]])],
                                    [np.full(3, -1)], [(-1, 1)])
    with pytest.warns(RuntimeWarning):         # it also runs through nodes
        fa = nodal_fields(grid, p, along, LINEAR)
    with pytest.raises(ValueError, match="runs along a J-contour edge"):
        j_integral(grid, fa, along, 0, "end", 2)


def report():
    """Print J1/J_exact - 1 (%) per contour size for both shape functions."""
    o = (0.0, 0.01)
    cases = [("mode I plane strain", 10.0, 0.0, 0.0, "end", False, o),
             ("mode I plane stress", 10.0, 0.0, 0.0, "end", True, o),
             ("mode II plane strain", 0.0, 10.0, 0.0, "end", False, o),
             ("mixed 30 deg", 10.0, -4.0, 30.0, "end", False, o),
             ("mixed 180 deg start tip", 10.0, -4.0, 180.0, "start", False, o),
             ("mixed -120 deg", 10.0, -4.0, -120.0, "end", False, o),
             ("mixed offset tip", 10.0, -4.0, 0.0, "end", False, (0.37, 0.21))]
    print("J1/J_exact - 1 in %, then (J2 - J2_exact)/J_exact in %, for contour sizes",
          list(SIZES))
    for kind, kname, shift in ((LINEAR, "linear", 0.0), (UGIMP, "uGIMP", 0.0),
                               (LINEAR, "linear", 0.1), (UGIMP, "uGIMP", 0.1)):
        print(f"particle lattice shifted by {shift} cell")
        for name, KI, KII, ang, te, ps, off in cases:
            _, _, e_prime = elastic(ps)
            je = (KI ** 2 + KII ** 2) / e_prime
            j2e = -2.0 * KI * KII / e_prime
            *_, res = contour_results(kind, KI, KII, ang, te, ps, shift, off)
            e1 = " ".join(f"{100 * (r.J1 / je - 1):+6.2f}" for r in res)
            e2 = " ".join(f"{100 * (r.J2 - j2e) / je:+6.2f}" for r in res)
            print(f"{kname:7s} {name:24s} J1: {e1}   J2: {e2}")


if __name__ == "__main__":
    report()
