"""R-curve theory for cracks with bridging zones (seed paper, Sections 3 and 5).

Units throughout: COD delta in mm, stresses in MPa, R, J_tip,c, J_B and W_B in J/m^2,
slopes dR/ddelta in J/m^2 per mm, force in N, displacement and crack length in mm,
thickness B in mm, U in J/m (energy per unit thickness).

* Any traction law (any object with the ``TractionLaw`` interface) works numerically:
  ``R_of_delta`` (Eq 16), ``R_eff_of_delta`` (Eq 14), ``dR_ddelta`` (Eq 17).
* Closed forms for the built-in laws: Eq 21 (triangular), Eq 22 (cubic), Eq 23 (cubic
  R_eff), Eq 27 (linear-softening R_eff) and the linear-softening R, which Eq 16 makes
  a straight line of slope sigma_c/2 (the paper's remark that sigma_c follows from the
  slope of R(delta) without knowing J_B or delta_c).
* Inversion: ``invert_traction`` (Eq 18) from R'(delta), ``traction_from_R`` from R
  samples, ``traction_from_R_eff`` (Eq 14).
* Fig 5: ``best_triangular_peak`` (the triangular peak whose W_B best matches the
  cubic's, 0.2259 delta_c) and ``fig5_curves``.
* Area method (Section 5.1): ``area_method_U`` (Eq 26), ``R_from_area_method`` (slope of
  U(a) by a smoothing spline) and ``R_discrete`` (Eq 25).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import cumulative_trapezoid, quad
from scipy.interpolate import make_smoothing_spline
from scipy.optimize import minimize_scalar

from .. import plugins

MPA_MM_TO_J_M2 = 1000.0  # MPa*mm = N/mm = 1 kJ/m^2


def _out(x):
    x = np.asarray(x, dtype=float)
    return x if x.ndim else float(x)


# ---- any law, numerically -------------------------------------------------------------
def R_eff_of_delta(law, delta, J_tip_c: float, mode=1):
    """Eq 14: R_eff = J_tip,c + W_B(delta_root), the J_ff-based effective R curve."""
    return _out(J_tip_c + np.asarray(law.work_to(delta, mode)))


def R_of_delta(law, delta, J_tip_c: float, mode=1):
    """Eq 16: R = J_tip,c + W_B(delta) - sigma(delta) delta / 2, the energy actually
    released when the bridging zone unloads linearly to the origin (Eq 15).  Past
    delta_c the recoverable part is zero and R = J_tip,c + J_B (steady state)."""
    return _out(J_tip_c + np.asarray(law.dissipated(delta, mode)))


def dR_ddelta(law, delta, mode=1):
    """Eq 17: dR/ddelta = (sigma - delta sigma')/2 in J/m^2 per mm; zero outside
    (0, delta_c).  sigma' by central differences (one-sided at the ends), so a kink in
    the law gives the mean of the two sides."""
    env = law.mode(mode)
    dc = env.delta_c
    d = np.asarray(delta, dtype=float)
    eps = 1e-6 * dc
    lo = np.clip(d - eps, 0.0, None)
    hi = np.minimum(d + eps, dc * (1.0 - 1e-12))
    hi = np.maximum(hi, lo + 1e-3 * eps)
    slope = (env(hi) - env(lo)) / (hi - lo)
    dR = 0.5 * MPA_MM_TO_J_M2 * (env(d) - d * slope)
    return _out(np.where((d >= 0) & (d < dc), dR, 0.0))


# ---- closed forms ---------------------------------------------------------------------
def R_triangular(delta, J_tip_c, J_B, delta_c, delta_pk):
    """Eq 21: flat at J_tip,c up to the peak (elastic, all recoverable), then linear."""
    d = np.clip(np.asarray(delta, dtype=float), 0.0, delta_c)
    if delta_pk >= delta_c:  # elastic-brittle: nothing released before failure
        return _out(np.where(d >= delta_c, J_tip_c + J_B, J_tip_c))
    return _out(J_tip_c + J_B * np.clip(d - delta_pk, 0.0, None) / (delta_c - delta_pk))


def R_cubic(delta, J_tip_c, J_B, delta_c):
    """Eq 22: R = J_tip,c + J_B x^3 (4 - 3x), x = delta/delta_c."""
    x = np.clip(np.asarray(delta, dtype=float) / delta_c, 0.0, 1.0)
    return _out(J_tip_c + J_B * x**3 * (4.0 - 3.0 * x))


def R_eff_cubic(delta, J_tip_c, J_B, delta_c):
    """Eq 23: R_eff = J_tip,c + J_B x^2 (6 - 8x + 3x^2)."""
    x = np.clip(np.asarray(delta, dtype=float) / delta_c, 0.0, 1.0)
    return _out(J_tip_c + J_B * x**2 * (6.0 - 8.0 * x + 3.0 * x * x))


def R_eff_linear_softening(delta, J_tip_c, J_B, delta_c):
    """Eq 27 (Lindhagen and Berglund's linear softening law): R_eff = J_tip,c +
    J_B x (2 - x), non-sigmoidal, steepest at the start."""
    x = np.clip(np.asarray(delta, dtype=float) / delta_c, 0.0, 1.0)
    return _out(J_tip_c + J_B * x * (2.0 - x))


def R_linear_softening(delta, J_tip_c, J_B, delta_c):
    """Eq 16 for linear softening: R = J_tip,c + J_B x, a straight line of slope
    J_B/delta_c = sigma_c/2 (x 1000 in J/m^2 per mm)."""
    x = np.clip(np.asarray(delta, dtype=float) / delta_c, 0.0, 1.0)
    return _out(J_tip_c + J_B * x)


def sigma_c_from_linear_R_slope(slope_J_m2_per_mm: float) -> float:
    """Section 5.3: for a linear softening law sigma_c = 2 dR/ddelta (MPa), measurable
    even when the experiment never reaches steady state."""
    return 2.0 * slope_J_m2_per_mm / MPA_MM_TO_J_M2


def closed_form_R(law, delta, J_tip_c: float, mode=1):
    """The paper's closed-form R(delta) for a built-in law (Eq 21, 22 or linear
    softening), or None when the law has none."""
    env = law.mode(mode)
    if law.name == "Triangular":
        return R_triangular(delta, J_tip_c, env.area, env.delta_c, env.peak_delta)
    if law.name == "Cubic":
        return R_cubic(delta, J_tip_c, env.area, env.delta_c)
    if law.name == "LinearSoftening":
        return R_linear_softening(delta, J_tip_c, env.area, env.delta_c)
    return None


def closed_form_R_eff(law, delta, J_tip_c: float, mode=1):
    """The paper's closed-form R_eff(delta) (Eq 23 cubic, Eq 27 linear softening), or
    None."""
    env = law.mode(mode)
    if law.name == "Cubic":
        return R_eff_cubic(delta, J_tip_c, env.area, env.delta_c)
    if law.name == "LinearSoftening":
        return R_eff_linear_softening(delta, J_tip_c, env.area, env.delta_c)
    return None


# ---- inversion ---------------------------------------------------------------------------
def invert_traction(delta, Rprime):
    """Eq 18: sigma(delta) = 2 delta * integral_delta^inf R'(s)/s^2 ds, in MPa.

    ``delta`` (mm, increasing, >= 0) and ``Rprime`` (dR/ddelta, J/m^2 per mm) are
    samples; R' is taken as piecewise linear between them and zero beyond the last.
    Each panel's integral of (p + q s)/s^2 is done exactly, so the 1/s^2 weight near
    delta -> 0 costs no accuracy.  At delta = 0 the limit 2 R'(0) is used.
    """
    d = np.asarray(delta, dtype=float)
    rp = np.asarray(Rprime, dtype=float)
    if d.ndim != 1 or d.shape != rp.shape or len(d) < 2:
        raise ValueError("delta and Rprime must be 1D arrays of the same length (>= 2)")
    if np.any(np.diff(d) <= 0) or d[0] < 0:
        raise ValueError("delta must be >= 0 and strictly increasing")
    a, b = d[:-1], d[1:]
    q = (rp[1:] - rp[:-1]) / (b - a)
    p = rp[:-1] - q * a
    panel = np.zeros(len(a))
    pos = a > 0
    panel[pos] = p[pos] * (1.0 / a[pos] - 1.0 / b[pos]) + q[pos] * np.log(b[pos] / a[pos])
    tail = np.concatenate([np.cumsum(panel[::-1])[::-1], [0.0]])  # integral from d_i to end
    sigma = 2.0 * d * tail
    if d[0] == 0:
        sigma[0] = 2.0 * rp[0]
    return sigma / MPA_MM_TO_J_M2


def derivative(x, y, smoothing=None):
    """dy/dx at the samples: second-order finite differences (ends too) when ``smoothing`` is None,
    else the derivative of ``make_smoothing_spline`` (``smoothing='gcv'`` picks the
    penalty by generalised cross-validation, a number sets it)."""
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    if smoothing is None:
        return np.gradient(y, x, edge_order=2)
    lam = None if smoothing == "gcv" else float(smoothing)
    return make_smoothing_spline(x, y, lam=lam).derivative()(x)


def traction_from_R(delta, R, smoothing=None):
    """Traction law sigma(delta) (MPa) from a measured R(delta) (J/m^2): R' then Eq 18."""
    return invert_traction(delta, derivative(delta, R, smoothing))


def traction_from_R_eff(delta, R_eff, smoothing=None):
    """Eq 14: sigma(delta) = dR_eff/ddelta (MPa) from an R_eff(delta) curve (J/m^2)."""
    return derivative(delta, R_eff, smoothing) / MPA_MM_TO_J_M2


# ---- Fig 5 ---------------------------------------------------------------------------------
def _law(name, **params):
    info = plugins.resolve("traction_laws", name)
    if info is None:
        raise ValueError(f"no traction law named {name} is installed")
    return info.cls.from_params(**params)


def W_B_mismatch(relative_peak: float) -> float:
    """Integral over 0 < delta < delta_c of [W_B,triangular - W_B,cubic]^2 for laws of the
    same area and delta_c (normalised: delta_c = 1 mm, J_B = 1 J/m^2)."""
    tri = _law("Triangular", delIc=1.0, JIc=1.0, delpkI=relative_peak)
    cub = _law("Cubic", delIc=1.0, JIc=1.0)
    val, _ = quad(lambda x: (tri.work_to(x) - cub.work_to(x)) ** 2, 0.0, 1.0,
                  points=[relative_peak], epsabs=1e-15, epsrel=1e-12, limit=200)
    return val


def best_triangular_peak() -> float:
    """delta_pk/delta_c of the triangular law whose W_B(delta) best matches the cubic
    law's in least squares (the paper quotes 0.2259; NairnMPM's default 0.225926299)."""
    r = minimize_scalar(W_B_mismatch, bounds=(0.01, 0.99), method="bounded",
                        options={"xatol": 1e-9})
    return float(r.x)


FIG5_PEAK = 0.2259  # the paper's value


def fig5_curves(x=None, relative_peak: float = FIG5_PEAK) -> dict[str, np.ndarray]:
    """Fig 5: R/J_tip,c against delta/delta_c for triangular (peak ``relative_peak``) and
    cubic laws with J_B = J_tip,c, and the cubic R_eff/J_tip,c."""
    x = np.linspace(0.0, 1.0, 201) if x is None else np.asarray(x, dtype=float)
    tri = _law("Triangular", delIc=1.0, JIc=1.0, delpkI=relative_peak)
    cub = _law("Cubic", delIc=1.0, JIc=1.0)
    return {"x": x,
            "R_triangular": R_of_delta(tri, x, 1.0),
            "R_cubic": R_of_delta(cub, x, 1.0),
            "R_eff_cubic": R_eff_of_delta(cub, x, 1.0)}


# ---- area method ----------------------------------------------------------------------------
def area_method_U(d, F, B: float):
    """Eq 26: U(d) = [integral_0^d F dx - d F(d)/2] / B, the cumulative energy released
    per unit thickness (J/m, i.e. N mm per mm).  If the data do not start at d = 0 the
    load is taken as linear from the origin to the first point."""
    d = np.asarray(d, dtype=float)
    F = np.asarray(F, dtype=float)
    work = 0.5 * F[0] * d[0] + cumulative_trapezoid(F, d, initial=0.0)
    return (work - 0.5 * d * F) / B


@dataclass
class AreaMethodFit:
    a: np.ndarray      # mm, distinct crack lengths from initiation on
    U: np.ndarray      # J/m, U at those lengths (mean of rows sharing a length)
    R: np.ndarray      # J/m^2, slope of the fitted U(a) at a
    spline: object     # the fitted U(a) (scipy BSpline, J/m against mm)

    def R_at(self, a):
        return _out(MPA_MM_TO_J_M2 * self.spline.derivative()(np.asarray(a, dtype=float)))


def R_from_area_method(d, F, a, B: float, smoothing="gcv") -> AreaMethodFit:
    """Revised area method (Section 5.1, Fig 11): U(d) by Eq 26, replotted against crack
    length, R = dU/da.

    The slope comes from ``scipy.interpolate.make_smoothing_spline``, a penalised cubic
    smoothing spline (the paper's "least-squares cubic spline fit").  It was chosen over
    ``UnivariateSpline`` because its penalty can be picked by generalised cross-
    validation (``smoothing='gcv'``, the default) instead of needing the noise level
    ``s``; pass a number to fix the penalty lambda (mm^3 scale; larger is smoother).

    Rows before crack growth all share the initial length; they and any other rows with
    equal lengths are averaged into one point so U(a) is a function.
    """
    d = np.asarray(d, dtype=float)
    F = np.asarray(F, dtype=float)
    a = np.asarray(a, dtype=float)
    U = area_method_U(d, F, B)
    a_u, inverse = np.unique(a, return_inverse=True)
    U_u = np.bincount(inverse, weights=U) / np.bincount(inverse)
    if len(a_u) < 5:
        raise ValueError(f"the area method needs at least 5 distinct crack lengths (got {len(a_u)})")
    lam = None if smoothing == "gcv" or smoothing is None else float(smoothing)
    spline = make_smoothing_spline(a_u, U_u, lam=lam)
    R = MPA_MM_TO_J_M2 * spline.derivative()(a_u)
    return AreaMethodFit(a=a_u, U=U_u, R=R, spline=spline)


def R_discrete(F1, d1, F2, d2, a1, a2, B: float):
    """Eq 25: R = (F1 d2 - F2 d1) / (2 B (a2 - a1)), in J/m^2 (the discrete area between
    the loading lines through the two points, over the crack growth)."""
    F1, d1, F2, d2, a1, a2 = (np.asarray(v, dtype=float) for v in (F1, d1, F2, d2, a1, a2))
    return _out(MPA_MM_TO_J_M2 * (F1 * d2 - F2 * d1) / (2.0 * B * (a2 - a1)))


def discrete_area_method(d, F, a, B: float):
    """Eq 25 between consecutive rows whose crack length grew: returns (a_mid, R)."""
    d, F, a = (np.asarray(v, dtype=float) for v in (d, F, a))
    grew = np.flatnonzero(np.diff(a) > 0)
    R = R_discrete(F[grew], d[grew], F[grew + 1], d[grew + 1], a[grew], a[grew + 1], B)
    return 0.5 * (a[grew] + a[grew + 1]), np.atleast_1d(R)
