"""Linear softening traction law (seed paper Fig 2E; no NairnMPM type).

S(delta) = sigma (1 - delta/delta_c): the peak sigma is at delta = 0 (infinite initial
stiffness), area J = sigma delta_c / 2.  NairnMPM has no such law: its Type 13
(LinearTraction) is a linear *elastic* traction kIe*delta that never fails, and its
triangular and trilinear laws refuse a zero-width elastic regime.  The law matters for
the theory (Eq 27: Lindhagen and Berglund's R_eff); an engine using it should note the
secant stiffness S(h)/h is unbounded as h -> 0.

Parameters: two of ``sigmaI`` (MPa), ``delIc`` (mm), ``JIc`` (J/m^2); mode II alike
or absent.
"""
from __future__ import annotations

from typing import ClassVar

import numpy as np
from numba import njit

from .base import SigmaDeltaJLaw, SigmaDeltaJParams


class LinearSofteningParams(SigmaDeltaJParams):
    area_factor: ClassVar[float] = 0.5


class LinearSoftening(SigmaDeltaJLaw):
    name = "LinearSoftening"
    nairn_type = None
    Params = LinearSofteningParams
    envelope_function = "nairnmpm_py.traction.linear_softening:envelope"
    peak_fraction = 0.0

    def envelope_array(self, delta, par):
        return par[1] * (1.0 - delta / par[0])

    def area_to(self, delta, mode=1):
        """Closed-form W_B(delta) = J x (2 - x) in J/m^2, x = delta/delta_c."""
        env = self.mode(mode)
        x = np.clip(np.asarray(delta, dtype=float) / env.delta_c, 0.0, 1.0)
        out = env.area * x * (2.0 - x)
        return out if out.ndim else float(out)


@njit(cache=True)
def envelope(delta, par):
    dc = par[0]
    if delta < 0.0 or delta >= dc:
        return 0.0
    return par[1] * (1.0 - delta / dc)
