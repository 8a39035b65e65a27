"""Crack-tip J integral and stress intensity factors from the grid (2D, planar).

The method follows NairnMPM's (see shared notes JINTEGRAL.md sections 1-6; Guo and
Nairn 2004), re-implemented from the description, not the code:

1. Nodal fields: particle quantities are extrapolated to the nodes with the
   engine's shape functions (linear or uGIMP), separately per side of a crack as
   CRAMP does for velocity fields: at each node, field 0 holds the particles with no
   crack between particle and node, field 1 the particles across one crack.

   In a running scene (``step_nodal_fields``, through ``CrackScene.j_fields``) the
   side of each particle-node pair is the one the time step assigned (``K.vfld``,
   ``K.cut``, with the step's cached stencils and weights): step field 0 goes to J
   field 0, step field 1 or 2 to J field 1, whose crack is the node's slot 0 or 1
   and whose side is the sign of that slot's GSD row; a node whose pairs name two
   cracks (or step field 3, across both) is flagged ``multi``.  J thus integrates
   the fields the dynamics moved, and needs a current assignment: after a crack grew
   the scene extrapolates again before J reads it.

   ``nodal_fields`` is the standalone path, for particle sets with no running scene
   (tests, scripts): it has no step assignment, so it runs its own crossing test per
   pair (``crossing.line_crosses_crack``, exterior ends extended as the step's
   chords), the only crack-side test besides the step's.  It differs from the step's
   in two rules only: a pair crossing field 1's crack from the side opposite to the
   node's first such pair goes to field 0 (counted in ``conflicts``; only a node or
   particle on the crack line can do that; the step keeps it across), and a pair
   crossing two cracks flags the node (the step gives each node two crack slots and
   ignores a third crack).  Measured on the shipped scenes, neither rule ever
   applied: SENT B after 2,000 steps gives the same J to the last bit (no pair of
   the window on another side); the DCB to 12 ms (42,192 J evaluations, 23 growths)
   gives J within 2e-13 relative at every evaluation (J_tip at growth within 3e-16,
   R identical), far below what one pair on another side would change: the rounding
   of the step's cached weights (times the reciprocal cell size) against the
   standalone path's (divided by it).

   Nodal values are mass-weighted averages of particle values:

   * displacement gradient  grad u = F - I  (exact for small strain; for moderate
     strain with little rotation it is the usual approximation; NairnMPM uses R.V - I
     from F = V.R, which equals F - I when F is symmetric);
   * Cauchy stress sxx, syy, sxy (MPa);
   * strain energy density W = particle ``w`` (per *reference* volume, as NairnMPM's
     default ``rho0 * w_p``; per current volume differs by det F, negligible for
     small strain);
   * kinetic energy density K = 1/2 rho0 |v|^2 with rho0 = m / vol0 (per reference
     volume too, consistent with W; NairnMPM's default).

2. ``j_integral``: a square contour of half-size ``size_cells`` cells along grid
   lines, centred on the node nearest the crack tip, walked counter-clockwise through
   the nodes; trapezoid rule on nodal values.  Where the contour crosses the crack a
   phantom point is inserted; each side of it is integrated with that side's data:
   real nodes use field 0, and the phantom point interpolates (linearly along the
   edge) the node fields that belong to the side of the segment it closes or opens.
   Integrand f_k = (W + K) n_k - (sigma.n) . du/dx_k, n the outward normal.  J1 and J2
   are (Jx, Jy) rotated into the tip frame, the tip direction being the unit vector
   from the crack particle next to the tip towards the tip.

   J1 is the contour value J(x) of the paper (seed section 2, Eq. 3).  For cracks
   with traction laws the crack-tip energy release rate is J_tip = J(x) - W_B(x) at
   the crossing (Eq. 9/12): ``JResult`` returns the crossing point, the crack
   particles of the crossed chord and the fraction along it so that W_B(x) can be
   subtracted by the caller.

3. ``stress_intensity``: K_I and K_II from J and the crack-tip opening (JINTEGRAL.md
   section 6); ``tip_cod`` computes that opening as NairnMPM does.

Units: mm, N, MPa; J in N/mm (1 N/mm = 1000 J/m^2); K in MPa sqrt(mm)
(``to_mpa_sqrt_m`` converts to MPa sqrt(m)).

Differences from NairnMPM (deliberate):

* at a phantom point, a node field that has no particles is left out and the other
  node's value used alone (NairnMPM counts it as zero without renormalising);
* a node that sees two different cracks is an error (NairnMPM has fields [2], [3]);
  a contour that crosses the crack more than once, or crosses another crack, is an
  error rather than a retry or a crack-face integral;
* the contour is always started at the middle of its right side; the integral over
  the closed loop does not depend on where it starts;
* a crossing exactly at a contour node belongs to the edge that *ends* at that node
  (half-open (0, 1] along the walk) rather than NairnMPM's (min, max] in x or y,
  which can count a crossing at a corner twice; a crack particle exactly on a
  contour edge belongs to the chord that starts at it.
"""
from __future__ import annotations

import math
import warnings
from collections import namedtuple
from dataclasses import dataclass

import numpy as np
from numba import njit

from nairnmpm_py.core.grid import GHOST, Grid
from nairnmpm_py.core.shape import weights_1d
from nairnmpm_py.cracks.bundle import GSD
from nairnmpm_py.cracks.crossing import collinear_overlap, line_crosses_crack, tri
from nairnmpm_py.cracks.geometry import CrackSet, EXTERIOR_END

