"""A simulation: the scene's arrays, its time-step settings and the run loop.

Build one from an input file (``nairnmpm_py.input.build_simulation``) or from Python
objects for scripted studies.  ``run`` advances the Numba step in chunks between
archive times, hands results to the output plugins and reports progress.
"""
from __future__ import annotations

import math
import time as wallclock
from dataclasses import dataclass, field
from typing import Callable

import numba
import numpy as np
from scipy.integrate import quad

from ..errors import SimulationUnstable
from .conditions import GRID_VELOCITY, ConditionRecord, Conditions, evaluate_expression
from .grid import Grid
from .kernel_build import load_kernels, material_table
from .load_couples import couple_moment, couples_opening, load_couples
from .particles import Particles
from .shape import LINEAR, UGIMP

# below this many particles, thread barriers cost more than threads give (a 200-particle
# bar took 170 s on two busy cores and 0.2 s on one)
PARALLEL_MIN_PARTICLES = 2500
METHOD_NAMES = {0: "USF", 2: "USAVG", 3: "USL"}
SHAPE_NAMES = {LINEAR: "linear", UGIMP: "uGIMP"}
STATUS_TEXT = {1: "a value became NaN or infinite",
               2: "too many particles left the grid (LeaveLimit); the last one was",
               3: "a particle velocity ran away (time step too large for stability?)",
               4: "a crack particle left the grid:"}


@dataclass
class GlobalQuantity:
    """One extra global.csv column (``GlobalArchive type=... mat=...``)."""
    kind: str          # velx vely dispx dispy
    material: int      # material index, -1 for all
    column: str


