"""Grid shape functions in one dimension: classic linear and uGIMP.

Each returns the first node index and the weights and derivatives of the nodes it
touches (2 for linear, 3 for uGIMP with a particle half-width ``lp`` up to half a
cell).  Positions are in cell units, so derivatives must be divided by the cell size.
The 2D weights are products of these (tensor-product shape functions).
"""
from __future__ import annotations

import math

from numba import njit

LINEAR = 0
UGIMP = 1


@njit(cache=True, inline="always")
def _ugimp(r, lp):
    """uGIMP weight and d/dx of a node at signed distance r (cell units)."""
    a = abs(r)
    sgn = 1.0 if r >= 0.0 else -1.0
    if a <= lp:
        return 1.0 - (r * r + lp * lp) / (2.0 * lp), -r / lp
    if a <= 1.0 - lp:
        return 1.0 - a, -sgn
    if a < 1.0 + lp:
        d = 1.0 + lp - a
        return d * d / (4.0 * lp), -sgn * d / (2.0 * lp)
    return 0.0, 0.0


@njit(cache=True, inline="always")
def weights_1d(xi, kind, lp):
    """Nodes and weights for a particle at ``xi`` (cell units from the first node).

    Returns (first node, S0, S1, S2, dS0, dS1, dS2); S2 = dS2 = 0 for linear.
    """
    if kind == LINEAR:
        i0 = int(math.floor(xi))
        r = xi - i0
        return i0, 1.0 - r, r, 0.0, -1.0, 1.0, 0.0
    i0 = int(math.floor(xi + 0.5)) - 1
    r = xi - i0
    s0, d0 = _ugimp(r, lp)
    s1, d1 = _ugimp(r - 1.0, lp)
    s2, d2 = _ugimp(r - 2.0, lp)
    return i0, s0, s1, s2, d0, d1, d2
