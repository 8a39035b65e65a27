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

from ..errors import SimulationUnstable
from .conditions import GRID_VELOCITY, ConditionRecord, Conditions
from .grid import Grid
from .kernel_build import (condition_functions, load_driver, load_kernels, material_table,
                           task_addresses)
from .particles import Particles
from .profile import StepProfile
from .tasks import periodic_task
from .shape import LINEAR, UGIMP
from .state import (N_ROWS, NO_CRACKS, STATUS_CRACK_LEFT_GRID, STATUS_CRACK_LISTS_FULL,
                    STATUS_TIP_CHECK, ConditionArrays, GridArrays, ParticleArrays, Settings, stress_split)

# below this many particles, thread barriers cost more than threads give (a 200-particle
# bar took 170 s on two busy cores and 0.2 s on one)
PARALLEL_MIN_PARTICLES = 2500
METHOD_NAMES = {0: "USF", 2: "USAVG", 3: "USL"}
SHAPE_NAMES = {LINEAR: "linear", UGIMP: "uGIMP"}
STATUS_TEXT = {1: "a value became NaN or infinite",
               2: "too many particles left the grid (LeaveLimit); the last one was",
               3: "a particle velocity ran away (time step too large for stability?)",
               4: "a crack particle left the grid:",
               5: "a crack's chords reach more cells than its lists hold (a crack stretched "
                  "far beyond its particle spacing?):"}


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
        self.kernels = None         # the scene's step tasks (kernel_build.load_kernels)
        self.driver = None          # the step driver (kernel_build.load_driver)
        self.task_at = None         # the driver's task addresses (kernel_build.task_addresses)
        self._update_stress = True  # the kernels built have the particle update's stress update
        self.profiler = None        # a StepProfile while a run is profiled
        self.grid_current = False   # the grid holds the particles' current extrapolation
        # a run lets the step watch its growing tips (``cracks.growth_watch``): the
        # driver then stops only when a tip may grow (``tip_check_due``)
        self.watch_growth = False
        self.tip_check_due = False
        self.stop_requested = False
        self.wall_before = 0.0     # wall seconds of the parts of a resumed run before this
        self.couples = None    # particle-load groups with a moment column (global row)
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
        envelopes = self.cracks.envelope_functions() if self.cracks is not None else None
        # the particle update updates stresses only in USL- and USAVG-
        self._update_stress = stress_split(self.method, self.post_extrapolate, 1.0)[2] > 0.0
        self.kernels = load_kernels(functions, self.shape, envelopes, self._update_stress,
                                    self.parallel)
        self.driver = load_driver(envelopes is not None)
        self.task_at = None         # compiled at the first step, for the bundles' types
        address, self.fconst = condition_functions(expressions)
        self.faddr = np.array([address], dtype=np.int64)
        self.nch = threads if self.parallel else 1
        nn = g.n_nodes
        nf, rows = (self.cracks.nf, self.cracks.n_rows) if self.cracks else (1, N_ROWS)
        self.g = np.zeros((nf, rows, nn))
        self.gbuf = np.zeros((self.nch, nf, rows, nn))
        self.gv = np.zeros((nf, 2, nn))
        self.ga = np.zeros((nf, 2, nn))
        self.gvn = np.zeros((nf, 2, nn))
        self.gtmp = np.zeros((2, nn))
        self.bad = np.zeros((self.nch, 4), dtype=np.int64)
        self.left = np.zeros(p.n, dtype=np.int8)
        self.wij = np.zeros((p.n, 2), dtype=np.int64)
        self.wc = np.zeros((p.n, 12))
        self.clock = np.zeros(2)       # time, carried USAVG+ / USL+ stress half (state.CLOCK_*)
        self.status = np.zeros(2, dtype=np.int64)
        self.leave_max = self.leave_limit if self.leave_limit > 0 else max(1, p.n // 100)
        self.sym_out, self.sym_in, self.sym_dir = self._symmetry_mirrors()
        self.cond_arrays = self.conditions.arrays()
        npbc = self.cond_arrays["pbc_part"].size
        self.pload = np.zeros(npbc)
        self.pos_before = np.zeros(npbc)
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

    def bundles(self):
        """The state bundles (P, G, C, K, S) the step tasks take, over this scene's
        current arrays (built per call, so arrays replaced from outside are seen)."""
        p = self.particles
        c = self.cond_arrays
        P = ParticleArrays(p.pos, p.pos0, p.vel, p.mass, p.vol0, p.lp, p.mat, p.F, p.stress,
                           p.hist, p.w, p.pdamp, self.left, self.wij, self.wc)
        G = GridArrays(self.geom, self.bounds, self.g, self.gbuf, self.gv, self.ga, self.gvn,
                       self.gtmp, self.bad)
        C = ConditionArrays(c["gbc_node"], c["gbc_dir"], c["gbc_rec"], c["pbc_part"],
                            c["pbc_dir"], c["pbc_scale"], c["pbc_face"], c["pbc_rec"],
                            c["rec_style"], c["rec_value"], c["rec_t0"], c["rec_ftime"],
                            self.rec_force, self.rec_work, self.sym_out, self.sym_in,
                            self.sym_dir, self.pload, self.pos_before, self.fconst,
                            self.faddr)
        K = self.cracks.bundle(self) if self.cracks is not None else NO_CRACKS
        first, last, update, plus = stress_split(self.method, self.post_extrapolate, self.dt)
        if update > 0.0 and not self._update_stress:
            raise RuntimeError("the MPM method changed to USL- / USAVG- after the kernels "
                               "were built without the particle update's stress update")
        S = Settings(float(self.dt), first, last, update, plus, bool(self.plane_stress),
                     float(self.damping), float(self.mass_tol), float(self.vmax),
                     int(self.leave_max), int(self.nch), self.mat_params, self.clock,
                     self.status)
        return P, G, C, K, S

    def advance(self, nsteps: int, flush: bool = True) -> None:
        """Advance ``nsteps`` steps; raises SimulationUnstable if the run blows up.
        ``flush=False`` may leave the last USAVG+ / USL+ stress half for the next call:
        stresses and energies are then half a step behind until it.  Particle arrays
        changed from outside between calls need ``grid_current = False`` first."""
        self.prepare()
        p = self.particles
        # one chunk of a scene with cracks (its crack-plane moves loop in parallel):
        # no thread pool, no barriers (asked only then: the two calls cost about 10 us,
        # a propagation check calls the driver every step; the step's own tasks have no
        # parallel loops on one chunk)
        threads = numba.get_num_threads() if not self.parallel and self.cracks else 0
        if threads:
            numba.set_num_threads(1)
        try:
            self.clock[0] = self.time
            bundles = self.bundles()
            if self.task_at is None:
                self.task_at = task_addresses(self.kernels, self.cracks is not None, bundles)
            if self.profiler is None:
                done = self.driver.advance(*bundles, self.task_at, nsteps, self.grid_current,
                                           flush)
            else:
                done = self.driver.advance_profiled(*bundles, self.task_at, nsteps,
                                                    self.grid_current, flush,
                                                    self.profiler.cycles)
        finally:
            if threads:
                numba.set_num_threads(threads)
        status, bad = int(self.status[0]), int(self.status[1])
        self.tip_check_due = status == STATUS_TIP_CHECK
        if self.tip_check_due:
            status = 0
        self.grid_current = status == 0
        self.step += int(done)
        # the step's own clock, summed dt by dt: adding done * dt here made the time's
        # rounding depend on how the run was cut into driver calls (which follows
        # the wall clock), so time-driven loads were not reproducible to the bit
        self.time = float(self.clock[0])
        if status == STATUS_CRACK_LEFT_GRID:
            cs = self.cracks.cracks
            raise SimulationUnstable(
                f"{STATUS_TEXT[4]} crack {int(cs.crack[bad]) + 1}, crack particle {bad} at "
                f"x = {cs.plane[0, bad]:.6g} mm, y = {cs.plane[1, bad]:.6g} mm",
                self.step, self.time)
        if status == STATUS_CRACK_LISTS_FULL:
            raise SimulationUnstable(f"{STATUS_TEXT[5]} {bad} chord-cell entries",
                                     self.step, self.time)
        if status != 0:
            name = self.material_names[p.mat[bad]] if self.material_names else p.mat[bad]
            where = (f"particle {bad} (material '{name}') at x = {p.pos[0, bad]:.6g} mm, "
                     f"y = {p.pos[1, bad]:.6g} mm")
            raise SimulationUnstable(f"{STATUS_TEXT.get(int(status), 'unstable')}: {where}",
                                     self.step, self.time)

    def run(self, outputs: list | None = None,
            progress: Callable[[float, float, int, float], None] | None = None,
            profile: bool = False, checkpoints=None, resumed: bool = False) -> dict:
        """Run to ``max_time``.  ``progress(fraction, time_ms, step, steps_per_s)``.

        Output plugins get ``begin(sim)``, ``on_global(sim, row)``,
        ``on_archive(sim)`` and ``end(sim, status)``; they are always ended, also
        when the run blows up or is interrupted, so what they wrote stays readable.
        With ``profile`` the returned status (and run.json) gets ``"profile"``: each
        task's time per step and share of the run (``core/profile``).
        ``checkpoints`` (``core.checkpoint.Checkpoints``) writes a checkpoint after
        each archive, at its wall-time interval and when ``request_stop`` was
        called (then the run raises KeyboardInterrupt).  ``resumed``: the state was
        restored from a checkpoint (``core.checkpoint.restore``) and the outputs were
        given ``resume``: the run goes on from there without a first extrapolation
        or first archive.
        """
        outputs = outputs or []
        t_wall = wallclock.perf_counter()
        wall_before = self.wall_before if resumed else 0.0
        self.prepare()
        if not resumed:
            self.grid_current = False   # the particles may have been changed since
        self.profiler = StepProfile(self.cracks is not None) if profile else None
        self.advance(0, flush=False)   # compiles the driver; extrapolates the start
        if self.profiler is not None:
            self.profiler.cycles[:] = 0
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
        # a resumed run's next output times, summed as the first part summed them
        while self.step >= step_at(next_arch):
            next_arch += arch_dt
        while self.step >= step_at(next_glob):
            next_glob += glob_dt
        status = {"exit_status": "running"}
        if not resumed:
            for o in outputs:
                o.begin(self)

        def wall_so_far() -> float:
            return wall_before + wallclock.perf_counter() - t_wall
        try:
            if not resumed:
                self._emit(outputs, archive=True, glob=True)
                if checkpoints is not None:   # a run killed before its next archive resumes
                    checkpoints.write(self, wall_so_far())
            chunk = 20
            start_run = wallclock.perf_counter()
            step0 = self.step
            timed = self.profiler.timed if self.profiler is not None else _untimed
            if self.profiler is not None:
                self.profiler.start()
            scene = self.cracks
            growing = scene is not None and scene.growing
            self.watch_growth = growing
            while self.step < total:
                if self.stop_requested:
                    # between driver calls, after the last call's outputs: the state
                    # and the files agree, so the checkpoint resumes exactly
                    if checkpoints is not None:
                        checkpoints.write(self, wall_so_far())
                    raise KeyboardInterrupt
                target = min(step_at(next_arch), step_at(next_glob), total, self.step + chunk)
                # without a watch on every growing tip, stop at every propagation check
                watched = growing and scene.watch_table(self).shape[0] > 0
                if growing and not watched:
                    target = min(target, (self.step // scene.check_steps + 1) * scene.check_steps)
                target = max(target, self.step + 1)
                t0 = wallclock.perf_counter()
                emits = (target >= total or target >= step_at(next_arch)
                         or target >= step_at(next_glob))
                self.advance(target - self.step, flush=emits)
                if growing and (self.tip_check_due if watched
                                else self.step % scene.check_steps == 0):
                    grown = timed("propagation", periodic_task("propagation"), self)
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
                self._emit(outputs, archive=archive, glob=glob, timed=timed)
                if checkpoints is not None and checkpoints.due(archive):
                    timed("checkpoint", checkpoints.write, self, wall_so_far())
                if progress is not None:
                    el = wallclock.perf_counter() - start_run
                    progress(self.step / total, self.time, self.step, self.step / max(el, 1e-9))
            status = {"exit_status": "done"}
        except SimulationUnstable as exc:
            status = {"exit_status": "unstable", "message": str(exc)}
            raise
        except KeyboardInterrupt:
            status = {"exit_status": "interrupted"}
            if checkpoints is not None and checkpoints.written:
                status["checkpoint_step"] = checkpoints.last_step
            raise
        except OSError as exc:
            status = {"exit_status": "write_failed", "message": str(exc)}
            raise
        finally:
            self.watch_growth = False
            self.stop_requested = False
            status["wall_seconds"] = wall_so_far()
            status["steps"] = self.step
            if checkpoints is not None:
                status["checkpoints"] = {"written": checkpoints.written,
                                         "seconds": checkpoints.seconds}
            if self.profiler is not None and self.profiler.wall0 is not None:
                self.profiler.stop()
                status["profile"] = self.profiler.rows(self.step - step0)
            self.profiler = None
            self._end_outputs(outputs, status)
        return status

    def request_stop(self) -> None:
        """Stop the run at its next return to Python (a fraction of a second), after
        writing a checkpoint if it keeps them (a signal handler may call this)."""
        self.stop_requested = True

    def _end_outputs(self, outputs, status: dict) -> None:
        """Close every output, also when one of them cannot write (a full disk): the
        others still close their files.  The first failure is raised after all, unless
        the run is already stopping for another reason (that one is reported)."""
        failed = None
        for o in outputs:
            try:
                o.end(self, status)
            except OSError as exc:
                failed = failed or exc
        if failed is not None and status.get("exit_status") == "done":
            raise failed

    def _emit(self, outputs, archive: bool, glob: bool, timed=None) -> None:
        timed = timed or _untimed
        if glob:
            timed("global_archive", self._emit_global, outputs)
        if archive:
            timed("archive", self._emit_archive, outputs)

    def _emit_global(self, outputs) -> None:
        row = periodic_task("global_archive")(self)
        for o in outputs:
            o.on_global(self, row)

    def _emit_archive(self, outputs) -> None:
        for o in outputs:
            o.on_archive(self)


def _untimed(name, fn, *args):
    return fn(*args)
