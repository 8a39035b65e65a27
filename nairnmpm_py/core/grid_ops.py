"""Per-node grid operations shared by the core tasks and the crack tasks."""
from numba import njit

from .state import GM, GPX, GPY, GFX, GFY


@njit(cache=True, inline="always")
def accelerate_node(g, ga, gvn, f, k, dt, mass_tol):
    """Acceleration and updated velocity of field f at node k from its force."""
    m = g[f, GM, k]
    if m > mass_tol:
        ga[f, 0, k] = g[f, GFX, k] / m
        ga[f, 1, k] = g[f, GFY, k] / m
        gvn[f, 0, k] = (g[f, GPX, k] + g[f, GFX, k] * dt) / m
        gvn[f, 1, k] = (g[f, GPY, k] + g[f, GFY, k] * dt) / m
    else:
        ga[f, 0, k] = 0.0
        ga[f, 1, k] = 0.0
        gvn[f, 0, k] = 0.0
        gvn[f, 1, k] = 0.0
