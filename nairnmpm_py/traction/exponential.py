"""Exponential traction law (NairnMPM Type 34, the scaled exponential softening law
Abaqus also offers).

Linear rise to the peak (delta_pk, sigma), then exponential softening that reaches
zero exactly at delta_c:

    S(delta) = sigma [exp(-alpha (delta - delta_pk)/(delta_c - delta_pk)) - e^-alpha]
                     / (1 - e^-alpha)

Area J = sigma delta_c [p + (1 - p) f(alpha)] / 2 with p = delta_pk/delta_c and
f(alpha) = 2 [1/alpha - e^-alpha/(1 - e^-alpha)] (f -> 1, a triangle, as alpha -> 0).

Parameters per mode, as NairnMPM names them (mode II: sigmaII, kIIe, delpkII,
delIIc, JIIc, alphaII, or none of them for no shear): ``alphaI`` (> 0, required);
exactly one of ``JIc`` (J/m^2) and ``delIc`` (mm); exactly two of ``sigmaI`` (MPa),
``kIe`` (initial stiffness, MPa/mm) and ``delpkI`` (peak COD as a fraction of delIc).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .base import MODE_NAMES, ModeSpec, TractionLaw, TractionParams, given


class ExponentialParams(TractionParams):
    sigmaI: float | None = None   # MPa
    kIe: float | None = None      # MPa/mm
    delpkI: float | None = None   # fraction of delIc
    delIc: float | None = None    # mm
    JIc: float | None = None      # J/m^2
    alphaI: float | None = None   # softening rate, > 0
    sigmaII: float | None = None
    kIIe: float | None = None
    delpkII: float | None = None
    delIIc: float | None = None
    JIIc: float | None = None
    alphaII: float | None = None

    def resolve(self, mode: int):
        return resolve(self, mode)


def area_factor(alpha: float) -> float:
    """f(alpha): the softening branch's area relative to a straight line's."""
    e = math.exp(-alpha)
    return 2.0 * (1.0 / alpha - e / (1.0 - e))


def resolve(p: ExponentialParams, mode: int) -> tuple[float, float, float, float, float] | None:
    """(sigma MPa, delta_pk mm, delta_c mm, alpha, J J/m^2) of one mode, or None for an
    absent mode II.  Raises ValueError on an inconsistent set."""
    m = MODE_NAMES[mode]
    n = dict(s=f"sigma{m}", k=f"k{m}e", p=f"delpk{m}", uc=f"del{m}c", J=f"J{m}c", a=f"alpha{m}")
    if not given(p, *n.values()) and mode == 2:
        return None
    v = {key: getattr(p, name) for key, name in n.items()}
    alpha = v["a"]
    if alpha is None or alpha <= 0:
        raise ValueError(f"{n['a']} must be given and > 0")
    ends = given(p, n["uc"], n["J"])
    if len(ends) != 1:
        raise ValueError(f"give exactly one of {n['uc']} and {n['J']} (got {', '.join(ends) or 'none'})")
    shape = given(p, n["s"], n["k"], n["p"])
    if len(shape) != 2:
        raise ValueError(f"give exactly two of {n['s']}, {n['k']}, {n['p']} "
                         f"(got {', '.join(shape) or 'none'})")
    for key in ("s", "k", "p", "uc", "J"):
        if v[key] is not None and v[key] <= 0:
            raise ValueError(f"{n[key]} must be > 0 (got {v[key]:g})")
    fe = area_factor(alpha)
    s, k, rel, uc = v["s"], v["k"], v["p"], v["uc"]
    G = None if v["J"] is None else v["J"] / 1000.0  # MPa*mm
    if uc is not None:
        if rel is None:
            rel = s / (k * uc)
        elif s is None:
            s = k * rel * uc
        G = 0.5 * s * uc * (rel + (1.0 - rel) * fe)
    elif rel is None:           # sigma and k with J
        uc = (2.0 * k * G - (1.0 - fe) * s * s) / (k * s * fe)
        if uc <= 0:
            raise ValueError(f"{n['J']} is too small for this {n['s']} and {n['k']}")
        rel = s / (k * uc)
    elif s is None:             # k and delpk with J
        uc = math.sqrt(2.0 * G / (k * rel * (rel + (1.0 - rel) * fe)))
        s = k * rel * uc
    else:                       # sigma and delpk with J
        uc = 2.0 * G / (s * (rel + (1.0 - rel) * fe))
    if not 0.0 < rel < 1.0:
        raise ValueError(f"the peak must lie inside (0, {n['uc']}): {n['p']} = {rel:.6g}")
    return s, rel * uc, uc, alpha, 1000.0 * G


class Exponential(TractionLaw):
    name = "Exponential"
    nairn_type = 34
    Params = ExponentialParams
    envelope_function = "nairnmpm_py.traction.exponential:envelope"

    def mode_spec(self, mode):
        r = resolve(self.params, mode)
        if r is None:
            return None
        s, upk, uc, alpha, J = r
        return ModeSpec(delta_c=uc, par=np.array([uc, s, upk, alpha]),
                        peak_stress=s, peak_delta=upk, area=J, breakpoints=(upk,))

    def envelope_array(self, delta, par):
        uc, s, upk, alpha = par
        e = math.exp(-alpha)
        soft = s * (np.exp(-alpha * (delta - upk) / (uc - upk)) - e) / (1.0 - e)
        return np.where(delta < upk, s * delta / upk, soft)

    def area_to(self, delta, mode=1):
        """Closed-form W_B(delta) in J/m^2."""
        env = self.mode(mode)
        uc, s, upk, alpha = env.par
        d = np.clip(np.asarray(delta, dtype=float), 0.0, uc)
        e = math.exp(-alpha)
        length = uc - upk
        decayed = np.exp(-alpha * np.clip(d - upk, 0.0, None) / length)
        soft = 0.5 * s * upk + s / (1.0 - e) * (length * (1.0 - decayed) / alpha - e * (d - upk))
        out = 1000.0 * np.where(d < upk, 0.5 * s * d * d / upk, soft)
        return out if out.ndim else float(out)


@njit(cache=True)
def envelope(delta, par):
    uc = par[0]
    s = par[1]
    upk = par[2]
    alpha = par[3]
    if delta < 0.0 or delta >= uc:
        return 0.0
    if delta < upk:
        return s * delta / upk
    e = math.exp(-alpha)
    return s * (math.exp(-alpha * (delta - upk) / (uc - upk)) - e) / (1.0 - e)
