"""Trilinear traction law (NairnMPM Type 20).

Linear rise to (delta_1, sigma_1), a straight line to a second break point
(delta_2, sigma_2), then linear softening to zero at delta_c.  With delta_1 = delta_2
the stress drops from sigma_1 to sigma_2 at that COD (a bilinear-softening variant).
Area J = [sigma_1 delta_2 + sigma_2 (delta_c - delta_1)] / 2.

Parameters per mode, as NairnMPM names them (mode I shown; mode II is sigmaII,
kIIe, delpkII, sigmaII2, delpkII2, delIIc, JIIc, or none of them for no shear):
``sigmaI`` (sigma_1, MPa), ``kIe`` (initial stiffness, MPa/mm), ``delpkI``
(delta_1/delta_c), ``sigmaI2`` (sigma_2, MPa), ``delpkI2`` (delta_2/delta_c),
``delIc`` (delta_c, mm), ``JIc`` (area, J/m^2).  Give exactly five of the seven; the
sixth of (sigma_1, delta_1, sigma_2, delta_2, delta_c, J) follows from the area.
``kIe`` stands in for one of sigmaI and delpkI (exactly one of them must be given with
it) and then needs delIc.  The result must satisfy 0 < delpkI <= delpkI2 <= 1.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .base import MODE_NAMES, ModeSpec, TractionLaw, TractionParams, given


class TrilinearParams(TractionParams):
    sigmaI: float | None = None    # MPa, first break stress
    kIe: float | None = None       # MPa/mm, initial stiffness
    delpkI: float | None = None    # first break COD / delIc
    sigmaI2: float | None = None   # MPa, second break stress
    delpkI2: float | None = None   # second break COD / delIc
    delIc: float | None = None     # mm
    JIc: float | None = None       # J/m^2
    sigmaII: float | None = None
    kIIe: float | None = None
    delpkII: float | None = None
    sigmaII2: float | None = None
    delpkII2: float | None = None
    delIIc: float | None = None
    JIIc: float | None = None

    def resolve(self, mode: int):
        return resolve(self, mode)


def resolve(p: TrilinearParams, mode: int) -> tuple[float, ...] | None:
    """(s1 MPa, u1 mm, s2 MPa, u2 mm, uc mm, J J/m^2) of one mode, or None for an
    absent mode II.  Raises ValueError on an inconsistent set."""
    m = MODE_NAMES[mode]
    n = dict(s1=f"sigma{m}", k=f"k{m}e", u1=f"delpk{m}", s2=f"sigma{m}2",
             u2=f"delpk{m}2", uc=f"del{m}c", J=f"J{m}c")
    have = given(p, *n.values())
    if not have and mode == 2:
        return None
    if len(have) != 5:
        got = ", ".join(have) or "none"
        raise ValueError(f"give exactly five of {', '.join(n.values())} (got {got})")
    v = {key: getattr(p, name) for key, name in n.items()}
    # Work with relative break CODs and G in MPa*mm, as the area formula is simplest so.
    G = None if v["J"] is None else v["J"] / 1000.0
    s1, u1, s2, u2, uc, k = v["s1"], v["u1"], v["s2"], v["u2"], v["uc"], v["k"]
    if k is not None:
        if k <= 0:
            raise ValueError(f"{n['k']} must be > 0 (got {k:g})")
        if (s1 is None) == (u1 is None):
            raise ValueError(f"with {n['k']} give exactly one of {n['s1']} and {n['u1']}")
        if uc is None:
            raise ValueError(f"with {n['k']} give {n['uc']} too ({n['u1']} is relative to it)")
        if s1 is None:
            s1 = k * u1 * uc
        else:
            u1 = s1 / (k * uc)
    # exactly one of the six is unknown now
    if G is None:
        G = 0.5 * uc * (s1 * u2 + s2 * (1.0 - u1))
    elif s1 is None:
        if u2 <= 0:
            raise ValueError(f"{n['u2']} must be > 0 to find {n['s1']}")
        s1 = (2.0 * G / uc - s2 * (1.0 - u1)) / u2
    elif u2 is None:
        if s1 <= 0:
            raise ValueError(f"{n['s1']} must be > 0 to find {n['u2']}")
        u2 = (2.0 * G / uc - s2 * (1.0 - u1)) / s1
    elif s2 is None:
        s2 = s1 if u1 >= 1.0 else (2.0 * G / uc - s1 * u2) / (1.0 - u1)
    elif u1 is None:
        if s2 <= 0:
            raise ValueError(f"{n['s2']} must be > 0 to find {n['u1']}")
        u1 = 1.0 - (2.0 * G / uc - s1 * u2) / s2
    else:
        denom = s1 * u2 + s2 * (1.0 - u1)
        if denom <= 0:
            raise ValueError(f"the law has zero area; cannot find {n['uc']}")
        uc = 2.0 * G / denom
    if not 0.0 < u1 <= u2 <= 1.0:
        raise ValueError(f"break points must satisfy 0 < {n['u1']} <= {n['u2']} <= 1 "
                         f"(got {u1:.6g}, {u2:.6g})")
    if s1 < 0 or s2 < 0 or max(s1, s2) <= 0 or G <= 0 or uc <= 0:
        raise ValueError(f"the {m} law needs stresses >= 0, a positive peak and positive "
                         f"area (got {n['s1']}={s1:.6g}, {n['s2']}={s2:.6g}, "
                         f"{n['J']}={1000 * G:.6g}, {n['uc']}={uc:.6g})")
    return s1, u1 * uc, s2, u2 * uc, uc, 1000.0 * G


class Trilinear(TractionLaw):
    name = "Trilinear"
    nairn_type = 20
    Params = TrilinearParams
    envelope_function = "nairnmpm_py.traction.trilinear:envelope"

    def mode_spec(self, mode):
        r = resolve(self.params, mode)
        if r is None:
            return None
        s1, u1, s2, u2, uc, J = r
        peak = (u1, s1) if s1 >= s2 else (u2, s2)
        return ModeSpec(delta_c=uc, par=np.array([uc, s1, u1, s2, u2]),
                        peak_stress=peak[1], peak_delta=peak[0], area=J,
                        breakpoints=(u1, u2))

    def envelope_array(self, delta, par):
        uc, s1, u1, s2, u2 = par
        with np.errstate(divide="ignore", invalid="ignore"):
            mid = s1 + (s2 - s1) * (delta - u1) / (u2 - u1) if u2 > u1 else np.full_like(delta, s1)
            tail = s2 * (uc - delta) / (uc - u2) if uc > u2 else np.zeros_like(delta)
        return np.where(delta < u1, s1 * delta / u1, np.where(delta <= u2, mid, tail))

    def area_to(self, delta, mode=1):
        """Closed-form W_B(delta) in J/m^2 (trapezoids under the three lines)."""
        env = self.mode(mode)
        uc, s1, u1, s2, u2 = env.par
        d = np.clip(np.asarray(delta, dtype=float), 0.0, uc)
        S = self.envelope_array(d, env.par)
        rise = 0.5 * s1 * d * d / u1
        mid = 0.5 * s1 * u1 + 0.5 * (s1 + S) * (d - u1)
        tail = 0.5 * s1 * u1 + 0.5 * (s1 + s2) * (u2 - u1) + 0.5 * (s2 + S) * (d - u2)
        out = 1000.0 * np.where(d < u1, rise, np.where(d <= u2, mid, tail))
        return out if out.ndim else float(out)


@njit(cache=True)
def envelope(delta, par):
    uc = par[0]
    s1 = par[1]
    u1 = par[2]
    s2 = par[3]
    u2 = par[4]
    if delta < 0.0 or delta >= uc:
        return 0.0
    if delta < u1:
        return s1 * delta / u1
    if delta <= u2:
        if u2 > u1:
            return s1 + (s2 - s1) * (delta - u1) / (u2 - u1)
        return s1
    return s2 * (uc - delta) / (uc - u2)
