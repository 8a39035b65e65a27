"""Field choice of a one-field build: there is none.

``step_kernels`` imports ``assign_and_scatter`` from here unless the scene's build
names a multi-field module (a scene with cracks: ``cracks.crack_kernels``).  With one
field ``MULTI_FIELD`` is False and this is never called; it only gives the name a type.
"""
from numba import njit


@njit(cache=True, inline="always")
def assign_and_scatter(P, G, K, buf, p, conflicts):
    return conflicts