MPA_SQRT_MM_TO_MPA_SQRT_M = math.sqrt(1e-3)   # 1 MPa sqrt(mm) = 0.0316 MPa sqrt(m)
N_PER_MM_TO_J_PER_M2 = 1000.0

# nodal value vector layout used by the contour integration
_GXX, _GXY, _GYX, _GYY = 0, 1, 2, 3          # du/dx, du/dy, dv/dx, dv/dy
_SXX, _SYY, _SXY = 4, 5, 6
_WK = 7                                      # W + K
_NV = 8


@dataclass
class NodalFields:
    """Mass-weighted nodal values, two fields per node (index 0 and 1 first).

    Arrays cover a window of the grid (``nodal_fields(window=...)``; by default all
    nodes, ghosts included, when local and flat ``Grid`` indices coincide): local
    index = (row - wj0) * wnx + (column - wi0), in ghost-inclusive node rows and
    columns.  Values of a field with no mass are 0.
    """
    kind: int
    mass: np.ndarray      # (2, nw) g
    grad: np.ndarray      # (2, 4, nw) du/dx, du/dy, dv/dx, dv/dy
    stress: np.ndarray    # (2, 3, nw) sxx, syy, sxy (MPa)
    W: np.ndarray         # (2, nw) strain energy density (MPa = N/mm^2)
    K: np.ndarray         # (2, nw) kinetic energy density (MPa)
    crack: np.ndarray     # (nw,) crack index of field 1, -1 if none
    side: np.ndarray      # (nw,) side of the crack of field 1's particles (+1 above, -1 below;
                          # in a run the sign of the step's GSD row)
    multi: np.ndarray     # (nw,) bool: node sees two different cracks (not supported)
    conflicts: int        # standalone crossing test only (0 from the step's assignment):
                          # particle-node pairs put in field 0 because they crossed
                          # field 1's crack from the unexpected side (node on a crack)
    wi0: int = 0          # window: first column and row, columns per row
    wj0: int = 0
    wnx: int = 0


# ---- particles to nodes, per crack side -----------------------------------------------
# what each particle brings to J (lp: half-widths in cells, for the crossing path's
# shape functions)
JParticles = namedtuple("JParticles", ["pos", "vel", "mass", "vol0", "lp", "F", "stress", "w"])
# the nodes filled: ghost-inclusive columns i0..i1 and rows j0..j1, and the only
# particles that may reach them (ascending; empty = all)
JWindow = namedtuple("JWindow", ["i0", "i1", "j0", "j1", "subset"])
# the window's sums; ``crack`` / ``side`` of field 1 fixed by the first pair to claim
# it; ``counts``: [pairs put in field 0 for crossing from the unexpected side, pairs
# left out at a node that sees two cracks]
JSums = namedtuple("JSums", ["m", "g", "s", "en", "ke", "crack", "side", "multi", "counts"])
# the crossing path's cracks (``_crack_arrays``)
CrackLines = namedtuple("CrackLines", ["x", "y", "first", "count", "ext0", "ext1", "box"])
# the time step's field assignment (``cracks.bundle``): each particle's field at each
# stencil node (``vfld``, all 0 where ``cut`` is 0), the node slots, the reduced grid
# (its GSD rows give each slot's crossing side) and the cached stencils and weights
StepAssignment = namedtuple("StepAssignment", ["vfld", "cut", "nslot", "grid", "wij", "wc"])


@njit(cache=True, inline="always")
def _field_one(sums, k, crack, side, check_side):
    """J field of a pair across ``crack`` from ``side`` at window node k: 1, or 0 for a
    pair that crosses field 1's crack from the other side (with ``check_side``), or -1
    (pair left out, node flagged) when field 1 already holds another crack."""
    if sums.crack[k] < 0:
        sums.crack[k] = crack
        sums.side[k] = side
        return 1
    if sums.crack[k] == crack:
        if check_side and sums.side[k] != side:
            sums.counts[0] += 1      # unexpected side: CRAMP puts it in [0]
            return 0
        return 1
    sums.multi[k] = True
    sums.counts[1] += 1
    return -1


@njit(cache=True, inline="always")
def _deposit(parts, p, sums, fi, k, sw, kin):
    """Particle p's J quantities with weight sw into field fi of window node k."""
    wm = sw * parts.mass[p]
    F = parts.F
    stress = parts.stress
    sums.m[fi, k] += wm
    sums.g[fi, 0, k] += wm * (F[0, p] - 1.0)
    sums.g[fi, 1, k] += wm * F[1, p]
    sums.g[fi, 2, k] += wm * F[2, p]
    sums.g[fi, 3, k] += wm * (F[3, p] - 1.0)
    sums.s[fi, 0, k] += wm * stress[0, p]
    sums.s[fi, 1, k] += wm * stress[1, p]
    sums.s[fi, 2, k] += wm * stress[2, p]
    sums.en[fi, k] += wm * parts.w[p]
    sums.ke[fi, k] += wm * kin


@njit(cache=True, inline="always")
def _kinetic(parts, p):
    """1/2 rho0 |v|^2, per reference volume as W."""
    return 0.5 * (parts.mass[p] / parts.vol0[p]) * (parts.vel[0, p] ** 2 + parts.vel[1, p] ** 2)


