"""Triangular traction law (NairnMPM Type 12; seed paper Eq 19, Fig 2C).

S(delta) = k delta up to the peak (delta_pk, sigma), then falls linearly to zero at
delta_c; area J = sigma delta_c / 2.

Parameters per mode, as NairnMPM names them (mode I shown; mode II is sigmaII,
delIIc, JIIc, delpkII, kIIe and may be left out entirely for no shear traction):

* two of ``sigmaI`` (MPa), ``delIc`` (mm), ``JIc`` (J/m^2);
* at most one of ``delpkI`` (peak COD as a fraction of delIc, 0 < delpkI <= 1; 1 is
  elastic-brittle) and ``kIe`` (initial stiffness, MPa/mm; then delta_pk = sigma/kIe).
  With neither, delpkI = 0.225926299, the peak whose W_B(delta) best matches the
  cubic law's in least squares (the paper's 0.2259, Fig 5).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .base import MODE_NAMES, ModeSpec, TractionLaw, TractionParams, given, two_of_three

DEFAULT_RELATIVE_PEAK = 0.225926299


class TriangularParams(TractionParams):
    sigmaI: float | None = None   # MPa
    delIc: float | None = None    # mm
    JIc: float | None = None      # J/m^2
    delpkI: float | None = None   # fraction of delIc
    kIe: float | None = None      # MPa/mm
    sigmaII: float | None = None
    delIIc: float | None = None
    JIIc: float | None = None
    delpkII: float | None = None
    kIIe: float | None = None

    def resolve(self, mode: int):
        return resolve(self, mode)


def resolve(p: TriangularParams, mode: int) -> tuple[float, float, float, float] | None:
    """(sigma MPa, delta_c mm, J J/m^2, delta_pk mm) of one mode, or None for an absent
    mode II.  Raises ValueError on an inconsistent set."""
    m = MODE_NAMES[mode]
    names = (f"sigma{m}", f"del{m}c", f"J{m}c")
    peak_names = (f"delpk{m}", f"k{m}e")
    base = two_of_three(p, names, 0.5, required=(mode == 1))
    if base is None:
        if given(p, *peak_names):
            raise ValueError(f"{' and '.join(given(p, *peak_names))} given but mode {m} has "
                             f"none of {', '.join(names)}")
        return None
    sigma, delta_c, J = base
    rel, k = getattr(p, peak_names[0]), getattr(p, peak_names[1])
    if rel is not None and k is not None:
        raise ValueError(f"give at most one of {peak_names[0]} and {peak_names[1]}")
    if k is not None:
        if k <= 0:
            raise ValueError(f"{peak_names[1]} must be > 0 (got {k:g})")
        delta_pk = sigma / k
        if delta_pk > delta_c:
            raise ValueError(f"peak COD sigma/{peak_names[1]} = {delta_pk:g} mm exceeds "
                             f"del{m}c = {delta_c:g} mm")
    else:
        rel = DEFAULT_RELATIVE_PEAK if rel is None else rel
        if not 0 < rel <= 1:
            raise ValueError(f"{peak_names[0]} is a fraction of del{m}c and must be in "
                             f"(0, 1] (got {rel:g})")
        delta_pk = rel * delta_c
    return sigma, delta_c, J, delta_pk


class Triangular(TractionLaw):
    name = "Triangular"
    nairn_type = 12
    Params = TriangularParams
    envelope_function = "nairnmpm_py.traction.triangular:envelope"

    def mode_spec(self, mode):
        r = resolve(self.params, mode)
        if r is None:
            return None
        sigma, delta_c, J, delta_pk = r
        return ModeSpec(delta_c=delta_c, par=np.array([delta_c, sigma, delta_pk]),
                        peak_stress=sigma, peak_delta=delta_pk, area=J,
                        breakpoints=(delta_pk,))

    def envelope_array(self, delta, par):
        dc, s, dp = par
        rising = s * delta / dp
        if dp >= dc:  # elastic-brittle: no softening branch
            return rising
        return np.where(delta < dp, rising, s * (dc - delta) / (dc - dp))

    def area_to(self, delta, mode=1):
        """Closed-form W_B(delta) in J/m^2."""
        env = self.mode(mode)
        dc, s, dp = env.par
        d = np.clip(np.asarray(delta, dtype=float), 0.0, dc)
        elastic = 0.5 * s * d * d / dp
        if dp < dc:
            soft = 0.5 * s * dp + s * (d - dp) * (2 * dc - d - dp) / (2 * (dc - dp))
            elastic = np.where(d < dp, elastic, soft)
        out = 1000.0 * elastic
        return out if out.ndim else float(out)


@njit(cache=True)
def envelope(delta, par):
    dc = par[0]
    s = par[1]
    dp = par[2]
    if delta < 0.0 or delta >= dc:
        return 0.0
    if delta < dp:
        return s * delta / dp
    return s * (dc - delta) / (dc - dp)
