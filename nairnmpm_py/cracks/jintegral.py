"""Crack-tip J integral and stress intensity factors from the grid (2D, planar).

The method follows NairnMPM's (see shared notes JINTEGRAL.md sections 1-6; Guo and
Nairn 2004), re-implemented from the description, not the code:

1. ``nodal_fields``: particle quantities are extrapolated to the nodes with the
   engine's shape functions (linear or uGIMP), separately per side of a crack as
   CRAMP does for velocity fields: at each node, field 0 holds the particles with no
   crack between particle and node, field 1 the particles across one crack.  Nodal
   values are mass-weighted averages of particle values:

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
from dataclasses import dataclass

import numpy as np
from numba import njit

from nairnmpm_py.core.grid import GHOST, Grid
from nairnmpm_py.core.shape import weights_1d
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
    columns.  ``local`` maps flat grid indices to it.  Values of a field with no
    mass are 0.
    """
    kind: int
    mass: np.ndarray      # (2, nw) g
    grad: np.ndarray      # (2, 4, nw) du/dx, du/dy, dv/dx, dv/dy
    stress: np.ndarray    # (2, 3, nw) sxx, syy, sxy (MPa)
    W: np.ndarray         # (2, nw) strain energy density (MPa = N/mm^2)
    K: np.ndarray         # (2, nw) kinetic energy density (MPa)
    crack: np.ndarray     # (nw,) crack index of field 1, -1 if none
    side: np.ndarray      # (nw,) side of the crack of field 1's particles (+1 above, -1 below)
    multi: np.ndarray     # (nw,) bool: node sees two different cracks (not supported)
    conflicts: int        # particle-node pairs put in field 0 because they crossed
                          # field 1's crack from the unexpected side (node on a crack)
    nnx: int = 0          # nodes per grid row (ghosts included)
    wi0: int = 0          # window: first column and row, columns per row
    wj0: int = 0
    wnx: int = 0

    def local(self, node):
        """Window index of flat grid node index(es) ``node`` (must lie in the window)."""
        node = np.asarray(node)
        return (node // self.nnx - self.wj0) * self.wnx + (node % self.nnx - self.wi0)

    def values(self, node: int, field: int) -> np.ndarray | None:
        """The value vector at (flat grid node, field) for the contour, or None if
        empty."""
        v, has = self.table(np.array([node]), field)
        return v[0] if has[0] else None

    def field_crack(self, node: int) -> int:
        """Crack index of field 1 at a flat grid node (-1 none)."""
        return int(self.crack[int(self.local(node))])

    def table(self, nodes: np.ndarray, field: int) -> tuple[np.ndarray, np.ndarray]:
        """(value vectors (len(nodes), 8) for the contour, has-mass mask) at flat grid
        nodes ``nodes`` for one field."""
        k = self.local(nodes)
        v = np.empty((len(k), _NV))
        v[:, 0:4] = self.grad[field][:, k].T
        v[:, 4:7] = self.stress[field][:, k].T
        v[:, _WK] = self.W[field, k] + self.K[field, k]
        return v, self.mass[field, k] > 0.0

@njit(cache=True)
def _extrapolate(pos, vel, mass, vol0, lp, F, stress, w, geom, kind,
                 cx, cy, cfirst, ccount, cext0, cext1, cbox, wi0, wi1, wj0, wj1, subset,
                 m, g, s, en, ke, ncrack, nside, multi, counts):
    """Serial particle loop (the first particle to claim field 1 fixes its side).
    Only nodes in columns wi0..wi1 and rows wj0..wj1 are filled (window arrays); only
    the particles ``subset`` (ascending indices) are visited, all if it is empty."""
    n = subset.size if subset.size > 0 else pos.shape[1]
    x0 = geom[0]
    y0 = geom[1]
    hx = geom[2]
    hy = geom[3]
    wnx = wi1 - wi0 + 1
    na = 2 if kind == 0 else 3
    ncr = cfirst.shape[0]
    # a particle reaches nodes less than 1.5 cells away (uGIMP, lp <= 0.5)
    xlo = x0 + (wi0 - 1.5) * hx
    xhi = x0 + (wi1 + 1.5) * hx
    ylo = y0 + (wj0 - 1.5) * hy
    yhi = y0 + (wj1 + 1.5) * hy
    for q in range(n):
        p = subset[q] if subset.size > 0 else q
        px = pos[0, p]
        py = pos[1, p]
        if px < xlo or px > xhi or py < ylo or py > yhi:
            continue
        i0, sx0, sx1, sx2, dx0, dx1, dx2 = weights_1d((px - x0) / hx, kind, lp[0, p])
        j0, sy0, sy1, sy2, dy0, dy1, dy2 = weights_1d((py - y0) / hy, kind, lp[1, p])
        mp = mass[p]
        g00 = F[0, p] - 1.0
        g01 = F[1, p]
        g10 = F[2, p]
        g11 = F[3, p] - 1.0
        kin = 0.5 * (mp / vol0[p]) * (vel[0, p] ** 2 + vel[1, p] ** 2)
        for b in range(na):
            sy = sy0 if b == 0 else (sy1 if b == 1 else sy2)
            for a in range(na):
                sw = sy * (sx0 if a == 0 else (sx1 if a == 1 else sx2))
                if sw == 0.0:
                    continue
                if i0 + a < wi0 or i0 + a > wi1 or j0 + b < wj0 or j0 + b > wj1:
                    continue
                k = (j0 + b - wj0) * wnx + i0 + a - wi0
                ndx = x0 + (i0 + a) * hx
                ndy = y0 + (j0 + b) * hy
                found = -1
                fside = 0
                ncross = 0
                for c in range(ncr):
                    if (max(px, ndx) < cbox[0, c] or min(px, ndx) > cbox[1, c]
                            or max(py, ndy) < cbox[2, c] or min(py, ndy) > cbox[3, c]):
                        continue
                    sd = line_crosses_crack(px, py, ndx, ndy, cx, cy, cfirst[c], ccount[c],
                                            cext0[c], cext1[c])
                    if sd != 0:
                        ncross += 1
                        if ncross == 1:
                            found = c
                            fside = sd
                fi = 0
                if ncross > 1:
                    multi[k] = True
                    counts[1] += 1
                    continue
                if ncross == 1:
                    if ncrack[k] < 0:
                        ncrack[k] = found
                        nside[k] = fside
                        fi = 1
                    elif ncrack[k] == found:
                        if nside[k] == fside:
                            fi = 1
                        else:
                            counts[0] += 1      # unexpected side: CRAMP puts it in [0]
                    else:
                        multi[k] = True
                        counts[1] += 1
                        continue
                wm = sw * mp
                m[fi, k] += wm
                g[fi, 0, k] += wm * g00
                g[fi, 1, k] += wm * g01
                g[fi, 2, k] += wm * g10
                g[fi, 3, k] += wm * g11
                s[fi, 0, k] += wm * stress[0, p]
                s[fi, 1, k] += wm * stress[1, p]
                s[fi, 2, k] += wm * stress[2, p]
                en[fi, k] += wm * w[p]
                ke[fi, k] += wm * kin


def _crack_arrays(cracks: CrackSet | None):
    """Crack arrays for the kernel, with bounding boxes that include the 4x
    extension of exterior ends."""
    if cracks is None or cracks.n_cracks == 0:
        zi = np.zeros(0, dtype=np.int64)
        return (np.zeros(1), np.zeros(1), zi, zi, np.zeros(0, dtype=np.bool_),
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
    return cx, cy, first, count, ext0, ext1, box


def nodal_fields(grid: Grid, particles, cracks: CrackSet | None, kind: int,
                 lp=None, strict: bool = True, window=None, subset=None) -> NodalFields:
    """Extrapolate the J-integral quantities to the grid, per side of the cracks.

    kind: ``shape.LINEAR`` (0) or ``shape.UGIMP`` (1), as the engine.
    lp: particle half-widths in cell units for uGIMP: None = ``particles.lp``; a
    scalar or a (2, n) array overrides it.
    strict: raise ValueError if any node sees two different cracks; with False those
    nodes are only flagged (``multi``) and ``j_integral`` refuses contours through
    them.
    window: (i_lo, i_hi, j_lo, j_hi) real-grid node columns and rows (inclusive) to
    fill, clipped to the grid; None = every node.  J needs only its contour's nodes,
    so the crack scene asks for the square around the tip.
    subset: ascending indices of the only particles that may reach the window (a
    cache kept by the caller); None = test every particle.
    """
    n = particles.pos.shape[1]
    if lp is None:
        lpa = np.asarray(particles.lp, dtype=float)
    else:
        lpa = np.broadcast_to(np.asarray(lp, dtype=float), (2, n))
    lpa = np.ascontiguousarray(np.broadcast_to(lpa, (2, n)))
    geom = grid.geometry_vector()
    if window is None:
        wi0, wi1, wj0, wj1 = 0, grid.nodes_x - 1, 0, grid.nodes_y - 1
    else:
        i_lo, i_hi, j_lo, j_hi = window
        wi0, wi1 = max(int(i_lo) + GHOST, 0), min(int(i_hi) + GHOST, grid.nodes_x - 1)
        wj0, wj1 = max(int(j_lo) + GHOST, 0), min(int(j_hi) + GHOST, grid.nodes_y - 1)
    nw = (wi1 - wi0 + 1) * (wj1 - wj0 + 1)
    m = np.zeros((2, nw))
    g = np.zeros((2, 4, nw))
    s = np.zeros((2, 3, nw))
    en = np.zeros((2, nw))
    ke = np.zeros((2, nw))
    ncrack = np.full(nw, -1, dtype=np.int64)
    nside = np.zeros(nw, dtype=np.int64)
    multi = np.zeros(nw, dtype=np.bool_)
    counts = np.zeros(2, dtype=np.int64)
    cx, cy, first, count, ext0, ext1, box = _crack_arrays(cracks)
    _extrapolate(np.ascontiguousarray(particles.pos, dtype=float),
                 np.ascontiguousarray(particles.vel, dtype=float),
                 np.ascontiguousarray(particles.mass, dtype=float),
                 np.ascontiguousarray(particles.vol0, dtype=float), lpa,
                 np.ascontiguousarray(particles.F, dtype=float),
                 np.ascontiguousarray(particles.stress, dtype=float),
                 np.ascontiguousarray(particles.w, dtype=float),
                 geom, int(kind), cx, cy, first, count, ext0, ext1, box, wi0, wi1, wj0, wj1,
                 np.zeros(0, dtype=np.int64) if subset is None else subset,
                 m, g, s, en, ke, ncrack, nside, multi, counts)
    wnx = wi1 - wi0 + 1
    if strict and multi.any():
        k = int(np.argmax(multi))
        x = geom[0] + (wi0 + k % wnx) * grid.dx
        y = geom[1] + (wj0 + k // wnx) * grid.dy
        raise ValueError(
            f"node at ({x:g}, {y:g}) mm sees two different cracks "
            f"({int(multi.sum())} such nodes): the J-integral fields support one crack "
            "near a node; move the cracks apart or refine the grid")
    if counts[0] > 0:
        warnings.warn(f"{int(counts[0])} particle-node pairs crossed a crack from the "
                      "unexpected side (a node or particle lies on a crack); they were put "
                      "in field 0", RuntimeWarning, stacklevel=2)
    with np.errstate(invalid="ignore", divide="ignore"):
        inv = np.where(m > 0.0, 1.0 / np.where(m > 0.0, m, 1.0), 0.0)
    return NodalFields(kind=int(kind), mass=m, grad=g * inv[:, None, :],
                       stress=s * inv[:, None, :], W=en * inv, K=ke * inv,
                       crack=ncrack, side=nside, multi=multi, conflicts=int(counts[0]),
                       nnx=grid.nodes_x, wi0=wi0, wj0=wj0, wnx=wnx)


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


def _contour_path(ic: int, jc: int, s: int) -> list[tuple[int, int]]:
    """Nodes of the square of half-size s around (ic, jc), CCW, from the middle of the
    right side back to it (first == last)."""
    path = [(ic + s, j) for j in range(jc, jc + s)]
    path += [(i, jc + s) for i in range(ic + s, ic - s, -1)]
    path += [(ic - s, j) for j in range(jc + s, jc - s, -1)]
    path += [(i, jc - s) for i in range(ic - s, ic + s)]
    path += [(ic + s, j) for j in range(jc - s, jc + 1)]
    return path


def _integrand(v: np.ndarray | None, nx: float, ny: float) -> np.ndarray:
    """(f_x, f_y) = (W+K) n - (sigma.n) . du/dx_k; zero for an empty field."""
    if v is None:
        return np.zeros(2)
    tx = v[_SXX] * nx + v[_SXY] * ny
    ty = v[_SXY] * nx + v[_SYY] * ny
    fx = v[_WK] * nx - (tx * v[_GXX] + ty * v[_GYX])
    fy = v[_WK] * ny - (tx * v[_GXY] + ty * v[_GYY])
    return np.array([fx, fy])


def _integrands(V: np.ndarray, has: np.ndarray, nx: np.ndarray, ny: np.ndarray) -> np.ndarray:
    """``_integrand`` for rows of value vectors (zero where ``has`` is False)."""
    tx = V[:, _SXX] * nx + V[:, _SXY] * ny
    ty = V[:, _SXY] * nx + V[:, _SYY] * ny
    fx = V[:, _WK] * nx - (tx * V[:, _GXX] + ty * V[:, _GYX])
    fy = V[:, _WK] * ny - (tx * V[:, _GXY] + ty * V[:, _GYY])
    return np.where(has[:, None], np.column_stack([fx, fy]), 0.0)


def _blend(a: np.ndarray | None, b: np.ndarray | None, f: float) -> np.ndarray | None:
    """(1-f) a + f b, using the available one alone if the other field is empty."""
    if a is None:
        return b
    if b is None:
        return a
    return (1.0 - f) * a + f * b


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
    path = _contour_path(ic, jc, s)
    ij = np.array(path)
    nodes = grid.node_index(ij[:, 0], ij[:, 1])
    if fields.multi[fields.local(nodes)].any():
        raise ValueError("the J contour passes a node that sees two cracks")
    xs = grid.xmin + ij[:, 0] * hx
    ys = grid.ymin + ij[:, 1] * hy

    # crossings of the contour edges with every crack's chords.  Sign tests as in
    # the particle-node crossing test: a crack particle exactly on an edge's line
    # is counted by one of its two chords only (its side value is the same float
    # for both, and 0 counts as positive), and a node exactly on a chord's line by
    # one edge only ((0, 1] along the walk), so nothing is counted twice or lost to
    # rounding.
    P = cracks.plane
    first = np.ascontiguousarray(cracks.first, dtype=np.int64)
    count = np.ascontiguousarray(cracks.count, dtype=np.int64)
    found = np.zeros((_MAX_HITS, 5))
    nhit, bad_edge, bad_crack = _contour_hits(xs, ys, P[0], P[1], first, count,
                                              1e-12 * (hx + hy), found)
    if bad_edge >= 0:
        raise ValueError(f"crack {bad_crack} runs along a J-contour edge near "
                         f"({xs[bad_edge]:g}, {ys[bad_edge]:g}); keep cracks off grid lines")
    # (edge, t along edge, crack, chord start particle k, u along chord)
    # (only the first _MAX_HITS are kept; more are counted)
    hits = [(int(h[0]), float(h[1]), int(h[2]), int(h[3]), float(h[4]))
            for h in found[:min(nhit, _MAX_HITS)]]
    others = [h for h in hits if h[2] != crack_index]
    if others:
        raise ValueError(f"crack {others[0][2]} crosses the J contour of crack "
                         f"{crack_index}; contours crossing other cracks are not supported")
    if nhit != 1:
        raise ValueError(f"the J contour (half-size {s} cells) crosses crack {crack_index} "
                         f"{nhit} times; it must cross it exactly once")
    e_hit, f_hit, _, k_hit, u_hit = hits[0]

    # trapezoid rule on field 0 along every edge but the crossed one
    V, has = fields.table(nodes, 0)
    if not has.any():
        raise ValueError("no node of the J contour has particles")
    dxe, dye = np.diff(xs), np.diff(ys)
    ds = np.hypot(dxe, dye)
    nx, ny = dye / ds, -dxe / ds                 # outward for a CCW walk
    f_from = _integrands(V[:-1], has[:-1], nx, ny)
    f_to = _integrands(V[1:], has[1:], nx, ny)
    edge = 0.5 * (f_from + f_to) * ds[:, None]
    edge[e_hit] = 0.0
    J = edge.sum(axis=0)
    # the crossed edge: each side of the crossing with that side's fields
    e = e_hit
    n1, n2 = int(nodes[e]), int(nodes[e + 1])
    v1 = V[e] if has[e] else None
    v2 = V[e + 1] if has[e + 1] else None
    f = f_hit
    a1 = fields.values(n1, 1) if fields.field_crack(n1) == crack_index else None
    a2 = fields.values(n2, 1) if fields.field_crack(n2) == crack_index else None
    end_v = _blend(v1, a2, f)        # node1's side, at the crossing
    start_v = _blend(a1, v2, f)      # node2's side, at the crossing
    nxe, nye = nx[e], ny[e]
    J += 0.5 * (_integrand(v1, nxe, nye) + _integrand(end_v, nxe, nye)) * (f * ds[e])
    J += 0.5 * (_integrand(start_v, nxe, nye) + _integrand(v2, nxe, nye)) * ((1.0 - f) * ds[e])

    Jx, Jy = float(J[0]), float(J[1])
    J1 = Jx * d[0] + Jy * d[1]
    J2 = -Jx * d[1] + Jy * d[0]
    cross = P[:, k_hit] + u_hit * (P[:, k_hit + 1] - P[:, k_hit])
    if tip_end == "end":
        cp, cb, frac = k_hit + 1, k_hit, 1.0 - u_hit
    else:
        cp, cb, frac = k_hit, k_hit + 1, u_hit
    corners = np.array([(ic - s, jc - s), (ic + s, jc - s), (ic + s, jc + s), (ic - s, jc + s)])
    return JResult(J1=float(J1), J2=float(J2), Jx=Jx, Jy=Jy, direction=d.copy(), tip=tip,
                   crossing=np.asarray(cross, dtype=float), crossing_particle=int(cp),
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
