"""Traction-law plugins: parameters as NairnMPM takes them, areas, peaks, the jitted
envelope against the numpy one, and the framework's history/unloading/failure."""
import math

import numpy as np
import pytest
from numba import njit
from pydantic import ValidationError
from scipy.integrate import quad
from scipy.optimize import minimize_scalar

from nairnmpm_py import plugins
from nairnmpm_py.traction.base import (ModeSpec, TractionLaw, TractionParams,
                                       load_envelope_function, numeric_work_to,
                                       traction_with_history)


def law(name, **params):
    return plugins.resolve("traction_laws", name).cls.from_params(**params)


# One example per built-in law (mode I only unless said), J in J/m^2.
EXAMPLES = {
    "triangular": ("Triangular", dict(sigmaI=1.0, JIc=100.0)),
    "triangular_kIe": ("Triangular", dict(sigmaI=2.0, delIc=0.3, kIe=40.0)),
    "elastic_brittle": ("Triangular", dict(delIc=0.2, JIc=50.0, delpkI=1.0)),
    "cubic": ("Cubic", dict(sigmaI=0.5, JIc=100.0)),
    "linear_softening": ("LinearSoftening", dict(sigmaI=0.8, delIc=0.5)),
    "trilinear": ("Trilinear", dict(sigmaI=2.0, delpkI=0.1, sigmaI2=0.5, delpkI2=0.3, JIc=200.0)),
    "trilinear_step": ("Trilinear", dict(sigmaI=2.0, delpkI=0.2, sigmaI2=0.5, delpkI2=0.2, delIc=0.4)),
    "exponential": ("Exponential", dict(sigmaI=1.0, delpkI=0.1, JIc=100.0, alphaI=3.0)),
}
EXPECTED_J = {"triangular": 100.0, "triangular_kIe": 300.0, "elastic_brittle": 50.0,
              "cubic": 100.0, "linear_softening": 200.0, "trilinear": 200.0,
              "trilinear_step": 0.5 * 0.4 * (2.0 * 0.2 + 0.5 * 0.8) * 1000.0,
              "exponential": 100.0}


@pytest.fixture(params=sorted(EXAMPLES))
def example(request):
    name, params = EXAMPLES[request.param]
    return request.param, law(name, **params)


# ---- registry -----------------------------------------------------------------------
def test_builtins_registered_by_name_and_type():
    assert plugins.resolve("traction_laws", 12).name == "Triangular"
    assert plugins.resolve("traction_laws", "14").name == "Cubic"
    assert plugins.resolve("traction_laws", 20).name == "Trilinear"
    assert plugins.resolve("traction_laws", 34).name == "Exponential"
    assert plugins.resolve("traction_laws", "linearsoftening").nairn_type is None
    # NairnMPM's Type 13 is a linear *elastic* traction, not linear softening
    assert plugins.resolve("traction_laws", 13) is None


# ---- area and peak ----------------------------------------------------------------------
def test_area_of_envelope_equals_J(example):
    key, lw = example
    env = lw.mode(1)
    integral, _ = quad(env, 0.0, env.delta_c, points=[p for p in env.breakpoints
                                                      if 0 < p < env.delta_c] or None,
                       limit=200, epsabs=0, epsrel=1e-12)
    assert 1000.0 * integral == pytest.approx(EXPECTED_J[key], rel=1e-9)
    assert lw.area() == pytest.approx(EXPECTED_J[key], rel=1e-12)
    assert lw.work_to(env.delta_c) == pytest.approx(EXPECTED_J[key], rel=1e-12)
    assert lw.work_to(10 * env.delta_c) == pytest.approx(EXPECTED_J[key], rel=1e-12)


def test_peak_is_the_envelope_maximum(example):
    _, lw = example
    env = lw.mode(1)
    d = np.linspace(0.0, env.delta_c, 20001)[:-1]
    s = env(d)
    # sharp peaks fall between grid points: never above, and close below
    assert env.peak_stress * (1 - 1e-3) < s.max() <= env.peak_stress * (1 + 1e-12)
    at = min(env.peak_delta, env.delta_c * (1 - 1e-13))  # elastic-brittle peaks at delta_c
    assert env(at) == pytest.approx(env.peak_stress, rel=1e-9)


