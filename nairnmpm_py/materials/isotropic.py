"""Isotropic linear elastic material (NairnMPM Type 1).

Small-strain increments in a frame that turns with the material spin, so large
rotations of a stiff body (a bending DCB arm) do not create stress.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydantic import field_validator

from .base import MaterialParams, MaterialPlugin


class IsotropicParams(MaterialParams):
    E: float   # MPa
    nu: float
    alpha: float = 0.0  # ppm/K, accepted; no thermal loading yet

    @field_validator("E")
    @classmethod
    def _positive_modulus(cls, v):
        if not v > 0:
            raise ValueError(f"E must be > 0 (got {v})")
        return v

    @field_validator("nu")
    @classmethod
    def _poisson(cls, v):
        if not -1.0 < v < 0.5:
            raise ValueError(f"nu must satisfy -1 < nu < 0.5 (got {v})")
        return v

    @field_validator("rho")
    @classmethod
    def _density(cls, v):
        if not v > 0:
            raise ValueError(f"rho must be > 0 (got {v})")
        return v


class Isotropic(MaterialPlugin):
    name = "Isotropic"
    nairn_type = 1
    Params = IsotropicParams
    update_function = "nairnmpm_py.materials.isotropic:update"

    def wave_speed(self) -> float:
        p = self.params
        g = p.E / (2 * (1 + p.nu))
        lam = p.E * p.nu / ((1 + p.nu) * (1 - 2 * p.nu))
        return math.sqrt((lam + 2 * g) / self.rho)  # mm/ms: MPa / (g/mm^3)

    def shear_and_poisson(self) -> tuple[float, float]:
        p = self.params
        return p.E / (2 * (1 + p.nu)), p.nu

    def param_vector(self, plane_stress: bool) -> np.ndarray:
        p = self.params
        g = p.E / (2 * (1 + p.nu))
        lam = p.E * p.nu / ((1 + p.nu) * (1 - 2 * p.nu))
        if plane_stress:
            c11 = p.E / (1 - p.nu ** 2)
            c12 = p.nu * c11
            czz = 0.0
            ezz = -p.nu / (1 - p.nu)
        else:
            c11, c12, czz, ezz = lam + 2 * g, lam, lam, 0.0
        return np.array([c11, c12, g, czz, ezz])


@njit(cache=True, inline="always", error_model="numpy",
      fastmath={"contract", "reassoc", "nsz", "arcp", "afn"})
def update(ip, dt, L00, L01, L10, L11, F, stress, hist, w, par, plane_stress):
    c11 = par[0]
    c12 = par[1]
    g = par[2]
    czz = par[3]
    ezz_ratio = par[4]
    sxx = stress[0, ip]
    syy = stress[1, ip]
    sxy = stress[2, ip]
    szz = stress[3, ip]
    # rotate the old stress by the increment of spin (objective in 2D)
    ang = 0.5 * (L10 - L01) * dt
    if abs(ang) < 1e-3:
        # series exact to rounding for the tiny angles of a stable step (faster than libm)
        a2 = ang * ang
        c = 1.0 - a2 * (0.5 - a2 * (1.0 / 24.0 - a2 * (1.0 / 720.0)))
        s = ang * (1.0 - a2 * (1.0 / 6.0 - a2 * (1.0 / 120.0 - a2 * (1.0 / 5040.0))))
    else:
        c = math.cos(ang)
        s = math.sin(ang)
    rxx = c * c * sxx - 2.0 * c * s * sxy + s * s * syy
    ryy = s * s * sxx + 2.0 * c * s * sxy + c * c * syy
    rxy = c * s * (sxx - syy) + (c * c - s * s) * sxy
    dexx = L00 * dt
    deyy = L11 * dt
    dgxy = (L01 + L10) * dt
    nxx = rxx + c11 * dexx + c12 * deyy
    nyy = ryy + c12 * dexx + c11 * deyy
    nxy = rxy + g * dgxy
    nzz = szz + czz * (dexx + deyy)
    dezz = ezz_ratio * (dexx + deyy)
    if plane_stress:
        F[4, ip] *= 1.0 + dezz
    stress[0, ip] = nxx
    stress[1, ip] = nyy
    stress[2, ip] = nxy
    stress[3, ip] = nzz
    jac = (F[0, ip] * F[3, ip] - F[1, ip] * F[2, ip]) * F[4, ip]
    w[ip] += jac * 0.5 * ((rxx + nxx) * dexx + (ryy + nyy) * deyy + (rxy + nxy) * dgxy
                          + (szz + nzz) * dezz)
