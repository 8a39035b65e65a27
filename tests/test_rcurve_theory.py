"""R-curve theory (seed paper Eqs 14-27) against its closed forms, the Eq 18 inversion,
the Fig 5 peak, and the area method on synthetic DCB data."""
import numpy as np
import pytest

from nairnmpm_py import plugins
from nairnmpm_py.analysis import rcurve as rc

J_TIP = 100.0  # J/m^2, the paper's crack-tip toughness


def law(name, **params):
    return plugins.resolve("traction_laws", name).cls.from_params(**params)


# An example for every registered built-in (J_B in J/m^2)
EVERY_LAW = {
    "Triangular": dict(sigmaI=0.5, JIc=100.0),
    "Cubic": dict(sigmaI=0.5, JIc=100.0),
    "LinearSoftening": dict(sigmaI=0.5, JIc=100.0),
    "Trilinear": dict(sigmaI=1.0, delpkI=0.05, sigmaI2=0.3, delpkI2=0.4, JIc=100.0),
    "Exponential": dict(sigmaI=0.5, delpkI=0.1, JIc=100.0, alphaI=2.0),
}


def test_every_registered_law_has_an_example():
    assert {p.name for p in plugins.registry("traction_laws")} >= set(EVERY_LAW)


# ---- closed forms against the numerical theory ------------------------------------------------
@pytest.mark.parametrize("sigma", [0.2, 0.5, 1.0])  # the paper's Fig 7 laws
def test_eq22_cubic_R_equals_numerical_eq16(sigma):
    lw = law("Cubic", sigmaI=sigma, JIc=100.0)
    dc = lw.delta_c()
    assert dc == pytest.approx(16 * 100.0 / (9 * sigma * 1000))
    d = np.linspace(0, dc, 501)
    np.testing.assert_allclose(rc.R_of_delta(lw, d, J_TIP), rc.R_cubic(d, J_TIP, 100.0, dc),
                               rtol=1e-6)
    np.testing.assert_allclose(rc.R_eff_of_delta(lw, d, J_TIP),
                               rc.R_eff_cubic(d, J_TIP, 100.0, dc), rtol=1e-6)
    # the same with the purely numerical W_B (no closed-form area_to)
    from nairnmpm_py.traction.base import numeric_work_to
    numeric_R = J_TIP + numeric_work_to(lw, d) - lw.recoverable(d)
    np.testing.assert_allclose(numeric_R, rc.R_cubic(d, J_TIP, 100.0, dc), rtol=1e-6)


@pytest.mark.parametrize("rel_peak", [0.1, 0.2259, 0.5, 0.9])
def test_eq21_triangular_R(rel_peak):
    lw = law("Triangular", sigmaI=0.5, JIc=100.0, delpkI=rel_peak)
    dc, dp = lw.delta_c(), lw.peak_delta()
    d = np.linspace(0, dc, 501)
    R = rc.R_of_delta(lw, d, J_TIP)
    np.testing.assert_allclose(R, rc.R_triangular(d, J_TIP, 100.0, dc, dp), rtol=1e-6)
    assert np.all(R[d <= dp] == pytest.approx(J_TIP))  # flat while elastic


def test_eq27_linear_softening():
    lw = law("LinearSoftening", sigmaI=0.5, JIc=100.0)
    dc = lw.delta_c()
    d = np.linspace(0, dc, 201)
    np.testing.assert_allclose(rc.R_eff_of_delta(lw, d, J_TIP),
                               rc.R_eff_linear_softening(d, J_TIP, 100.0, dc), rtol=1e-6)
    # Eq 27 is steepest at the start (non-sigmoidal); R itself is a straight line...
    x = d / dc
    np.testing.assert_allclose(rc.R_eff_linear_softening(d, J_TIP, 100.0, dc),
                               J_TIP + 100.0 * x * (2 - x))
    R = rc.R_of_delta(lw, d, J_TIP)
    np.testing.assert_allclose(R, J_TIP + 100.0 * x, rtol=1e-6)
    # ...whose slope gives sigma_c without J_B or delta_c (Section 5.3)
    slope = np.polyfit(d, R, 1)[0]
    assert rc.sigma_c_from_linear_R_slope(slope) == pytest.approx(0.5, rel=1e-6)


def test_closed_form_dispatch():
    for name in ("Triangular", "Cubic", "LinearSoftening"):
        lw = law(name, **EVERY_LAW[name])
        d = np.linspace(0, lw.delta_c(), 101)
        np.testing.assert_allclose(rc.closed_form_R(lw, d, J_TIP), rc.R_of_delta(lw, d, J_TIP),
                                   rtol=1e-6)
    assert rc.closed_form_R(law("Exponential", **EVERY_LAW["Exponential"]), 0.1, J_TIP) is None