@dataclass
class Simulation:
    grid: Grid
    particles: Particles
    materials: list            # material plugin instances, index = Particles.mat
    conditions: Conditions
    plane_stress: bool = False
    method: int = 2            # 0 USF, 2 USAVG, 3 USL
    shape: int = UGIMP
    max_time: float = 1.0      # ms
    time_step: float | None = None   # ms; None = CFL limit
    cfl: float = 0.5
    archive_time: float | None = None          # ms; None = start and end only
    archive_start: float = 0.0                 # ms; first regular archive (0 archives too)
    global_archive_time: float | None = None   # ms
    damping: float = 0.0       # grid damping, 1/ms
    post_extrapolate: bool = True   # USL+/USAVG+ (NairnMPM default) or the "-" variant
    leave_limit: int = 0       # distinct particles that may leave (pushed back); 0 = 1%
    parallel: bool | None = None    # threads for the kernels; None = when the scene is big
    global_quantities: list = field(default_factory=list)
    title: str = ""
    source: dict = field(default_factory=dict)   # input path, sha256, parsed text
    material_names: list = field(default_factory=list)
    cracks: object = None      # cracks.scene.CrackScene, or None for a scene without cracks

    def __post_init__(self):
        self.time = 0.0
        self.step = 0
        self.kernels = None
        self.couples = []      # particle-load groups with a moment column (prepare)
        self.rec_force = np.zeros(len(self.conditions.records))
        self.rec_work = np.zeros(len(self.conditions.records))

    # ---- time step -------------------------------------------------------------
    def max_wave_speed(self) -> float:
        used = np.unique(self.particles.mat)
        return max(self.materials[m].wave_speed() for m in used)

    def cfl_time_step(self) -> float:
        """Largest stable step (ms) for the CFL factor: cfl * cell / wave speed."""
        return self.cfl * min(self.grid.dx, self.grid.dy) / self.max_wave_speed()

    @property
    def dt(self) -> float:
        cached = getattr(self, "_dt", None)
        if self.kernels is not None and cached is not None:   # fixed once prepared
            return cached
        return self._uncached_dt()

    def _uncached_dt(self) -> float:
        limit = self.cfl_time_step()
        return min(self.time_step, limit) if self.time_step is not None else limit

    @property
    def n_steps(self) -> int:
        return int(math.ceil(self.max_time / self.dt - 1e-9))

    # ---- results helpers -------------------------------------------------------
    def prescribed_displacement(self, r: int, t: float) -> float:
        """Displacement (mm) a grid velocity condition has imposed by time t."""
        rec = self.conditions.records[r]
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

    def global_row(self) -> dict:
        p = self.particles
        row = {"time_ms": self.time, "step": self.step,
               "kinetic_energy_J": p.kinetic_energy() * 1e-3,
               "strain_energy_J": p.strain_energy() * 1e-3,
               "external_work_J": float(np.sum(self.rec_work)) * 1e-3}
        cond = self.conditions
        part_ids = np.array(cond.part_ids, dtype=np.int64)
        part_recs = np.array(cond.part_recs, dtype=np.int64)
        for r, rec in enumerate(cond.records):
            row[f"load_N_{rec.name}"] = float(self.rec_force[r])
            if rec.kind == GRID_VELOCITY:
                row[f"disp_mm_{rec.name}"] = self.prescribed_displacement(r, self.time)
            else:
                members = part_ids[part_recs == r]
                d = rec.direction
                row[f"disp_mm_{rec.name}"] = float(np.mean(p.pos[d, members] - p.pos0[d, members])) if members.size else 0.0
        for couple in self.couples:
            row[f"moment_Nmm_{couple.name}"] = couple_moment(couple, cond.records,
                                                             self.rec_force, p.pos)
        if len(self.couples) == 2:
            a, b = self.couples
            row[f"opening_mm_{a.name}_{b.name}"] = couples_opening(a, b, p.pos, p.pos0)
        for q in self.global_quantities:
            sel = slice(None) if q.material < 0 else (p.mat == q.material)
            m = p.mass[sel]
            axis = 0 if q.kind.endswith("x") else 1
            if q.kind.startswith("vel"):
                value = np.sum(m * p.vel[axis][sel]) / np.sum(m) * 1e3  # mm/s as NairnMPM
            else:
                value = np.sum(m * (p.pos[axis][sel] - p.pos0[axis][sel])) / np.sum(m)
            row[q.column] = float(value)
        return row

    # ---- running ---------------------------------------------------------------
    def prepare(self) -> None:
        """Sort particles by cell and compile (or load) the kernels."""
        if self.kernels is not None:
            return
        g = self.grid
        p = self.particles
        ci = np.clip(((p.pos[0] - g.xmin) / g.dx).astype(np.int64), 0, g.nx - 1)
        cj = np.clip(((p.pos[1] - g.ymin) / g.dy).astype(np.int64), 0, g.ny - 1)
        order = np.lexsort((ci, cj))
        p.reorder(order)
        new_index = np.empty_like(order)
        new_index[order] = np.arange(order.size)
        self.conditions.renumber_particles(new_index)
        self._add_symmetry_planes()
        functions, self.mat_params = material_table(self.materials, self.plane_stress)
        threads = numba.get_num_threads()
        if self.parallel is None:
            self.parallel = threads > 1 and p.n >= PARALLEL_MIN_PARTICLES
        expressions = {r: rec.function for r, rec in enumerate(self.conditions.records)
                       if rec.style == 6}
        self.kernels = load_kernels(functions, self.shape, expressions)
        self.nch = threads if self.parallel else 1
        nn = g.n_nodes
        self.g = np.zeros((5, nn))
        self.gbuf = np.zeros((self.nch, 5, nn))
        self.gv = np.zeros((2, nn))
        self.ga = np.zeros((2, nn))
        self.gvn = np.zeros((2, nn))
        self.gtmp = np.zeros((2, nn))
        self.bad = np.zeros((self.nch, 4), dtype=np.int64)
        self.left = np.zeros(p.n, dtype=np.int8)
        self.leave_max = self.leave_limit if self.leave_limit > 0 else max(1, p.n // 100)
        self.sym_out, self.sym_in, self.sym_dir = self._symmetry_mirrors()
        self.cond_arrays = self.conditions.arrays()
        self.couples = load_couples(self.conditions, p.pos, self.cracks)
        self.geom = g.geometry_vector()
        self.bounds = g.bounds()
        # any node with mass has a velocity: p/m is accurate even for tiny weights, and
        # zeroing it would put spurious gradients on particles near empty cells
        self.mass_tol = 0.0
        speeds = [self.max_wave_speed(), float(np.max(np.abs(p.vel))) if p.n else 0.0]
        speeds += [abs(r.value) for r in self.conditions.records if r.kind == GRID_VELOCITY]
        self.vmax = 20.0 * max(speeds)
        self._dt = self._uncached_dt()
        if self.cracks is not None:
            self.cracks.prepare(self)

    def _add_symmetry_planes(self) -> None:
        """Zero normal velocity on every node of each symmetry plane (a wall); the
        reaction it records is the force the mirrored half would exert."""
        g = self.grid
        for axis, coord, side in g.symmetry:
            name = f"symmetry_{'x' if axis == 0 else 'y'}{side}"
            if any(r.name == name for r in self.conditions.records):
                continue
            if axis == 0:
                line = int(round((coord - g.xmin) / g.dx))
                others = np.arange(-1, g.ny + 2)
                nodes = g.node_index(np.full(others.size, line), others)
            else:
                line = int(round((coord - g.ymin) / g.dy))
                others = np.arange(-1, g.nx + 2)
                nodes = g.node_index(others, np.full(others.size, line))
            self.conditions.add_grid_velocity(ConditionRecord(name, GRID_VELOCITY, axis, 1, 0.0), nodes)
        self.rec_force = np.zeros(len(self.conditions.records))
        self.rec_work = np.zeros(len(self.conditions.records))

    def _symmetry_mirrors(self):
        """Node pairs (just outside, mirror inside) and normal direction of every
        symmetry plane; the plane's own nodes are velocity conditions."""
        g = self.grid
        out, inside, dirs = [], [], []
        for axis, coord, side in g.symmetry:
            if axis == 0:
                line = int(round((coord - g.xmin) / g.dx))
                others = np.arange(-1, g.ny + 2)
                step = -1 if side == "min" else 1
                out += list(g.node_index(np.full(others.size, line + step), others))
                inside += list(g.node_index(np.full(others.size, line - step), others))
            else:
                line = int(round((coord - g.ymin) / g.dy))
                others = np.arange(-1, g.nx + 2)
                step = -1 if side == "min" else 1
                out += list(g.node_index(others, np.full(others.size, line + step)))
                inside += list(g.node_index(others, np.full(others.size, line - step)))
            dirs += [axis] * others.size
        nn = g.n_nodes
        keep = [(o, i, d) for o, i, d in zip(out, inside, dirs) if 0 <= o < nn and 0 <= i < nn]
        return (np.array([k[0] for k in keep], dtype=np.int64),
                np.array([k[1] for k in keep], dtype=np.int64),
                np.array([k[2] for k in keep], dtype=np.int64))

    def advance(self, nsteps: int, flush: bool = True) -> None:
        """Advance ``nsteps`` steps; raises SimulationUnstable if the run blows up.
        ``flush=False`` (scenes with cracks) may leave the last USAVG+ stress half for
        the next call: stresses and energies are then half a step behind until it."""
        self.prepare()
        p = self.particles
        c = self.cond_arrays
        threads = numba.get_num_threads()
        if not self.parallel:
            numba.set_num_threads(1)  # one chunk: no thread pool, no barriers
        try:
            if self.cracks is not None:
                done, status, bad = self.cracks.advance(self, nsteps, flush)
            else:
                done, status, bad = self.kernels.advance(
                    nsteps, self.time, self.dt, self.method, self.post_extrapolate,
                    self.plane_stress, p.pos, p.vel, p.mass, p.vol0, p.lp, p.mat, p.F,
                    p.stress, p.hist, p.w, p.pdamp, self.mat_params, self.geom, self.bounds,
                    self.g, self.gbuf, self.gv, self.ga, self.gvn, self.gtmp, self.damping,
                    self.mass_tol, self.vmax, self.left, self.leave_max,
                    c["gbc_node"], c["gbc_dir"], c["gbc_rec"], c["pbc_part"], c["pbc_dir"],
                    c["pbc_scale"], c["pbc_face"], c["pbc_rec"], c["rec_style"], c["rec_value"], c["rec_t0"],
                    c["rec_ftime"], self.rec_force, self.rec_work, self.sym_out, self.sym_in,
                    self.sym_dir, self.bad, self.nch)
        finally:
            numba.set_num_threads(threads)
        self.step += int(done)
        self.time += int(done) * self.dt
        if status == 4:
            cs = self.cracks.cracks
            raise SimulationUnstable(
                f"{STATUS_TEXT[4]} crack {int(cs.crack[bad]) + 1}, crack particle {bad} at "
                f"x = {cs.plane[0, bad]:.6g} mm, y = {cs.plane[1, bad]:.6g} mm",
                self.step, self.time)
        if status != 0:
            name = self.material_names[p.mat[bad]] if self.material_names else p.mat[bad]
            where = (f"particle {bad} (material '{name}') at x = {p.pos[0, bad]:.6g} mm, "
                     f"y = {p.pos[1, bad]:.6g} mm")
            raise SimulationUnstable(f"{STATUS_TEXT.get(int(status), 'unstable')}: {where}",
                                     self.step, self.time)

    def run(self, outputs: list | None = None,
            progress: Callable[[float, float, int, float], None] | None = None) -> dict:
        """Run to ``max_time``.  ``progress(fraction, time_ms, step, steps_per_s)``.

        Output plugins get ``begin(sim)``, ``on_global(sim, row)``,
        ``on_archive(sim)`` and ``end(sim, status)``; they are always ended, also
        when the run blows up or is interrupted, so what they wrote stays readable.
        """
        outputs = outputs or []
        t_wall = wallclock.perf_counter()
        self.prepare()
        self.compile_seconds = wallclock.perf_counter() - t_wall
        dt = self.dt
        total = self.n_steps

        def step_at(t_ms: float) -> int:
            """First step ending at or after t_ms (NairnMPM archives then)."""
            return int(math.ceil(t_ms / dt - 1e-9))

        arch_dt = self.archive_time or self.max_time
        glob_dt = self.global_archive_time or arch_dt
        next_arch = max(self.archive_start, arch_dt) if self.archive_start > 0 else arch_dt
        next_glob = glob_dt
        status = {"exit_status": "running"}
        for o in outputs:
            o.begin(self)
        try:
            self._emit(outputs, archive=True, glob=True)
            chunk = 20
            start_run = wallclock.perf_counter()
            scene = self.cracks
            growing = scene is not None and scene.growing
            while self.step < total:
                target = min(step_at(next_arch), step_at(next_glob), total, self.step + chunk)
                if growing:   # stop at every propagation check
                    target = min(target, (self.step // scene.check_steps + 1) * scene.check_steps)
                target = max(target, self.step + 1)
                t0 = wallclock.perf_counter()
                emits = (target >= total or target >= step_at(next_arch)
                         or target >= step_at(next_glob))
                self.advance(target - self.step, flush=emits)
                if growing and self.step % scene.check_steps == 0:
                    grown = scene.propagate(self)
                    if grown:
                        for o in outputs:
                            hook = getattr(o, "on_crack_growth", None)
                            if hook is not None:
                                hook(self, grown)
                spent = wallclock.perf_counter() - t0
                # aim at about 0.2 s between returns to Python (progress, Ctrl-C)
                chunk = int(min(max(chunk * (0.2 / max(spent, 1e-4)), 1), 100000))
                at_end = self.step >= total
                archive = at_end or self.step >= step_at(next_arch)
                glob = at_end or self.step >= step_at(next_glob)
                while self.step >= step_at(next_arch):
                    next_arch += arch_dt
                while self.step >= step_at(next_glob):
                    next_glob += glob_dt
                self._emit(outputs, archive=archive, glob=glob)
                if progress is not None:
                    el = wallclock.perf_counter() - start_run
                    progress(self.step / total, self.time, self.step, self.step / max(el, 1e-9))
            status = {"exit_status": "done"}
        except SimulationUnstable as exc:
            status = {"exit_status": "unstable", "message": str(exc)}
            raise
        except KeyboardInterrupt:
            status = {"exit_status": "interrupted"}
            raise
        finally:
            status["wall_seconds"] = wallclock.perf_counter() - t_wall
            status["steps"] = self.step
            for o in outputs:
                o.end(self, status)
        return status

    def _emit(self, outputs, archive: bool, glob: bool) -> None:
        if glob:
            row = self.global_row()
            for o in outputs:
                o.on_global(self, row)
        if archive:
            for o in outputs:
                o.on_archive(self)
