"""Traction dispatch of the crack-task template when imported directly: a stub.

Scenes with traction laws get a generated dispatcher over their laws' envelopes
instead (see ``core.kernel_build``).
"""
from numba import njit


@njit(cache=True, inline="always")
def traction_envelope(kind, delta, par):
    """No law: no traction."""
    return 0.0
