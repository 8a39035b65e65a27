"""What a traction-law plugin provides, and the framework that works from it.

Units: COD (delta) in mm, stresses in MPa, energy release rates and traction-law
areas in J/m^2.  Since MPa*mm = N/mm = kJ/m^2, an integral of sigma(delta) in
MPa*mm is multiplied by 1000 to give J/m^2 (``MPA_MM_TO_J_M2``).

A traction law is a class with

* ``name`` and ``nairn_type`` (NairnMPM's material ``Type`` number, or None);
* ``Params``: a pydantic model of its XML child elements (``extra='forbid'``) whose
  validators reject inconsistent sets (e.g. "give two of sigmaI, delIc, JIc");
* ``mode_spec(mode) -> ModeSpec | None``: the resolved constants of one mode
  (1 = opening, 2 = shear; None means that mode carries no traction);
* ``envelope_function = "module:function"``: an ``@njit(cache=True)`` scalar function
  ``f(delta, par) -> sigma`` for the engine's crack loops, where ``par`` is
  ``param_vector(mode)``.  By convention ``par[0]`` is delta_c, so the engine can test
  failure without knowing the law;
* optionally ``envelope_array(delta, par)``: the same envelope vectorised in numpy
  (default: the jitted function applied element by element), ``area_to(delta, mode)``:
  a closed form for W_B(delta) in J/m^2, and closed forms in ``ModeSpec`` for the
  peak and area (found numerically when left out).

The envelope is only the *loading* curve S(delta).  Everything else belongs to the
framework, identically for every law (seed paper, Appendix and Eqs 15-16): history
h = max delta reached, secant unloading to the origin T = S(h)/h * delta, normal
traction only while the crack is open, shear on |delta| with the sign of delta, and
failure once h >= delta_c.  Energies follow from the envelope alone: W_B(delta)
(Eq 8), recoverable W_B^(r)(h) = S(h) h / 2 (linear unloading, the last term of
Eq 16) and dissipated W_B(h) - W_B^(r)(h).
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from pydantic import BaseModel, ConfigDict, field_validator, model_validator
from scipy.integrate import quad
from scipy.optimize import minimize_scalar
from scipy.special import roots_legendre

MPA_MM_TO_J_M2 = 1000.0  # MPa*mm = N/mm = 1 kJ/m^2

MODE_NAMES = {1: "I", 2: "II"}


def mode_number(mode) -> int:
    """1 or 2 from 1, 2, 'I', 'II' (any case), '1' or '2'."""
    key = str(mode).strip().upper()
    if key in ("1", "I"):
        return 1
    if key in ("2", "II"):
        return 2
    raise ValueError(f"traction mode must be I or II (got {mode!r})")


# ---- parameters -------------------------------------------------------------------
class TractionParams(BaseModel):
    """Base of every law's XML parameters.  ``nmix`` is NairnMPM's mixed-mode exponent
    for the debond rule (GI/GIc)^n + (GII/GIIc)^n >= 1; a value <= 0 means a mode
    debonds only at its critical COD.  It is the only parameter allowed to be negative.
    """
    model_config = ConfigDict(extra="forbid")
    nmix: float = 1.0

    @field_validator("*")
    @classmethod
    def _not_negative(cls, v, info):
        # NairnMPM uses negative numbers internally as "not given"; here "not given" is
        # None, so a negative value can only be a mistake.
        if info.field_name != "nmix" and isinstance(v, float) and v < 0:
            raise ValueError(f"must be >= 0 (got {v:g})")
        return v

    def resolve(self, mode: int):
        """The resolved constants of one mode, None when that mode carries no traction;
        raises ValueError on an inconsistent set.  Each law defines it."""
        return None

    @model_validator(mode="after")
    def _modes_consistent(self):
        # every law is checked the same way: both modes must resolve
        self.resolve(1)
        self.resolve(2)
        return self


def given(params: BaseModel, *names: str) -> list[str]:
    """The names among ``names`` that were given (not None) in ``params``."""
    return [n for n in names if getattr(params, n) is not None]


def two_of_three(params: BaseModel, names: tuple[str, str, str], factor: float,
                 required: bool) -> tuple[float, float, float] | None:
    """Complete (sigma MPa, delta_c mm, J J/m^2) from exactly two of the three names
    (in that order) when J = 1000 * factor * sigma * delta_c.

    NairnMPM's rule: exactly two, even when a third given value happens to agree.
    Returns None when none is given and the mode is optional.
    """
    have = given(params, *names)
    if not have and not required:
        return None
    if len(have) != 2:
        got = "none" if not have else ", ".join(have)
        raise ValueError(f"give two of {', '.join(names)} (got {got})")
    for n in have:
        if getattr(params, n) <= 0:
            raise ValueError(f"{n} must be > 0 (got {getattr(params, n):g})")
    sigma, delta_c, J = (getattr(params, n) for n in names)
    if sigma is None:
        sigma = J / (MPA_MM_TO_J_M2 * factor * delta_c)
    elif delta_c is None:
        delta_c = J / (MPA_MM_TO_J_M2 * factor * sigma)
    else:
        J = MPA_MM_TO_J_M2 * factor * sigma * delta_c
    return sigma, delta_c, J


class SigmaDeltaJParams(TractionParams):
    """Per mode, two of the peak stress, critical COD and area, as NairnMPM names them
    (mode II may be left out); ``area_factor`` is J / (sigma delta_c) for the law's
    shape."""
    area_factor: ClassVar[float] = 0.5
    sigmaI: float | None = None   # MPa
    delIc: float | None = None    # mm
    JIc: float | None = None      # J/m^2
    sigmaII: float | None = None
    delIIc: float | None = None
    JIIc: float | None = None

    def resolve(self, mode: int) -> tuple[float, float, float] | None:
        """(sigma MPa, delta_c mm, J J/m^2) of one mode, or None for an absent mode II."""
        m = MODE_NAMES[mode_number(mode)]
        return two_of_three(self, (f"sigma{m}", f"del{m}c", f"J{m}c"), self.area_factor,
                            required=(mode_number(mode) == 1))


# ---- one resolved mode --------------------------------------------------------------
@dataclass(frozen=True)
class ModeSpec:
    """What a plugin computes for one mode from its parameters.  Peak and area may be
    left None to be found numerically from the envelope."""
    delta_c: float                      # mm, failure COD
    par: np.ndarray                     # float64 vector for the envelope; par[0] = delta_c
    peak_stress: float | None = None    # MPa
    peak_delta: float | None = None     # mm
    area: float | None = None           # J/m^2 (J_B)
    breakpoints: tuple[float, ...] = () # mm, kinks of the envelope (help integration)


@dataclass(frozen=True, eq=False)
class ModeEnvelope:
    """A law bound to one mode: a vectorised callable S(delta) with its constants."""
    law: "TractionLaw"
    mode: int
    delta_c: float
    peak_stress: float
    peak_delta: float
    area: float
    par: np.ndarray = field(repr=False)
    breakpoints: tuple[float, ...] = ()

    def __call__(self, delta):
        return self.law.envelope(delta, self.mode)


# ---- the plugin base class ----------------------------------------------------------
class TractionLaw:
    name = "traction law"
    nairn_type: int | None = None
    Params: type[TractionParams] = TractionParams
    envelope_function = ""  # "module:function", @njit f(delta, par) -> sigma

    def __init__(self, params: TractionParams | dict | None = None, label: str = ""):
        if params is None:
            params = {}
        if isinstance(params, dict):
            params = self.Params(**params)
        self.params = params
        self.label = label or self.name
        self._modes: dict[int, ModeEnvelope | None] = {}
        for m in (1, 2):
            spec = self.mode_spec(m)
            self._modes[m] = None if spec is None else self._complete(m, spec)

    @classmethod
    def from_params(cls, label: str = "", **values) -> "TractionLaw":
        """Build from keyword parameters, e.g. ``Cubic.from_params(sigmaI=1, JIc=100)``."""
        return cls(cls.Params(**values), label=label)

    # -- to implement --------------------------------------------------------------
    def mode_spec(self, mode: int) -> ModeSpec | None:  # pragma: no cover - abstract
        raise NotImplementedError

    # -- optional: override with numpy for speed --------------------------------------
    def envelope_array(self, delta: np.ndarray, par: np.ndarray) -> np.ndarray:
        """S(delta) for 0 <= delta < delta_c, vectorised.  Default: the jitted scalar
        function element by element, so a new law need only write that one."""
        f = load_envelope_function(self)
        return np.array([f(float(d), par) for d in np.ravel(delta)]).reshape(np.shape(delta))

    # -- provided -------------------------------------------------------------------
    def has_mode(self, mode) -> bool:
        return self._modes[mode_number(mode)] is not None

    def mode(self, mode) -> ModeEnvelope:
        m = mode_number(mode)
        env = self._modes[m]
        if env is None:
            raise ValueError(f"traction law '{self.label}' ({self.name}) has no mode "
                             f"{MODE_NAMES[m]} tractions")
        return env

    def delta_c(self, mode=1) -> float:
        return self.mode(mode).delta_c

    def peak_stress(self, mode=1) -> float:
        return self.mode(mode).peak_stress

    def peak_delta(self, mode=1) -> float:
        return self.mode(mode).peak_delta

    def area(self, mode=1) -> float:
        """J_B in J/m^2."""
        return self.mode(mode).area

    def param_vector(self, mode=1) -> np.ndarray:
        return self.mode(mode).par

    def envelope(self, delta, mode=1):
        """Loading envelope S(delta) in MPa; zero for delta < 0 and delta >= delta_c
        (the law has failed there)."""
        env = self.mode(mode)
        d = np.asarray(delta, dtype=float)
        inside = (d >= 0) & (d < env.delta_c)
        out = np.zeros(d.shape)
        if np.any(inside):
            out[inside] = self.envelope_array(d[inside], env.par)
        return out if d.ndim else float(out)

    def work_to(self, delta, mode=1):
        return work_to(self, delta, mode)

    def recoverable(self, h, mode=1):
        return recoverable(self, h, mode)

    def dissipated(self, h, mode=1):
        return dissipated(self, h, mode)

    # -- numerical fallbacks ---------------------------------------------------------
    def _complete(self, m: int, spec: ModeSpec) -> ModeEnvelope:
        par = np.ascontiguousarray(spec.par, dtype=np.float64)
        dc = float(spec.delta_c)
        pending = ModeEnvelope(self, m, dc, np.nan, np.nan, np.nan, par, tuple(spec.breakpoints))
        self._modes[m] = pending  # let envelope() work while filling in the rest
        if spec.peak_stress is None or spec.peak_delta is None:
            pk_d, pk_s = _numeric_peak(pending)
        else:
            pk_d, pk_s = spec.peak_delta, spec.peak_stress
        area = spec.area if spec.area is not None else _numeric_area(pending)
        return ModeEnvelope(self, m, dc, float(pk_s), float(pk_d), float(area), par,
                            tuple(spec.breakpoints))


class SigmaDeltaJLaw(TractionLaw):
    """A law fixed by sigma, delta_c and J per mode (``SigmaDeltaJParams``), whose
    envelope takes (delta_c, sigma) and peaks at ``peak_fraction`` * delta_c."""
    peak_fraction: float = 0.0

    def mode_spec(self, mode):
        r = self.params.resolve(mode)
        if r is None:
            return None
        sigma, delta_c, J = r
        return ModeSpec(delta_c=delta_c, par=np.array([delta_c, sigma]), peak_stress=sigma,
                        peak_delta=self.peak_fraction * delta_c, area=J)


def load_envelope_function(law):
    """Import the law's jitted envelope from its ``"module:function"`` string."""
    target = law.envelope_function
    if not target or ":" not in target:
        raise ValueError(f"traction law {law.name} names no envelope_function "
                         f"('module:function')")
    module, func = target.split(":", 1)
    return getattr(importlib.import_module(module), func)


