"""What a propagation-criterion plugin provides.

A criterion is a class with ``name``, ``nairn_type`` (NairnMPM's criterion number)
and ``should_grow(tip, material) -> bool``, where ``tip`` is the crack tip's row of
results (``cracks.csv`` columns: ``J_tip_J_m2``, ``J_ff_J_m2``, ``KI_MPa_sqrt_m``, ...)
and ``material`` the tip material plugin instance, whose parameters carry the
fracture properties (``JIc``, ``JIIc`` in J/m^2, ``KIc``, ``KIIc`` in MPa sqrt(m)).
``critical_J(material)`` gives the J_tip,c the framework uses in R (seed Eq 15).
``row_keys`` names the columns ``should_grow`` reads, when they are all J columns
(``J_contour_J_m2``, ``J_tip_J_m2``, ``J_ff_J_m2``, ``W_B_*``): a check then skips
the rest of the row (K, the notch CODs), which it computes only for a tip that grows.
None (the default) gives every check the whole row.
``growth_threshold(material)`` is a J_tip (J/m^2) below which ``should_grow`` is never
true, or None (the default): with one, the time step watches the tip itself and
Python's full check runs only when J nears it (``cracks.growth_watch``).

The framework owns the rest (NairnMPM's rules, shared notes JINTEGRAL.md section 8):
when to check, the growth direction and length, the new crack particle and the
traction law it gets, and the energy released.
"""
from __future__ import annotations

import math


class PropagationCriterion:
    name = "criterion"
    nairn_type: int | None = None
    row_keys: tuple[str, ...] | None = None

    def should_grow(self, tip: dict, material) -> bool:  # pragma: no cover - abstract
        raise NotImplementedError

    def growth_threshold(self, material) -> float | None:
        """J_tip (J/m^2) below which this criterion never grows the tip, or None."""
        return None

    def critical_J(self, material) -> float:
        """J_tip,c in J/m^2 (NaN when the criterion has none)."""
        return math.nan

    def check(self, material) -> str | None:
        """A message when the tip material lacks what this criterion needs."""
        return None