def test_cubic_peak_at_one_third_of_delta_c():
    lw = law("Cubic", sigmaI=0.7, delIc=0.3)
    r = minimize_scalar(lambda d: -lw.envelope(d), bounds=(0, 0.3), method="bounded",
                        options={"xatol": 1e-12})
    assert r.x == pytest.approx(0.1, rel=1e-6)
    assert -r.fun == pytest.approx(0.7, rel=1e-12)
    assert lw.peak_delta() == pytest.approx(0.1) and lw.peak_stress() == 0.7
    assert lw.area() == pytest.approx(9 / 16 * 0.7 * 0.3 * 1000)


def test_triangular_default_peak_and_kIe():
    lw = law("Triangular", sigmaI=1.0, delIc=0.2)
    assert lw.peak_delta() == pytest.approx(0.225926299 * 0.2)
    assert lw.area() == pytest.approx(100.0)
    lw = law("Triangular", sigmaI=2.0, delIc=0.3, kIe=40.0)
    assert lw.peak_delta() == pytest.approx(0.05)
    assert lw.envelope(0.025) == pytest.approx(1.0)


# ---- parameter sets -------------------------------------------------------------------------
@pytest.mark.parametrize("name,factor", [("Triangular", 0.5), ("Cubic", 9 / 16),
                                         ("LinearSoftening", 0.5)])
def test_two_of_sigma_delta_J(name, factor):
    sigma, dc = 0.4, 0.25
    J = 1000 * factor * sigma * dc
    for pair in (dict(sigmaI=sigma, delIc=dc), dict(sigmaI=sigma, JIc=J), dict(delIc=dc, JIc=J)):
        lw = law(name, **pair)
        assert lw.peak_stress() == pytest.approx(sigma)
        assert lw.delta_c() == pytest.approx(dc)
        assert lw.area() == pytest.approx(J)
        assert not lw.has_mode(2)  # no mode II parameters: no shear traction
    with pytest.raises(ValidationError, match="give two of sigmaI, delIc, JIc"):
        law(name, sigmaI=sigma, delIc=dc, JIc=J)  # three, even consistent, is an error
    with pytest.raises(ValidationError, match=r"give two of sigmaI, delIc, JIc \(got sigmaI\)"):
        law(name, sigmaI=sigma)
    with pytest.raises(ValidationError, match=r"got none"):
        law(name)
    with pytest.raises(ValidationError, match=r"give two of sigmaII, delIIc, JIIc"):
        law(name, sigmaI=sigma, delIc=dc, sigmaII=1.0)
    with pytest.raises(ValidationError, match="must be >= 0"):
        law(name, sigmaI=-sigma, delIc=dc)
    with pytest.raises(ValidationError, match="Extra inputs"):
        law(name, sigmaI=sigma, delIc=dc, bogus=1.0)
    both = law(name, sigmaI=sigma, delIc=dc, sigmaII=2 * sigma, JIIc=2 * J)
    assert both.delta_c(2) == pytest.approx(dc) and both.area("II") == pytest.approx(2 * J)


def test_triangular_peak_options_are_checked():
    with pytest.raises(ValidationError, match="at most one of delpkI and kIe"):
        law("Triangular", sigmaI=1.0, delIc=0.2, delpkI=0.3, kIe=10.0)
    with pytest.raises(ValidationError, match=r"must be in \(0, 1\]"):
        law("Triangular", sigmaI=1.0, delIc=0.2, delpkI=1.5)
    with pytest.raises(ValidationError, match="exceeds delIc"):
        law("Triangular", sigmaI=1.0, delIc=0.2, kIe=1.0)
    with pytest.raises(ValidationError, match="delpkII given but mode II"):
        law("Triangular", sigmaI=1.0, delIc=0.2, delpkII=0.3)
    lw = law("Triangular", sigmaI=1.0, delIc=0.2, sigmaII=0.5, delIIc=0.4, delpkII=0.5)
    assert lw.peak_delta(2) == pytest.approx(0.2)


TRILINEAR_TRUE = dict(sigmaI=2.0, delpkI=0.1, sigmaI2=0.5, delpkI2=0.3, delIc=0.4)
TRILINEAR_J = 0.5 * 0.4 * (2.0 * 0.3 + 0.5 * 0.9) * 1000.0


@pytest.mark.parametrize("omit", ["sigmaI", "delpkI", "sigmaI2", "delpkI2", "delIc", "JIc"])
def test_trilinear_any_five_of_seven(omit):
    full = dict(TRILINEAR_TRUE, JIc=TRILINEAR_J)
    params = {k: v for k, v in full.items() if k != omit}
    lw = law("Trilinear", **params)
    np.testing.assert_allclose(lw.param_vector(), [0.4, 2.0, 0.04, 0.5, 0.12], rtol=1e-12)
    assert lw.area() == pytest.approx(TRILINEAR_J)