@pytest.mark.parametrize("name", sorted(EVERY_LAW))
def test_R_rises_from_Jtip_to_steady_state(name):
    lw = law(name, **EVERY_LAW[name])
    dc = lw.delta_c()
    d = np.linspace(0, dc, 401)
    R = rc.R_of_delta(lw, d, J_TIP)
    R_eff = rc.R_eff_of_delta(lw, d, J_TIP)
    assert R[0] == pytest.approx(J_TIP)
    # steady state: W_B^(r) -> 0 at delta_c so R = J_tip,c + J_B
    assert rc.R_of_delta(lw, dc, J_TIP) == pytest.approx(J_TIP + lw.area(), rel=1e-12)
    assert rc.R_of_delta(lw, 2 * dc, J_TIP) == pytest.approx(J_TIP + 100.0, rel=1e-12)
    assert lw.recoverable(dc) == 0.0
    assert np.all(np.diff(R) >= -1e-9)
    assert np.all(R_eff >= R - 1e-9)  # R_eff omits the recoverable energy


@pytest.mark.parametrize("name", sorted(EVERY_LAW))
def test_eq17_slope_matches_derivative_of_R(name):
    lw = law(name, **EVERY_LAW[name])
    dc = lw.delta_c()
    kinks = np.array(lw.mode(1).breakpoints)
    d = np.linspace(0.02 * dc, 0.98 * dc, 97)
    d = d[np.all(np.abs(d[:, None] - kinks[None, :]) > 0.01 * dc, axis=1)] if kinks.size else d
    h = 1e-5 * dc
    numeric = (rc.R_of_delta(lw, d + h, J_TIP) - rc.R_of_delta(lw, d - h, J_TIP)) / (2 * h)
    np.testing.assert_allclose(rc.dR_ddelta(lw, d), numeric, rtol=1e-5, atol=1e-6 * 100 / dc)


def test_eq17_cubic_closed_form():
    lw = law("Cubic", sigmaI=0.5, JIc=100.0)
    dc = lw.delta_c()
    d = np.linspace(0, dc, 101)
    x = d / dc
    np.testing.assert_allclose(rc.dR_ddelta(lw, d), 100.0 * 12 * x**2 * (1 - x) / dc,
                               rtol=1e-6, atol=1e-6)


# ---- Eq 18 inversion ------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", sorted(EVERY_LAW))
def test_eq18_recovers_the_law_from_R(name):
    lw = law(name, **EVERY_LAW[name])
    dc, sc = lw.delta_c(), lw.peak_stress()
    d = np.linspace(0, dc, 801)
    inner = (d >= 0.05 * dc) & (d <= 0.95 * dc)
    exact = lw.envelope(d)
    # from R'(delta) (Eq 17) ...
    sigma = rc.invert_traction(d, rc.dR_ddelta(lw, d))
    err_slope = np.abs(sigma - exact)[inner].max() / sc
    # ... and from sampled R(delta) alone, as an experiment would give it
    sigma_R = rc.traction_from_R(d, rc.R_of_delta(lw, d, J_TIP))
    err_R = np.abs(sigma_R - exact)[inner].max() / sc
    tol = 0.01 if name in ("Cubic", "Triangular") else 0.02
    assert err_slope < tol and err_R < tol, (err_slope, err_R)


def test_eq18_cubic_and_triangular_accuracy():
    """Numbers worth knowing: the smooth cubic inverts to ~1e-5 sigma_c, the triangular
    law's kink costs ~0.2% right at the peak on a 801-point grid."""
    errs = {}
    for name in ("Cubic", "Triangular"):
        lw = law(name, sigmaI=1.0, JIc=100.0)
        dc = lw.delta_c()
        d = np.linspace(0, dc, 801)
        inner = (d >= 0.05 * dc) & (d <= 0.95 * dc)
        s = rc.traction_from_R(d, rc.R_of_delta(lw, d, J_TIP))
        errs[name] = np.abs(s - lw.envelope(d))[inner].max()
    assert errs["Cubic"] < 1e-4
    assert errs["Triangular"] < 5e-3


def test_eq18_treats_Rprime_as_zero_beyond_the_data():
    d = np.linspace(0, 2.0, 201)
    Rp = np.where(d < 1.0, 50.0, 0.0)  # linear-softening R' = sigma_c/2 (x 1000) up to 1 mm
    sigma = rc.invert_traction(d, Rp)
    x = d[d < 0.9]
    np.testing.assert_allclose(sigma[d < 0.9], 0.1 * (1 - x), rtol=2e-2, atol=1e-3)
    assert sigma[0] == pytest.approx(0.1)
    assert np.all(sigma[d > 1.0] == 0)


