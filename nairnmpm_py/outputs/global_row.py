"""One row of global.csv: energies, each condition's load and displacement, the moments
of load groups and the ``GlobalArchive`` quantities, at the simulation's current time.

The run loop computes it once per global archive time (the ``global_archive`` entry
of ``core/tasks.PERIODIC``) and hands it to every output's ``on_global``.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.integrate import quad

from ..core.conditions import GRID_VELOCITY, evaluate_expression
from .load_couples import couple_moment, couples_opening, load_couples


def prescribed_displacement(rec, t: float) -> float:
    """Displacement (mm) a grid velocity condition record has imposed by time t."""
    if t <= rec.t0:
        return 0.0
    s, v, w = t - rec.t0, rec.value, rec.ftime
    if rec.style == 1:
        return v * s
    if rec.style == 2:
        return 0.5 * v * s * s
    if rec.style == 3:
        return v * (1 - math.cos(w * s)) / w if w else 0.0
    if rec.style == 4:
        return v * math.sin(w * s) / w if w else v * s
    if rec.style == 6:  # (a position-dependent expression is taken at x = y = 0)
        return v * quad(lambda u: evaluate_expression(rec.function, u), 0.0, s, limit=200)[0]
    return 0.0


def global_row(sim) -> dict:
    p = sim.particles
    if sim.couples is None:   # load groups, from the positions at the first row
        sim.couples = load_couples(sim.conditions, p.pos, sim.cracks)
    row = {"time_ms": sim.time, "step": sim.step,
           "kinetic_energy_J": p.kinetic_energy() * 1e-3,
           "strain_energy_J": p.strain_energy() * 1e-3,
           "external_work_J": float(np.sum(sim.rec_work)) * 1e-3}
    cond = sim.conditions
    part_ids = np.array(cond.part_ids, dtype=np.int64)
    part_recs = np.array(cond.part_recs, dtype=np.int64)
    for r, rec in enumerate(cond.records):
        row[f"load_N_{rec.name}"] = float(sim.rec_force[r])
        if rec.kind == GRID_VELOCITY:
            row[f"disp_mm_{rec.name}"] = prescribed_displacement(rec, sim.time)
        else:
            members = part_ids[part_recs == r]
            d = rec.direction
            row[f"disp_mm_{rec.name}"] = (float(np.mean(p.pos[d, members] - p.pos0[d, members]))
                                          if members.size else 0.0)
    for couple in sim.couples:
        row[f"moment_Nmm_{couple.name}"] = couple_moment(couple, cond.records, sim.rec_force,
                                                         p.pos)
    if len(sim.couples) == 2:
        a, b = sim.couples
        row[f"opening_mm_{a.name}_{b.name}"] = couples_opening(a, b, p.pos, p.pos0)
    for q in sim.global_quantities:
        sel = slice(None) if q.material < 0 else (p.mat == q.material)
        m = p.mass[sel]
        axis = 0 if q.kind.endswith("x") else 1
        if q.kind.startswith("vel"):
            value = np.sum(m * p.vel[axis][sel]) / np.sum(m) * 1e3  # mm/s as NairnMPM
        else:
            value = np.sum(m * (p.pos[axis][sel] - p.pos0[axis][sel])) / np.sum(m)
        row[q.column] = float(value)
    return row
