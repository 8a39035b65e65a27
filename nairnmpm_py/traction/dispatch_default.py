"""Traction dispatch used when ``crack_step_kernels`` is imported directly (cubic only).

Scenes with traction laws get a generated dispatcher over their laws' envelopes
instead (see ``core.kernel_build``).
"""
from numba import njit

from nairnmpm_py.traction.cubic import envelope as _cubic


@njit(cache=True, inline="always")
def traction_envelope(kind, delta, par):
    return _cubic(delta, par)
