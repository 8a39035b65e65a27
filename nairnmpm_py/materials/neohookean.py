"""Compressible Neo-Hookean hyperelastic material (NairnMPM Type 28).

Kirchhoff stress tau = G (B - I) + lambda g(J) I with g(J) chosen by ``UJOption``
(0: (J^2 - 1)/2, 1: J (J - 1), 2: ln J); Cauchy stress is tau / J.  Stress follows
from the deformation gradient alone, so rigid rotations give exactly no stress; the
material carries its full state in F (its "history").
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydantic import model_validator

from .base import MaterialParams, MaterialPlugin


class NeohookeanParams(MaterialParams):
    G: float | None = None
    K: float | None = None
    Lame: float | None = None
    E: float | None = None
    nu: float | None = None
    alpha: float = 0.0
    UJOption: int = 0

    @model_validator(mode="after")
    def _one_pair(self):
        given = {k for k in ("G", "K", "Lame", "E", "nu") if getattr(self, k) is not None}
        if given not in ({"K", "G"}, {"Lame", "G"}, {"E", "nu"}):
            raise ValueError("give exactly one pair of elastic constants: (K, G), (Lame, G) "
                             f"or (E, nu); got {', '.join(sorted(given)) or 'none'}")
        if self.UJOption not in (0, 1, 2):
            raise ValueError("UJOption must be 0, 1 or 2")
        g, lam = self.moduli()
        if not (g > 0 and lam + 2 * g / 3 > 0):
            raise ValueError(f"moduli give G = {g:g} MPa and K = {lam + 2 * g / 3:g} MPa; "
                             "both must be > 0 (for E, nu: E > 0 and -1 < nu < 0.5)")
        if not self.rho > 0:
            raise ValueError(f"rho must be > 0 (got {self.rho})")
        return self

    def moduli(self) -> tuple[float, float]:
        """(G, Lame lambda) in MPa."""
        if self.E is not None:
            if not (self.E > 0 and -1 < self.nu < 0.5):
                return -1.0, 0.0
            g = self.E / (2 * (1 + self.nu))
            return g, self.E * self.nu / ((1 + self.nu) * (1 - 2 * self.nu))
        g = self.G
        if self.K is not None:
            return g, self.K - 2 * g / 3
        return g, self.Lame


class Neohookean(MaterialPlugin):
    name = "Neohookean"
    nairn_type = 28
    Params = NeohookeanParams
    update_function = "nairnmpm_py.materials.neohookean:update"

    def wave_speed(self) -> float:
        g, lam = self.params.moduli()
        return math.sqrt((lam + 2 * g) / self.rho)

    def shear_and_poisson(self) -> tuple[float, float]:
        g, lam = self.params.moduli()
        return g, lam / (2 * (lam + g))

    def param_vector(self, plane_stress: bool) -> np.ndarray:
        g, lam = self.params.moduli()
        return np.array([g, lam, float(self.params.UJOption)])


@njit(cache=True, inline="always")
def _g_of_j(j, option):
    if option == 0:
        return 0.5 * (j * j - 1.0)
    if option == 1:
        return j * (j - 1.0)
    return math.log(j)


@njit(cache=True, inline="always")
def _u_of_j(j, option):
    if option == 0:
        return 0.5 * (0.5 * (j * j - 1.0) - math.log(j))
    if option == 1:
        return 0.5 * (j - 1.0) * (j - 1.0)
    lj = math.log(j)
    return 0.5 * lj * lj


@njit(cache=True, inline="always", error_model="numpy",
      fastmath={"contract", "reassoc", "nsz", "arcp", "afn"})
def update(ip, dt, L00, L01, L10, L11, F, stress, hist, w, par, plane_stress):
    g = par[0]
    lam = par[1]
    option = int(par[2])
    f00 = F[0, ip]
    f01 = F[1, ip]
    f10 = F[2, ip]
    f11 = F[3, ip]
    j2 = f00 * f11 - f01 * f10
    fzz = 1.0
    if plane_stress:
        # out-of-plane stretch that makes sigma_zz vanish
        if option == 0:
            fzz = math.sqrt((g + 0.5 * lam) / (g + 0.5 * lam * j2 * j2))
        elif option == 1:
            a = g + lam * j2 * j2
            fzz = (lam * j2 + math.sqrt(lam * lam * j2 * j2 + 4.0 * a * g)) / (2.0 * a)
        else:
            fzz = F[4, ip]
            for _ in range(30):
                res = g * (fzz * fzz - 1.0) + lam * math.log(j2 * fzz)
                der = 2.0 * g * fzz + lam / fzz
                step = res / der
                fzz -= step
                if abs(step) < 1e-14:
                    break
        F[4, ip] = fzz
    j = j2 * fzz
    b00 = f00 * f00 + f01 * f01
    b11 = f10 * f10 + f11 * f11
    b01 = f00 * f10 + f01 * f11
    bzz = fzz * fzz
    pterm = lam * _g_of_j(j, option)
    stress[0, ip] = (g * (b00 - 1.0) + pterm) / j
    stress[1, ip] = (g * (b11 - 1.0) + pterm) / j
    stress[2, ip] = g * b01 / j
    stress[3, ip] = 0.0 if plane_stress else (g * (bzz - 1.0) + pterm) / j
    w[ip] = 0.5 * g * (b00 + b11 + bzz - 3.0) - g * math.log(j) + lam * _u_of_j(j, option)
