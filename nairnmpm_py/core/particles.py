"""Material points as structure-of-arrays (component first, particle second)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Particles:
    pos: np.ndarray      # (2, n) mm
    vel: np.ndarray      # (2, n) mm/ms = m/s
    mass: np.ndarray     # (n,) g
    vol0: np.ndarray     # (n,) mm^3 (area times thickness)
    lp: np.ndarray       # (2, n) half-width in cell units (uGIMP)
    mat: np.ndarray      # (n,) int32 index into the scene's materials
    F: np.ndarray        # (5, n) F00 F01 F10 F11 F22
    stress: np.ndarray   # (4, n) Cauchy sxx syy sxy szz, MPa
    hist: np.ndarray     # (k, n) material history
    w: np.ndarray        # (n,) strain energy per reference volume, MPa = mJ/mm^3
    pdamp: np.ndarray    # (n,) particle damping, 1/ms
    pos0: np.ndarray     # (2, n) initial positions (displacements for output)
    thick: np.ndarray | None = None     # (n,) mm, thickness of the particle's body
    per_side: np.ndarray | None = None  # (n,) particles per cell side it was made with

    @classmethod
    def allocate(cls, pos, vel, mass, vol0, lp, mat, n_hist: int, pdamp) -> "Particles":
        n = pos.shape[1]
        F = np.zeros((5, n))
        F[0] = F[3] = F[4] = 1.0
        return cls(pos=np.ascontiguousarray(pos, dtype=float),
                   vel=np.ascontiguousarray(vel, dtype=float),
                   mass=np.ascontiguousarray(mass, dtype=float),
                   vol0=np.ascontiguousarray(vol0, dtype=float),
                   lp=np.ascontiguousarray(lp, dtype=float),
                   mat=np.ascontiguousarray(mat, dtype=np.int32),
                   F=F, stress=np.zeros((4, n)), hist=np.zeros((max(n_hist, 1), n)),
                   w=np.zeros(n), pdamp=np.ascontiguousarray(pdamp, dtype=float),
                   pos0=np.array(pos, dtype=float))

    @property
    def n(self) -> int:
        return self.pos.shape[1]

    def reorder(self, order: np.ndarray) -> None:
        """Permute every particle array (sorting by cell keeps grid access local)."""
        for name in self.__dataclass_fields__:
            a = getattr(self, name)
            if a is None:
                continue
            setattr(self, name, np.ascontiguousarray(a[..., order]))

    def kinetic_energy(self) -> float:
        """mJ (g mm^2/ms^2)."""
        return 0.5 * float(np.sum(self.mass * (self.vel[0] ** 2 + self.vel[1] ** 2)))

    def strain_energy(self) -> float:
        """mJ."""
        return float(np.sum(self.w * self.vol0))
