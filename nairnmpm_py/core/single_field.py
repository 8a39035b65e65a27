"""Field choice of a one-field build: there is none.

``step_kernels`` imports ``assign_and_scatter`` and ``field_lists`` from here unless
the scene's build names a multi-field module (a scene with cracks:
``cracks.crack_kernels``).  With one field ``MULTI_FIELD`` is False and neither is
called; they only give the names a type.
"""
from numba import njit


@njit(cache=True)
def field_lists(P, K):
    return 0


@njit(cache=True, inline="always")
def assign_and_scatter(buf, p, r, i0, j0, geom, m, x, y, mvx, mvy, vfld, cut, cnear,
                       crack_lists, conflicts):
    return conflicts