def _numeric_peak(env: ModeEnvelope) -> tuple[float, float]:
    grid = np.linspace(0.0, env.delta_c, 2001)[:-1]
    s = env(grid)
    i = int(np.argmax(s))
    if i == 0:
        return 0.0, float(s[0])
    lo, hi = grid[i - 1], grid[min(i + 1, len(grid) - 1)]
    r = minimize_scalar(lambda d: -env(d), bounds=(lo, hi), method="bounded",
                        options={"xatol": 1e-12 * env.delta_c})
    return (float(r.x), float(-r.fun)) if -r.fun >= s[i] else (float(grid[i]), float(s[i]))


def _numeric_area(env: ModeEnvelope) -> float:
    pts = [p for p in env.breakpoints if 0 < p < env.delta_c] or None
    val, _ = quad(env, 0.0, env.delta_c, points=pts, limit=200, epsabs=0, epsrel=1e-12)
    return MPA_MM_TO_J_M2 * val


# ---- framework: history, unloading, failure -------------------------------------------
def traction_with_history(delta, h, envelope, delta_c: float | None = None, shear: bool = False):
    """Reference (numpy) traction update for one mode, shared by every law.

    ``delta``: current COD (mm); ``h``: history, the largest COD reached so far (mm,
    start at 0); ``envelope``: S(delta) as a callable, e.g. ``law.mode(1)`` (which also
    carries delta_c) or any function with ``delta_c`` given.

    Returns ``(T, h_new, failed)``: traction (MPa), updated history, and whether the law
    has failed (h_new >= delta_c; tractions are then zero for good).  Opening (mode I)
    tractions act only while delta > 0 (closing is the contact algorithm's job); shear
    uses |delta| for damage and the sign of delta for the traction.  Below the history
    the law unloads along the secant to the origin: T = S(h)/h * delta.
    """
    if delta_c is None:
        delta_c = envelope.delta_c
    d = np.asarray(delta, dtype=float)
    hist = np.asarray(h, dtype=float)
    mag = np.abs(d) if shear else d
    loaded = mag > 0
    h_new = np.where(loaded, np.maximum(hist, mag), hist)
    failed = h_new >= delta_c
    live = loaded & ~failed & (h_new > 0)
    safe_h = np.where(live, h_new, 0.5 * delta_c)  # any point inside (0, delta_c)
    secant = np.asarray(envelope(safe_h), dtype=float) / safe_h
    T = np.where(live, secant * d, 0.0)
    if T.ndim == 0:
        return float(T), float(h_new), bool(failed)
    return T, h_new, failed