@njit(cache=True)
def _extrapolate_crossing(parts, kind, geom, win, lines, sums):
    """Standalone path: each particle-node pair's side by its own crossing test
    (module docstring).  Serial; the first particle to claim field 1 fixes its side."""
    subset = win.subset
    n = subset.size if subset.size > 0 else parts.pos.shape[1]
    x0 = geom[0]
    y0 = geom[1]
    hx = geom[2]
    hy = geom[3]
    wnx = win.i1 - win.i0 + 1
    na = 2 if kind == 0 else 3
    box = lines.box
    # a particle reaches nodes less than 1.5 cells away (uGIMP, lp <= 0.5)
    xlo = x0 + (win.i0 - 1.5) * hx
    xhi = x0 + (win.i1 + 1.5) * hx
    ylo = y0 + (win.j0 - 1.5) * hy
    yhi = y0 + (win.j1 + 1.5) * hy
    for q in range(n):
        p = subset[q] if subset.size > 0 else q
        px = parts.pos[0, p]
        py = parts.pos[1, p]
        if px < xlo or px > xhi or py < ylo or py > yhi:
            continue
        i0, sx0, sx1, sx2, dx0, dx1, dx2 = weights_1d((px - x0) / hx, kind, parts.lp[0, p])
        j0, sy0, sy1, sy2, dy0, dy1, dy2 = weights_1d((py - y0) / hy, kind, parts.lp[1, p])
        kin = _kinetic(parts, p)
        for b in range(na):
            sy = sy0 if b == 0 else (sy1 if b == 1 else sy2)
            for a in range(na):
                sw = sy * (sx0 if a == 0 else (sx1 if a == 1 else sx2))
                if sw == 0.0:
                    continue
                if i0 + a < win.i0 or i0 + a > win.i1 or j0 + b < win.j0 or j0 + b > win.j1:
                    continue
                k = (j0 + b - win.j0) * wnx + i0 + a - win.i0
                ndx = x0 + (i0 + a) * hx
                ndy = y0 + (j0 + b) * hy
                found = -1
                fside = 0
                ncross = 0
                for c in range(lines.first.shape[0]):
                    if (max(px, ndx) < box[0, c] or min(px, ndx) > box[1, c]
                            or max(py, ndy) < box[2, c] or min(py, ndy) > box[3, c]):
                        continue
                    sd = line_crosses_crack(px, py, ndx, ndy, lines.x, lines.y, lines.first[c],
                                            lines.count[c], lines.ext0[c], lines.ext1[c])
                    if sd != 0:
                        ncross += 1
                        if ncross == 1:
                            found = c
                            fside = sd
                fi = 0
                if ncross > 1:
                    sums.multi[k] = True
                    sums.counts[1] += 1
                    continue
                if ncross == 1:
                    fi = _field_one(sums, k, found, fside, True)
                    if fi < 0:
                        continue
                _deposit(parts, p, sums, fi, k, sw, kin)


@njit(cache=True)
def _extrapolate_assigned(parts, geom, win, step, sums):
    """In-run path: each pair's field as the time step assigned it.  Step field 0 is J
    field 0; field 1 or 2 is J field 1, across the crack in the node's slot 0 or 1,
    from the side the sign of that slot's GSD row says; a pair in field 3 (across
    both) or naming a second crack at a node is left out and the node flagged
    ``multi``.  Stencils and weights are the step's cached ones."""
    subset = win.subset
    n = subset.size if subset.size > 0 else parts.mass.size
    na = 2 if step.vfld.shape[1] == 4 else 3
    nnx = int(geom[4])
    wnx = win.i1 - win.i0 + 1
    grid = step.grid
    for q in range(n):
        p = subset[q] if subset.size > 0 else q
        i0 = step.wij[p, 0]
        j0 = step.wij[p, 1]
        if i0 + na - 1 < win.i0 or i0 > win.i1 or j0 + na - 1 < win.j0 or j0 > win.j1:
            continue
        r = step.wc[p]
        cut = step.cut[p] != 0
        kin = _kinetic(parts, p)
        for b in range(na):
            for a in range(na):
                sw = r[3 + b] * r[a]
                if sw == 0.0:
                    continue
                if i0 + a < win.i0 or i0 + a > win.i1 or j0 + b < win.j0 or j0 + b > win.j1:
                    continue
                k = (j0 + b - win.j0) * wnx + i0 + a - win.i0
                f = step.vfld[p, b * na + a] if cut else 0
                fi = 0
                if f == 3:
                    sums.multi[k] = True
                    sums.counts[1] += 1
                    continue
                if f > 0:
                    node = (j0 + b) * nnx + i0 + a
                    crossed = grid[f, GSD, node]
                    side = 1 if crossed > 0.0 else (-1 if crossed < 0.0 else 0)
                    fi = _field_one(sums, k, step.nslot[f - 1, node], side, False)
                    if fi < 0:
                        continue
                _deposit(parts, p, sums, fi, k, sw, kin)