def test_trilinear_kIe_stands_in_for_sigma_or_peak():
    k = 2.0 / 0.04  # sigma_1 / delta_1 in MPa/mm
    a = law("Trilinear", kIe=k, delpkI=0.1, sigmaI2=0.5, delpkI2=0.3, delIc=0.4)
    b = law("Trilinear", kIe=k, sigmaI=2.0, sigmaI2=0.5, JIc=TRILINEAR_J, delIc=0.4)
    for lw in (a, b):
        np.testing.assert_allclose(lw.param_vector(), [0.4, 2.0, 0.04, 0.5, 0.12], rtol=1e-12)
    with pytest.raises(ValidationError, match="exactly one of sigmaI and delpkI"):
        law("Trilinear", kIe=k, sigmaI=2.0, delpkI=0.1, sigmaI2=0.5, delIc=0.4)
    with pytest.raises(ValidationError, match="exactly five"):
        law("Trilinear", **dict(TRILINEAR_TRUE, JIc=TRILINEAR_J, kIe=k))
    with pytest.raises(ValidationError, match="exactly five"):
        law("Trilinear", sigmaI=2.0, delpkI=0.1, delIc=0.4, JIc=100.0)
    with pytest.raises(ValidationError, match="0 < delpkI <= delpkI2 <= 1"):
        law("Trilinear", sigmaI=2.0, delpkI=0.5, sigmaI2=0.5, delpkI2=0.3, delIc=0.4)


EXP_TRUE = dict(sigma=1.2, rel=0.15, uc=0.3, alpha=2.5)


def _exp_J():
    a = EXP_TRUE["alpha"]
    f = 2 * (1 / a - math.exp(-a) / (1 - math.exp(-a)))
    return 500 * EXP_TRUE["sigma"] * EXP_TRUE["uc"] * (EXP_TRUE["rel"] + (1 - EXP_TRUE["rel"]) * f)


@pytest.mark.parametrize("shape", [("sigmaI", "delpkI"), ("sigmaI", "kIe"), ("kIe", "delpkI")])
@pytest.mark.parametrize("end", ["delIc", "JIc"])
def test_exponential_parameter_styles(shape, end):
    k = EXP_TRUE["sigma"] / (EXP_TRUE["rel"] * EXP_TRUE["uc"])
    values = dict(sigmaI=EXP_TRUE["sigma"], delpkI=EXP_TRUE["rel"], kIe=k,
                  delIc=EXP_TRUE["uc"], JIc=_exp_J())
    params = {n: values[n] for n in shape + (end,)}
    lw = law("Exponential", alphaI=EXP_TRUE["alpha"], **params)
    np.testing.assert_allclose(lw.param_vector(), [0.3, 1.2, 0.045, 2.5], rtol=1e-12)
    assert lw.area() == pytest.approx(_exp_J(), rel=1e-12)
    integral, _ = quad(lw.mode(1), 0, 0.3, points=[0.045], epsrel=1e-12)
    assert 1000 * integral == pytest.approx(_exp_J(), rel=1e-9)


def test_exponential_errors():
    with pytest.raises(ValidationError, match="alphaI must be given"):
        law("Exponential", sigmaI=1.0, delpkI=0.1, JIc=100.0)
    with pytest.raises(ValidationError, match="exactly one of delIc and JIc"):
        law("Exponential", sigmaI=1.0, delpkI=0.1, JIc=100.0, delIc=0.3, alphaI=2.0)
    with pytest.raises(ValidationError, match="exactly two of sigmaI, kIe, delpkI"):
        law("Exponential", sigmaI=1.0, JIc=100.0, alphaI=2.0)


# ---- jitted envelope and generic energies -------------------------------------------------------
def test_jitted_envelope_equals_numpy_envelope(example):
    _, lw = example
    f = load_envelope_function(lw)
    par = lw.param_vector()
    dc = lw.delta_c()
    d = np.concatenate([np.linspace(-0.1 * dc, 1.2 * dc, 1001), list(lw.mode(1).breakpoints)])
    jitted = np.array([f(x, par) for x in d])
    np.testing.assert_allclose(jitted, lw.envelope(d), rtol=1e-13, atol=1e-15)
    assert par[0] == dc  # the convention the engine relies on


def test_numeric_work_equals_closed_form(example):
    _, lw = example
    dc = lw.delta_c()
    d = np.random.default_rng(3).uniform(-0.1 * dc, 1.1 * dc, 300)
    np.testing.assert_allclose(numeric_work_to(lw, d), lw.work_to(d), rtol=1e-10, atol=1e-10)


