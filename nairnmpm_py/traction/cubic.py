"""Cubic traction law (NairnMPM Type 14; seed paper Eq 20, Fig 2D).

S(delta) = (27 sigma / 4) x (1 - x)^2 with x = delta/delta_c: peak sigma at
delta_c/3, zero slope at delta_c, area J = 9 sigma delta_c / 16.

Parameters per mode, as NairnMPM names them: two of ``sigmaI`` (MPa), ``delIc`` (mm),
``JIc`` (J/m^2); mode II alike (``sigmaII``, ``delIIc``, ``JIIc``), or none of them for
no shear traction.
"""
from __future__ import annotations

from typing import ClassVar

import numpy as np
from numba import njit

from .base import SigmaDeltaJLaw, SigmaDeltaJParams

AREA_FACTOR = 9.0 / 16.0


class CubicParams(SigmaDeltaJParams):
    area_factor: ClassVar[float] = AREA_FACTOR


class Cubic(SigmaDeltaJLaw):
    name = "Cubic"
    nairn_type = 14
    Params = CubicParams
    envelope_function = "nairnmpm_py.traction.cubic:envelope"
    peak_fraction = 1.0 / 3.0

    def envelope_array(self, delta, par):
        x = delta / par[0]
        return 6.75 * par[1] * x * (1.0 - x) ** 2

    def area_to(self, delta, mode=1):
        """Closed-form W_B(delta) = J x^2 (6 - 8x + 3x^2) in J/m^2."""
        env = self.mode(mode)
        x = np.clip(np.asarray(delta, dtype=float) / env.delta_c, 0.0, 1.0)
        out = env.area * x * x * (6.0 - 8.0 * x + 3.0 * x * x)
        return out if out.ndim else float(out)


@njit(cache=True)
def envelope(delta, par):
    dc = par[0]
    if delta < 0.0 or delta >= dc:
        return 0.0
    x = delta / dc
    return 6.75 * par[1] * x * (1.0 - x) * (1.0 - x)
