"""Material dispatch of the ``step_kernels`` template when imported directly: a stub.

Scenes get a generated dispatcher over their materials' update functions instead
(see ``kernel_build``); the core names no concrete material.
"""
from numba import njit


@njit(cache=True, inline="always")
def material_update(m, p, dt, L00, L01, L10, L11, F, stress, hist, w, par, plane_stress):
    """No material: the stress stays as it is."""
    return
