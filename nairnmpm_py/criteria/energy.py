"""Critical energy release rate (NairnMPM criterion 7): the tip grows once the
crack-tip energy release rate J_tip (seed Eq 12, the contour J less the traction work
crossed inside the zone) reaches the tip material's ``JIc`` (J/m^2)."""
from __future__ import annotations

import math

from .base import PropagationCriterion


class CriticalEnergyRelease(PropagationCriterion):
    name = "CriticalERR"
    nairn_type = 7
    row_keys = ("J_tip_J_m2",)

    def critical_J(self, material) -> float:
        v = getattr(material.params, "JIc", None)
        return float(v) if v is not None else math.nan

    def growth_threshold(self, material) -> float:
        return self.critical_J(material)

    def check(self, material):
        if getattr(material.params, "JIc", None) is None:
            return (f"propagation criterion 7 needs <JIc> (J/m^2) in the crack-tip "
                    f"material '{material.label}'")
        return None

    def should_grow(self, tip: dict, material) -> bool:
        j = tip.get("J_tip_J_m2", math.nan)
        return math.isfinite(j) and j >= self.critical_J(material)


class NoPropagation(PropagationCriterion):
    """Criterion 0: the crack does not grow."""
    name = "None"
    nairn_type = 0
    row_keys = ()

    def growth_threshold(self, material) -> float:
        return math.inf

    def should_grow(self, tip: dict, material) -> bool:
        return False