def _crack_arrays(cracks: CrackSet | None) -> CrackLines:
    """Crack arrays for the crossing path, with bounding boxes that include the 4x
    extension of exterior ends."""
    if cracks is None or cracks.n_cracks == 0:
        zi = np.zeros(0, dtype=np.int64)
        return CrackLines(np.zeros(1), np.zeros(1), zi, zi, np.zeros(0, dtype=np.bool_),
                          np.zeros(0, dtype=np.bool_), np.zeros((4, 0)))
    cx = np.ascontiguousarray(cracks.plane[0], dtype=float)
    cy = np.ascontiguousarray(cracks.plane[1], dtype=float)
    first = np.asarray(cracks.first, dtype=np.int64)
    count = np.asarray(cracks.count, dtype=np.int64)
    ext0 = np.asarray(cracks.tips[:, 0] == EXTERIOR_END)
    ext1 = np.asarray(cracks.tips[:, 1] == EXTERIOR_END)
    box = np.empty((4, len(first)))
    for c in range(len(first)):
        pts = cracks.plane[:, first[c]:first[c] + count[c]]
        extra = [pts]
        if ext0[c] and count[c] > 1:
            extra.append((pts[:, 0] - 4.0 * (pts[:, 1] - pts[:, 0]))[:, None])
        if ext1[c] and count[c] > 1:
            extra.append((pts[:, -1] + 4.0 * (pts[:, -1] - pts[:, -2]))[:, None])
        allp = np.hstack(extra)
        box[:, c] = [allp[0].min(), allp[0].max(), allp[1].min(), allp[1].max()]
    return CrackLines(cx, cy, first, count, ext0, ext1, box)


def _window(grid: Grid, window, subset) -> JWindow:
    """The ghost-inclusive node window of ``window`` (real-grid columns and rows,
    inclusive; None = every node), clipped to the grid."""
    if window is None:
        wi0, wi1, wj0, wj1 = 0, grid.nodes_x - 1, 0, grid.nodes_y - 1
    else:
        i_lo, i_hi, j_lo, j_hi = window
        wi0, wi1 = max(int(i_lo) + GHOST, 0), min(int(i_hi) + GHOST, grid.nodes_x - 1)
        wj0, wj1 = max(int(j_lo) + GHOST, 0), min(int(j_hi) + GHOST, grid.nodes_y - 1)
    return JWindow(wi0, wi1, wj0, wj1,
                   np.zeros(0, dtype=np.int64) if subset is None else subset)


def _empty_sums(win: JWindow) -> JSums:
    nw = (win.i1 - win.i0 + 1) * (win.j1 - win.j0 + 1)
    return JSums(np.zeros((2, nw)), np.zeros((2, 4, nw)), np.zeros((2, 3, nw)),
                 np.zeros((2, nw)), np.zeros((2, nw)), np.full(nw, -1, dtype=np.int64),
                 np.zeros(nw, dtype=np.int64), np.zeros(nw, dtype=np.bool_),
                 np.zeros(2, dtype=np.int64))