def test_eq14_inversion_of_R_eff():
    lw = law("Cubic", sigmaI=0.5, JIc=100.0)
    d = np.linspace(0, lw.delta_c(), 801)
    sigma = rc.traction_from_R_eff(d, rc.R_eff_of_delta(lw, d, J_TIP))
    np.testing.assert_allclose(sigma, lw.envelope(d), atol=1e-4 * 0.5)


# ---- Fig 5 --------------------------------------------------------------------------------------------------
def test_fig5_best_triangular_peak_is_0_2259():
    best = rc.best_triangular_peak()
    assert best == pytest.approx(0.2259, abs=1e-3)
    assert best == pytest.approx(0.225926299, abs=1e-6)  # NairnMPM's default
    assert rc.W_B_mismatch(best) < rc.W_B_mismatch(best - 0.01)
    assert rc.W_B_mismatch(best) < rc.W_B_mismatch(best + 0.01)


def test_fig5_curves():
    c = rc.fig5_curves()
    x = c["x"]
    assert np.all(c["R_triangular"][x <= 0.2259] == pytest.approx(1.0))
    for key in ("R_triangular", "R_cubic", "R_eff_cubic"):
        assert c[key][0] == pytest.approx(1.0) and c[key][-1] == pytest.approx(2.0)
    np.testing.assert_allclose(c["R_cubic"], 1 + x**3 * (4 - 3 * x), rtol=1e-9)
    assert np.all(c["R_eff_cubic"] >= c["R_cubic"] - 1e-12)


# ---- area method --------------------------------------------------------------------------------------------
B = 20.0          # mm
R_TRUE = 500.0    # J/m^2
K = 8.0 / (2500.0 * B * 6.0**3)  # DCB compliance C(a) = K a^3 (mm/N), E = 2500 MPa, h = 6 mm
A0 = 50.0


def dcb_data(n_load=20, n_grow=60, a_end=100.0):
    """Force, displacement and crack length of a linear elastic DCB with constant R:
    load along C(a0) to the critical force, then grow with G = F^2/(2B) dC/da = R."""
    Rn = R_TRUE / 1000.0  # N/mm
    Fc = np.sqrt(2 * B * Rn / (3 * K * A0**2))
    F_load = np.linspace(0, Fc, n_load)
    a_grow = np.linspace(A0, a_end, n_grow)[1:]
    F = np.concatenate([F_load, np.sqrt(2 * B * Rn / (3 * K * a_grow**2))])
    a = np.concatenate([np.full(n_load, A0), a_grow])
    return K * a**3 * F, F, a


def test_area_method_U_is_R_times_growth():
    d, F, a = dcb_data()
    U = rc.area_method_U(d, F, B)
    assert np.allclose(U[a == A0], 0.0, atol=1e-9)  # elastic loading releases nothing
    # trapezoid rule on the curved F(d) path: second order in the step
    np.testing.assert_allclose(U, R_TRUE / 1000 * (a - A0), rtol=1e-3, atol=1e-9)


def test_area_method_recovers_constant_R():
    d, F, a = dcb_data()
    fit = rc.R_from_area_method(d, F, a, B)
    np.testing.assert_allclose(fit.R, R_TRUE, rtol=0.02)
    assert fit.R_at(75.0) == pytest.approx(R_TRUE, rel=0.02)
    a_mid, R_d = rc.discrete_area_method(d, F, a, B)
    assert len(a_mid) == 59
    np.testing.assert_allclose(R_d, R_TRUE, rtol=0.02)


def test_area_method_reduces_scatter():
    """Section 5.1: the slope of U(a) is far less noisy than Eq 25, which subtracts
    nearly equal numbers."""
    d, F, a = dcb_data(n_grow=120)
    noisy = F * (1 + 0.005 * np.random.default_rng(0).standard_normal(len(F)))
    fit = rc.R_from_area_method(d, noisy, a, B)
    _, R_d = rc.discrete_area_method(d, noisy, a, B)
    rms_spline = np.sqrt(np.mean((fit.R / R_TRUE - 1) ** 2))
    rms_discrete = np.sqrt(np.mean((R_d / R_TRUE - 1) ** 2))
    assert abs(np.mean(fit.R) / R_TRUE - 1) < 0.02
    assert rms_spline < 0.1 * rms_discrete


def test_eq25_single_step():
    # two points on loading lines of compliance 1 and 1.2 mm/N with 2 mm of growth
    R = rc.R_discrete(F1=100.0, d1=100.0, F2=90.0, d2=108.0, a1=50.0, a2=52.0, B=10.0)
    assert R == pytest.approx(1000 * (100 * 108 - 90 * 100) / (2 * 10 * 2))