def test_recoverable_and_dissipated(example):
    key, lw = example
    env = lw.mode(1)
    h = np.linspace(0, env.delta_c, 801)
    rec = lw.recoverable(h)
    np.testing.assert_allclose(rec, 500.0 * env(h) * h)
    dis = lw.dissipated(h)
    assert dis[0] == 0 and dis[-1] == pytest.approx(EXPECTED_J[key])
    assert np.all(np.diff(dis) >= -1e-9)  # released energy never decreases


# ---- framework: history, secant unloading, failure ------------------------------------------------
def test_secant_unloading_and_failure():
    lw = law("Cubic", sigmaI=1.0, delIc=0.3)
    env = lw.mode(1)
    h = 0.0
    for d in np.linspace(0.01, 0.15, 15):  # loading follows the envelope
        T, h, failed = traction_with_history(d, h, env)
        assert T == pytest.approx(env(d)) and h == d and not failed
    stiffness = env(0.15) / 0.15
    for d in (0.1, 0.05, 0.12):  # unloading and reloading stay on the secant line
        T, h2, failed = traction_with_history(d, h, env)
        assert T == pytest.approx(stiffness * d) and h2 == 0.15 and not failed
    T, h2, failed = traction_with_history(-0.02, h, env)  # closed: no normal traction
    assert T == 0 and h2 == 0.15 and not failed
    T, h, failed = traction_with_history(0.3, h, env)  # delta_c reached: failed
    assert T == 0 and failed
    T, h, failed = traction_with_history(0.05, h, env)  # and stays failed
    assert T == 0 and failed


def test_shear_uses_magnitude_and_sign():
    lw = law("Triangular", sigmaI=1.0, delIc=0.2, sigmaII=0.5, delIIc=0.4)
    env = lw.mode(2)
    T, h, failed = traction_with_history(-0.1, 0.0, env, shear=True)
    assert T == pytest.approx(-env(0.1)) and h == 0.1 and not failed
    T, h2, _ = traction_with_history(0.05, h, env, shear=True)
    assert T == pytest.approx(env(0.1) / 0.1 * 0.05) and h2 == 0.1
    _, _, failed = traction_with_history(-0.4, h, env, shear=True)
    assert failed


def test_history_vectorised_and_with_plain_function():
    lw = law("Triangular", sigmaI=1.0, delIc=0.2)
    d = np.array([0.01, 0.1, 0.05, 0.25, -0.01])
    h = np.array([0.0, 0.0, 0.15, 0.0, 0.1])
    T, h_new, failed = traction_with_history(d, h, lw.envelope, delta_c=0.2)
    np.testing.assert_allclose(h_new, [0.01, 0.1, 0.15, 0.25, 0.1])
    np.testing.assert_array_equal(failed, [False, False, False, True, False])
    np.testing.assert_allclose(T, [lw.envelope(0.01), lw.envelope(0.1),
                                   lw.envelope(0.15) / 0.15 * 0.05, 0.0, 0.0])


# ---- a new law is a few lines: only mode_spec and a jitted envelope ---------------------------------
@njit(cache=True)
def sine_envelope(delta, par):
    if delta < 0.0 or delta >= par[0]:
        return 0.0
    return par[1] * math.sin(math.pi * delta / par[0])


class SineParams(TractionParams):
    sigmaI: float
    delIc: float


class Sine(TractionLaw):
    name = "Sine"
    Params = SineParams
    envelope_function = f"{__name__}:sine_envelope"

    def mode_spec(self, mode):
        p = self.params
        return ModeSpec(delta_c=p.delIc, par=np.array([p.delIc, p.sigmaI])) if mode == 1 else None


def test_minimal_plugin_gets_everything_numerically():
    lw = Sine.from_params(sigmaI=2.0, delIc=0.5)
    assert lw.peak_delta() == pytest.approx(0.25, rel=1e-6)
    assert lw.peak_stress() == pytest.approx(2.0, rel=1e-12)
    assert lw.area() == pytest.approx(1000 * 2 * 2.0 * 0.5 / math.pi, rel=1e-10)
    d = np.linspace(0, 0.5, 11)
    exact = 1000 * 2.0 * 0.5 / math.pi * (1 - np.cos(math.pi * d / 0.5))
    np.testing.assert_allclose(lw.work_to(d), exact, rtol=1e-12, atol=1e-12)
    assert not lw.has_mode("II")
    with pytest.raises(ValueError, match="no mode II"):
        lw.delta_c(2)
