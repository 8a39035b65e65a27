"""Material dispatch used when ``step_kernels`` is imported directly (isotropic only).

Scenes get a generated dispatcher instead (see ``kernel_build``).
"""
from numba import njit

from nairnmpm_py.materials.isotropic import update as _isotropic


@njit(cache=True, inline="always")
def material_update(m, p, dt, L00, L01, L10, L11, F, stress, hist, w, par, plane_stress):
    _isotropic(p, dt, L00, L01, L10, L11, F, stress, hist, w, par[1:], plane_stress)
