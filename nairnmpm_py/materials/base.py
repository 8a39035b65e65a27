"""What a material plugin provides.

A material plugin is a class with

* ``name`` and optionally ``nairn_type`` (NairnMPM's ``Type`` number);
* ``Params``: a pydantic model of its XML child elements (``<E>``, ``<nu>``, ...);
* ``update_function``: ``"module:function"`` naming an ``@njit`` stress update with the
  signature below, which the engine calls inside its fused particle loop;
* ``param_vector(plane_stress)``: the float64 vector handed to that function;
* ``wave_speed()`` in mm/ms (= m/s), ``rho`` in g/mm^3 (internal units, see README);
* ``n_history``: history variables per particle (initialised by ``initial_history``).

The update signature (all arrays structure-of-arrays, component first)::

    update(ip, dt, L00, L01, L10, L11, F, stress, hist, w, par, plane_stress)

``F[0:5, ip]`` holds the new deformation gradient (F00, F01, F10, F11, F22; the engine
updates the in-plane part, the material owns F22 in plane stress); ``L`` is the velocity
gradient over the step ``dt`` (ms); ``stress[0:4, ip]`` is Cauchy stress (sxx, syy, sxy,
szz) in MPa to update; ``w[ip]`` is strain energy per reference volume (MPa = mJ/mm^3)
to update.
"""
from __future__ import annotations

import numpy as np
from pydantic import BaseModel, ConfigDict


class MaterialParams(BaseModel):
    model_config = ConfigDict(extra="forbid")
    rho: float  # g/cm^3 as NairnMPM reads it
    # fracture properties, used by propagation criteria when the material is a crack tip
    JIc: float | None = None     # J/m^2
    JIIc: float | None = None    # J/m^2
    KIc: float | None = None     # MPa sqrt(m)
    KIIc: float | None = None    # MPa sqrt(m)


class MaterialPlugin:
    name = "material"
    nairn_type: int | None = None
    Params: type[MaterialParams] = MaterialParams
    update_function = ""
    n_history = 0

    def __init__(self, params: MaterialParams, label: str = ""):
        self.params = params
        self.label = label or self.name

    @property
    def rho(self) -> float:
        """Density in g/mm^3 (input is g/cm^3)."""
        return self.params.rho * 1.0e-3

    def wave_speed(self) -> float:  # pragma: no cover - abstract
        raise NotImplementedError

    def param_vector(self, plane_stress: bool) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError

    def shear_and_poisson(self) -> tuple[float, float] | None:
        """Low-strain shear modulus (MPa) and Poisson's ratio, for K from J; None when
        the material has no such constants (K is then not reported)."""
        return None

    def initial_history(self, n: int) -> np.ndarray:
        return np.zeros((self.n_history, n))