def _averaged(grid: Grid, kind: int, win: JWindow, sums: JSums, strict: bool) -> NodalFields:
    """The sums as mass-weighted averages; with ``strict`` a node that sees two
    cracks is an error."""
    wnx = win.i1 - win.i0 + 1
    if strict and sums.multi.any():
        k = int(np.argmax(sums.multi))
        x = grid.xmin + (win.i0 - GHOST + k % wnx) * grid.dx
        y = grid.ymin + (win.j0 - GHOST + k // wnx) * grid.dy
        raise ValueError(
            f"node at ({x:g}, {y:g}) mm sees two different cracks "
            f"({int(sums.multi.sum())} such nodes): the J-integral fields support one crack "
            "near a node; move the cracks apart or refine the grid")
    grad, stress, W, K = _mass_averages(sums.m, sums.g, sums.s, sums.en, sums.ke)
    return NodalFields(kind=int(kind), mass=sums.m, grad=grad, stress=stress, W=W, K=K,
                       crack=sums.crack, side=sums.side, multi=sums.multi,
                       conflicts=int(sums.counts[0]), wi0=win.i0, wj0=win.j0, wnx=wnx)


@njit(cache=True)
def _mass_averages(m, g, s, en, ke):
    """Sums times 1/m (0 where a field has no mass).  One compiled loop: J at a
    propagation check runs every step, and a dozen small numpy operations took about
    25 us there; the products are the same as numpy's, to the bit."""
    grad = np.zeros_like(g)
    stress = np.zeros_like(s)
    W = np.zeros_like(en)
    K = np.zeros_like(ke)
    for f in range(m.shape[0]):
        for k in range(m.shape[1]):
            inv = 1.0 / m[f, k] if m[f, k] > 0.0 else 0.0
            for c in range(g.shape[1]):
                grad[f, c, k] = g[f, c, k] * inv
            for c in range(s.shape[1]):
                stress[f, c, k] = s[f, c, k] * inv
            W[f, k] = en[f, k] * inv
            K[f, k] = ke[f, k] * inv
    return grad, stress, W, K


def nodal_fields(grid: Grid, particles, cracks: CrackSet | None, kind: int,
                 lp=None, strict: bool = True, window=None, subset=None) -> NodalFields:
    """Extrapolate the J-integral quantities to the grid, per side of the cracks, by
    the standalone crossing test (for particle sets with no running scene; a running
    scene uses ``step_nodal_fields``).

    kind: ``shape.LINEAR`` (0) or ``shape.UGIMP`` (1), as the engine.
    lp: particle half-widths in cell units for uGIMP: None = ``particles.lp``; a
    scalar or a (2, n) array overrides it.
    strict: raise ValueError if any node sees two different cracks; with False those
    nodes are only flagged (``multi``) and ``j_integral`` refuses contours through
    them.
    window: (i_lo, i_hi, j_lo, j_hi) real-grid node columns and rows (inclusive) to
    fill, clipped to the grid; None = every node.  J needs only its contour's nodes.
    subset: ascending indices of the only particles that may reach the window (a
    cache kept by the caller); None = test every particle.
    """
    n = particles.pos.shape[1]
    if lp is None:
        lpa = np.asarray(particles.lp, dtype=float)
    else:
        lpa = np.broadcast_to(np.asarray(lp, dtype=float), (2, n))
    lpa = np.ascontiguousarray(np.broadcast_to(lpa, (2, n)))
    parts = JParticles(*(np.ascontiguousarray(a, dtype=float) for a in (
        particles.pos, particles.vel, particles.mass, particles.vol0)), lpa,
        *(np.ascontiguousarray(a, dtype=float) for a in (
            particles.F, particles.stress, particles.w)))
    win = _window(grid, window, subset)
    sums = _empty_sums(win)
    _extrapolate_crossing(parts, int(kind), grid.geometry_vector(), win, _crack_arrays(cracks),
                          sums)
    fields = _averaged(grid, kind, win, sums, strict)
    if fields.conflicts > 0:
        warnings.warn(f"{fields.conflicts} particle-node pairs crossed a crack from the "
                      "unexpected side (a node or particle lies on a crack); they were put "
                      "in field 0", RuntimeWarning, stacklevel=2)
    return fields


def step_nodal_fields(grid: Grid, P, assignment: StepAssignment, kind: int,
                      strict: bool = False, window=None, subset=None) -> NodalFields:
    """The J-integral quantities on the grid, per side of the cracks as the time step
    assigned them (``StepAssignment``, current only while the simulation's grid is).

    P: the particles (the step's bundle, or ``Particles`` with the same arrays: pos,
    vel, mass, vol0, lp, F, stress, w); kind, strict, window and subset as
    ``nodal_fields``.
    """
    parts = JParticles(P.pos, P.vel, P.mass, P.vol0, P.lp, P.F, P.stress, P.w)
    win = _window(grid, window, subset)
    sums = _empty_sums(win)
    _extrapolate_assigned(parts, grid.geometry_vector(), win, assignment, sums)
    return _averaged(grid, kind, win, sums, strict)


@dataclass
class JResult:
    """One contour's J integral at one crack tip."""
    J1: float                 # N/mm, energy release rate for extension along `direction`
    J2: float                 # N/mm, component normal to it
    Jx: float                 # N/mm, grid-frame components
    Jy: float
    direction: np.ndarray     # (2,) unit crack-tip direction
    tip: int                  # crack-particle index (CrackSet arrays) of the tip
    crossing: np.ndarray      # (2,) where the contour crosses the crack plane (mm)
    crossing_particle: int    # crack particle at the tip-side end of the crossed chord
    crossing_beyond: int      # crack particle at the other end of that chord
    crossing_fraction: float  # crossing = P[particle] + f (P[beyond] - P[particle])
    centre: tuple             # (i, j) real-grid node at the centre of the contour
    size_cells: int
    corners: np.ndarray       # (4, 2) real-grid (i, j) of the corners, CCW from lower-left
    corner_nodes: np.ndarray  # (4,) flat node indices of the corners

    @property
    def J1_J_per_m2(self) -> float:
        return self.J1 * N_PER_MM_TO_J_PER_M2


def crack_tip(cracks: CrackSet, crack_index: int, tip_end: str):
    """(tip particle, adjacent particle, unit direction from adjacent to tip)."""
    s0 = int(cracks.first[crack_index])
    nc = int(cracks.count[crack_index])
    if nc < 2:
        raise ValueError(f"crack {crack_index} has fewer than 2 particles")
    if tip_end == "end":
        tip, adj = s0 + nc - 1, s0 + nc - 2
    elif tip_end == "start":
        tip, adj = s0, s0 + 1
    else:
        raise ValueError(f"tip_end must be 'start' or 'end', not {tip_end!r}")
    d = cracks.plane[:, tip] - cracks.plane[:, adj]
    ln = float(np.hypot(d[0], d[1]))
    if ln == 0.0:
        raise ValueError(f"crack {crack_index}: tip and adjacent crack particle coincide")
    return tip, adj, d / ln


_MAX_HITS = 16


@njit(cache=True)
def _contour_hits(xs, ys, px, py, first, count, tol, found):
    """Crossings of the contour's edges (path xs, ys) with every crack's chords, in
    walk order, into ``found`` rows (edge, t along the edge, crack, chord start
    particle, u along the chord).  Returns (number of crossings, edge where a chord
    runs along it or -1, that chord's crack).

    Sign tests as in the particle-node crossing test: a crack particle exactly on an
    edge's line is counted by one of its two chords only (its side value is the same
    float for both, and 0 counts as positive), and a node exactly on a chord's line
    by one edge only ((0, 1] along the walk), so nothing is counted twice or lost to
    rounding.
    """
    lo_x = xs.min()
    hi_x = xs.max()
    lo_y = ys.min()
    hi_y = ys.max()
    nhit = 0
    for e in range(xs.size - 1):
        ax = xs[e]
        ay = ys[e]
        bx = xs[e + 1]
        by = ys[e + 1]
        for c in range(first.size):
            for k in range(first[c], first[c] + count[c] - 1):
                cx0 = px[k]
                cy0 = py[k]
                cx1 = px[k + 1]
                cy1 = py[k + 1]
                # a chord with both ends strictly inside the square cannot cross it
                if (min(cx0, cx1) > lo_x and max(cx0, cx1) < hi_x
                        and min(cy0, cy1) > lo_y and max(cy0, cy1) < hi_y):
                    continue
                if (max(cx0, cx1) < min(ax, bx) or min(cx0, cx1) > max(ax, bx)
                        or max(cy0, cy1) < min(ay, by) or min(cy0, cy1) > max(ay, by)):
                    continue
                if collinear_overlap(ax, ay, bx, by, cx0, cy0, cx1, cy1, tol):
                    return nhit, e, c
                a1 = tri(ax, ay, bx, by, cx0, cy0)
                a2 = tri(ax, ay, bx, by, cx1, cy1)
                if (a1 < 0.0) == (a2 < 0.0):
                    continue                    # chord does not straddle the edge line
                b1 = tri(cx0, cy0, cx1, cy1, ax, ay)
                b2 = tri(cx0, cy0, cx1, cy1, bx, by)
                if not ((b1 < 0.0 and b2 >= 0.0) or (b1 > 0.0 and b2 <= 0.0)):
                    continue                    # edge does not straddle the chord line
                if nhit < found.shape[0]:
                    found[nhit, 0] = e
                    found[nhit, 1] = b1 / (b1 - b2)
                    found[nhit, 2] = c
                    found[nhit, 3] = k
                    found[nhit, 4] = a1 / (a1 - a2)
                nhit += 1
    return nhit, -1, -1


@njit(cache=True, inline="always")
def _node_values(grad, stress, W, K, fld, k, out):
    """The contour's value vector of field ``fld`` at window node k into ``out``."""
    out[_GXX] = grad[fld, 0, k]
    out[_GXY] = grad[fld, 1, k]
    out[_GYX] = grad[fld, 2, k]
    out[_GYY] = grad[fld, 3, k]
    out[_SXX] = stress[fld, 0, k]
    out[_SYY] = stress[fld, 1, k]
    out[_SXY] = stress[fld, 2, k]
    out[_WK] = W[fld, k] + K[fld, k]


@njit(cache=True, inline="always")
def _flux(v, nx, ny):
    """(f_x, f_y) = (W+K) n - (sigma.n) . du/dx_k for a value vector."""
    tx = v[_SXX] * nx + v[_SXY] * ny
    ty = v[_SXY] * nx + v[_SYY] * ny
    return (v[_WK] * nx - (tx * v[_GXX] + ty * v[_GYX]),
            v[_WK] * ny - (tx * v[_GXY] + ty * v[_GYY]))


@njit(cache=True, inline="always")
def _blend_into(a, has_a, b, has_b, f, out):
    """out = (1-f) a + f b, or the available one alone; False if neither is."""
    if has_a and has_b:
        for q in range(_NV):
            out[q] = (1.0 - f) * a[q] + f * b[q]
    elif has_a:
        out[:] = a
    elif has_b:
        out[:] = b
    return has_a or has_b


# _contour_j status codes (j_integral turns them into messages)
_J_OK, _J_MULTI, _J_ALONG, _J_OTHER, _J_COUNT, _J_EMPTY, _J_WINDOW = 0, 1, 2, 3, 4, 5, 6


# a ``NodalFields`` for the contour kernel: its arrays, window origin and shape
NodalArrays = namedtuple("NodalArrays", ["mass", "grad", "stress", "W", "K", "crack", "multi",
                                         "wi0", "wj0", "wnx", "wny"])
# the contour: half-size s cells around real-grid node (ic, jc); x0, y0 the real
# grid's node (0, 0), hx, hy the cell size
Square = namedtuple("Square", ["ic", "jc", "s", "x0", "y0", "hx", "hy"])
# crack planes as the contour's crossing search reads them
CrackPlane = namedtuple("CrackPlane", ["x", "y", "first", "count"])


@njit(cache=True)
def _contour_j(nodal, square, plane, crack_index, found):
    """J over the square of half-size s around real-grid node (ic, jc), walked CCW
    from the middle of its right side (module docstring, step 2).  Returns (status,
    Jx, Jy, crossings, bad edge, bad crack, x, y of the bad edge's start); ``found``
    row 0 is the crossing (edge, t along it, crack, chord start, u along the chord)."""
    mass, grad, stress, W, K = nodal.mass, nodal.grad, nodal.stress, nodal.W, nodal.K
    fcrack, multi = nodal.crack, nodal.multi
    wi0, wj0, wnx, wny = nodal.wi0, nodal.wj0, nodal.wnx, nodal.wny
    ic, jc, s = square.ic, square.jc, square.s
    x0, y0, hx, hy = square.x0, square.y0, square.hx, square.hy
    npath = 8 * s + 1
    ii = np.empty(npath, dtype=np.int64)
    jj = np.empty(npath, dtype=np.int64)
    q = 0
    for j in range(jc, jc + s):
        ii[q] = ic + s
        jj[q] = j
        q += 1
    for i in range(ic + s, ic - s, -1):
        ii[q] = i
        jj[q] = jc + s
        q += 1
    for j in range(jc + s, jc - s, -1):
        ii[q] = ic - s
        jj[q] = j
        q += 1
    for i in range(ic - s, ic + s):
        ii[q] = i
        jj[q] = jc - s
        q += 1
    for j in range(jc - s, jc + 1):
        ii[q] = ic + s
        jj[q] = j
        q += 1
    xs = np.empty(npath)
    ys = np.empty(npath)
    loc = np.empty(npath, dtype=np.int64)
    for q in range(npath):
        li = ii[q] + GHOST - wi0
        lj = jj[q] + GHOST - wj0
        if li < 0 or li >= wnx or lj < 0 or lj >= wny:
            return _J_WINDOW, 0.0, 0.0, 0, -1, -1, 0.0, 0.0
        loc[q] = lj * wnx + li
        xs[q] = x0 + ii[q] * hx
        ys[q] = y0 + jj[q] * hy
    for q in range(npath):
        if multi[loc[q]]:
            return _J_MULTI, 0.0, 0.0, 0, -1, -1, 0.0, 0.0
    nhit, bad_edge, bad_crack = _contour_hits(xs, ys, plane.x, plane.y, plane.first,
                                              plane.count, 1e-12 * (hx + hy), found)
    if bad_edge >= 0:
        return _J_ALONG, 0.0, 0.0, nhit, bad_edge, bad_crack, xs[bad_edge], ys[bad_edge]
    for h in range(min(nhit, found.shape[0])):
        if int(found[h, 2]) != crack_index:
            return _J_OTHER, 0.0, 0.0, nhit, -1, int(found[h, 2]), 0.0, 0.0
    if nhit != 1:
        return _J_COUNT, 0.0, 0.0, nhit, -1, -1, 0.0, 0.0
    empty = True
    for q in range(npath):
        if mass[0, loc[q]] > 0.0:
            empty = False
    if empty:
        return _J_EMPTY, 0.0, 0.0, nhit, -1, -1, 0.0, 0.0
    e_hit = int(found[0, 0])
    f = found[0, 1]
    va = np.zeros(_NV)
    vb = np.zeros(_NV)
    fa = np.zeros(_NV)
    fb = np.zeros(_NV)
    mid = np.zeros(_NV)
    jx = 0.0
    jy = 0.0
    for e in range(npath - 1):
        dxe = xs[e + 1] - xs[e]
        dye = ys[e + 1] - ys[e]
        ds = math.sqrt(dxe * dxe + dye * dye)
        nx = dye / ds                   # outward for a CCW walk
        ny = -dxe / ds
        a = loc[e]
        b = loc[e + 1]
        has_a = mass[0, a] > 0.0
        has_b = mass[0, b] > 0.0
        ax = ay = bx = by = 0.0
        if has_a:
            _node_values(grad, stress, W, K, 0, a, va)
            ax, ay = _flux(va, nx, ny)
        if has_b:
            _node_values(grad, stress, W, K, 0, b, vb)
            bx, by = _flux(vb, nx, ny)
        if e != e_hit:                  # trapezoid rule on field 0
            jx += 0.5 * (ax + bx) * ds
            jy += 0.5 * (ay + by) * ds
            continue
        # the crossed edge: each side of the crossing with that side's fields
        has_fa = fcrack[a] == crack_index and mass[1, a] > 0.0
        has_fb = fcrack[b] == crack_index and mass[1, b] > 0.0
        if has_fa:
            _node_values(grad, stress, W, K, 1, a, fa)
        if has_fb:
            _node_values(grad, stress, W, K, 1, b, fb)
        mx = my = 0.0
        if _blend_into(va, has_a, fb, has_fb, f, mid):      # node a's side, at the crossing
            mx, my = _flux(mid, nx, ny)
        jx += 0.5 * (ax + mx) * (f * ds)
        jy += 0.5 * (ay + my) * (f * ds)
        mx = my = 0.0
        if _blend_into(fa, has_fa, vb, has_b, f, mid):      # node b's side, at the crossing
            mx, my = _flux(mid, nx, ny)
        jx += 0.5 * (mx + bx) * ((1.0 - f) * ds)
        jy += 0.5 * (my + by) * ((1.0 - f) * ds)
    return _J_OK, jx, jy, nhit, -1, -1, 0.0, 0.0


def j_integral(grid: Grid, fields: NodalFields, cracks: CrackSet, crack_index: int,
               tip_end: str = "end", size_cells: int = 2) -> JResult:
    """J integral of one crack tip on a square grid contour (JINTEGRAL.md sections 2-4).

    tip_end: 'end' for the last crack particle, 'start' for the first.
    size_cells: half-size of the square in cells (NairnMPM's ``JContour size``).
    Raises ValueError if the contour leaves the grid, does not cross the crack
    exactly once, crosses another crack, runs along the crack, passes a node that
    sees two cracks, or has no particles at all.
    """
    s = int(size_cells)
    if s < 1:
        raise ValueError("size_cells must be >= 1")
    tip, adj, d = crack_tip(cracks, crack_index, tip_end)
    hx, hy = grid.dx, grid.dy
    xt, yt = cracks.plane[:, tip]
    ic = int(math.floor((xt - grid.xmin) / hx + 0.5))
    jc = int(math.floor((yt - grid.ymin) / hy + 0.5))
    if ic - s < 0 or ic + s > grid.nx or jc - s < 0 or jc + s > grid.ny:
        raise ValueError(f"J contour of half-size {s} cells around node ({ic}, {jc}) "
                         f"leaves the grid (0..{grid.nx}, 0..{grid.ny})")
    P = cracks.plane
    found = np.zeros((_MAX_HITS, 5))
    wny = fields.mass.shape[1] // fields.wnx
    nodal = NodalArrays(fields.mass, fields.grad, fields.stress, fields.W, fields.K,
                        fields.crack, fields.multi, int(fields.wi0), int(fields.wj0),
                        int(fields.wnx), int(wny))
    square = Square(ic, jc, s, float(grid.xmin), float(grid.ymin), float(hx), float(hy))
    plane = CrackPlane(np.ascontiguousarray(P[0]), np.ascontiguousarray(P[1]),
                       np.ascontiguousarray(cracks.first, dtype=np.int64),
                       np.ascontiguousarray(cracks.count, dtype=np.int64))
    status, Jx, Jy, nhit, bad_edge, bad_crack, bx, by = _contour_j(nodal, square, plane,
                                                                   int(crack_index), found)
    if status == _J_WINDOW:
        raise ValueError(f"J contour of half-size {s} cells around node ({ic}, {jc}) "
                         "is outside the window of nodal fields it was given")
    if status == _J_MULTI:
        raise ValueError("the J contour passes a node that sees two cracks")
    if status == _J_ALONG:
        raise ValueError(f"crack {bad_crack} runs along a J-contour edge near "
                         f"({bx:g}, {by:g}); keep cracks off grid lines")
    if status == _J_OTHER:
        raise ValueError(f"crack {bad_crack} crosses the J contour of crack "
                         f"{crack_index}; contours crossing other cracks are not supported")
    if status == _J_COUNT:
        raise ValueError(f"the J contour (half-size {s} cells) crosses crack {crack_index} "
                         f"{nhit} times; it must cross it exactly once")
    if status == _J_EMPTY:
        raise ValueError("no node of the J contour has particles")
    k_hit, u_hit = int(found[0, 3]), float(found[0, 4])
    J1 = Jx * d[0] + Jy * d[1]
    J2 = -Jx * d[1] + Jy * d[0]
    cross = P[:, k_hit] + u_hit * (P[:, k_hit + 1] - P[:, k_hit])
    if tip_end == "end":
        cp, cb, frac = k_hit + 1, k_hit, 1.0 - u_hit
    else:
        cp, cb, frac = k_hit, k_hit + 1, u_hit
    corners = np.array([(ic - s, jc - s), (ic + s, jc - s), (ic + s, jc + s), (ic - s, jc + s)])
    return JResult(J1=float(J1), J2=float(J2), Jx=float(Jx), Jy=float(Jy), direction=d.copy(),
                   tip=tip, crossing=np.asarray(cross, dtype=float), crossing_particle=int(cp),
                   crossing_beyond=int(cb), crossing_fraction=float(frac), centre=(ic, jc),
                   size_cells=s, corners=corners,
                   corner_nodes=grid.node_index(corners[:, 0], corners[:, 1]))


def tip_cod(cracks: CrackSet, crack_index: int, tip_end: str = "end") -> tuple[float, float]:
    """Crack opening near a tip in the tip frame, (delta_n, delta_t) in mm.

    As NairnMPM (COD location 2): with crack particles P0 (tip) .. P3 and surfaces A
    (above) and B (below), COD = [(A1 + 4 A2 + A3) - (B1 + 4 B2 + B3)] / 6, or A1 - B1
    with fewer than 4 particles; negated at a start tip (where "above" is on the
    right of the tip direction), then resolved along the tip direction d:
    delta_t = COD.d, delta_n = -COD_x d_y + COD_y d_x.
    """
    tip, _, d = crack_tip(cracks, crack_index, tip_end)
    step = -1 if tip_end == "end" else 1
    nc = int(cracks.count[crack_index])
    A, B = cracks.above, cracks.below
    if nc >= 4:
        i1, i2, i3 = tip + step, tip + 2 * step, tip + 3 * step
        cod = ((A[:, i1] + 4.0 * A[:, i2] + A[:, i3]) - (B[:, i1] + 4.0 * B[:, i2] + B[:, i3])) / 6.0
    else:
        cod = A[:, tip + step] - B[:, tip + step]
    if tip_end == "start":
        cod = -cod
    return float(-cod[0] * d[1] + cod[1] * d[0]), float(cod[0] * d[0] + cod[1] * d[1])


def stress_intensity(J1: float, cod_n: float, cod_t: float, G: float, nu: float,
                     plane_stress: bool) -> tuple[float, float]:
    """(K_I, K_II) in MPa sqrt(mm) from J (N/mm) and the tip-frame opening (mm).

    Isotropic material with shear modulus G (MPa) and Poisson's ratio nu;
    kappa = (3 - nu)/(1 + nu) in plane stress, 3 - 4 nu in plane strain.  The opening
    splits J between the modes: K_I = dn sqrt(8 G J / ((kappa+1)(dn^2 + dt^2))),
    K_II likewise with dt (JINTEGRAL.md section 6).  Both are 0 if J <= 0 or the
    opening is 0.  Multiply by ``MPA_SQRT_MM_TO_MPA_SQRT_M`` for MPa sqrt(m).
    """
    d2 = cod_n * cod_n + cod_t * cod_t
    if J1 <= 0.0 or d2 == 0.0:
        return 0.0, 0.0
    kappa = (3.0 - nu) / (1.0 + nu) if plane_stress else 3.0 - 4.0 * nu
    f = math.sqrt(8.0 * G * J1 / ((kappa + 1.0) * d2))
    return cod_n * f, cod_t * f


def to_mpa_sqrt_m(k: float) -> float:
    """MPa sqrt(mm) -> MPa sqrt(m)."""
    return k * MPA_SQRT_MM_TO_MPA_SQRT_M
