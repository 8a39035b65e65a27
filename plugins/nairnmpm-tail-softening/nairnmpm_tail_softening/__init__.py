"""A nonlinear softening traction law with a long tail (seed paper Fig 2F).

S(delta) = sigma (1 - delta/delta_c)^n: the full stress at zero opening, then a steep
drop and a long tail (n = 3 by default).  Area J = sigma delta_c / (n + 1).

Parameters per mode: two of ``sigmaI`` (MPa), ``delIc`` (mm), ``JIc`` (J/m^2), and the
exponent ``nI`` (default 3); mode II alike or left out.  Everything else (history,
unloading to the origin, failure at delta_c, W_B, the R curve) comes from nairnmpm_py.
"""
from __future__ import annotations

import numpy as np
from numba import njit
from pydantic import model_validator

from nairnmpm_py.traction.base import (MODE_NAMES, ModeSpec, TractionLaw, TractionParams,
                                       two_of_three)


class TailSofteningParams(TractionParams):
    sigmaI: float | None = None   # MPa
    delIc: float | None = None    # mm
    JIc: float | None = None      # J/m^2
    nI: float = 3.0
    sigmaII: float | None = None
    delIIc: float | None = None
    JIIc: float | None = None
    nII: float = 3.0

    @model_validator(mode="after")
    def _consistent(self):
        for mode in (1, 2):
            if getattr(self, f"n{MODE_NAMES[mode]}") < 1:
                raise ValueError(f"n{MODE_NAMES[mode]} must be >= 1")
            resolve(self, mode)
        return self


def resolve(p: TailSofteningParams, mode: int):
    m = MODE_NAMES[mode]
    n = getattr(p, f"n{m}")
    base = two_of_three(p, (f"sigma{m}", f"del{m}c", f"J{m}c"), 1.0 / (n + 1.0),
                        required=(mode == 1))
    return None if base is None else (*base, n)


class TailSoftening(TractionLaw):
    name = "TailSoftening"
    nairn_type = None
    Params = TailSofteningParams
    envelope_function = "nairnmpm_tail_softening:envelope"

    def mode_spec(self, mode):
        r = resolve(self.params, mode)
        if r is None:
            return None
        sigma, delta_c, J, n = r
        return ModeSpec(delta_c=delta_c, par=np.array([delta_c, sigma, n]),
                        peak_stress=sigma, peak_delta=0.0, area=J)


@njit(cache=True)
def envelope(delta, par):
    dc = par[0]
    if delta < 0.0 or delta >= dc:
        return 0.0
    return par[1] * (1.0 - delta / dc) ** par[2]