# ---- framework: energies -------------------------------------------------------------
_GL_X, _GL_W = roots_legendre(8)
_MIN_PANELS = 256


def work_to(law: TractionLaw, delta, mode=1):
    """W_B(delta) = integral of the loading envelope from 0 to delta, in J/m^2 (Eq 8).

    Uses the law's closed form ``area_to(delta, mode)`` when it has one.  Otherwise
    integrates numerically: composite 8-point Gauss-Legendre on panels whose ends include
    every requested delta, the law's kinks and at least 256 equal panels over
    (0, delta_c).  That is exact to round-off for polynomial pieces and converges like
    panel^16 for smooth ones, and all requested values come from one vectorised pass
    (one scipy.quad call per value would be far slower on a fine delta grid).
    """
    if hasattr(law, "area_to"):
        return law.area_to(delta, mode)
    return numeric_work_to(law, delta, mode)


def numeric_work_to(law: TractionLaw, delta, mode=1):
    """W_B(delta) in J/m^2 from the envelope alone (see ``work_to``)."""
    env = law.mode(mode)
    d = np.clip(np.asarray(delta, dtype=float), 0.0, env.delta_c)
    kinks = [p for p in env.breakpoints if 0 < p < env.delta_c]
    knots = np.unique(np.concatenate([
        np.linspace(0.0, env.delta_c, _MIN_PANELS + 1), kinks, d.ravel()]))
    a, b = knots[:-1], knots[1:]
    half = 0.5 * (b - a)
    x = (0.5 * (a + b))[:, None] + half[:, None] * _GL_X[None, :]
    panel = half * (env(x) @ _GL_W)
    cumulative = np.concatenate([[0.0], np.cumsum(panel)])
    out = MPA_MM_TO_J_M2 * cumulative[np.searchsorted(knots, d)]
    return out if out.ndim else float(out)


def recoverable(law: TractionLaw, h, mode=1):
    """W_B^(r)(h) = S(h) h / 2 in J/m^2: the energy given back by linear unloading to the
    origin from history h (zero once failed, h >= delta_c)."""
    hh = np.asarray(h, dtype=float)
    out = 0.5 * MPA_MM_TO_J_M2 * law.envelope(hh, mode) * np.clip(hh, 0.0, None)
    return out if np.ndim(out) else float(out)


def dissipated(law: TractionLaw, h, mode=1):
    """Energy released by the bridging zone up to history h: W_B(h) - W_B^(r)(h), J/m^2."""
    return work_to(law, h, mode) - recoverable(law, h, mode)
