"""The cracks of one simulation: their state, the crack step and the crack results.

``CrackScene`` holds the crack particles (``CrackSet``), the traction laws they use,
the kernel arrays, and computes at archive times what ``cracks.csv`` reports: the
contour J(x) at each crack tip, the traction-loaded zone behind it (tip to notch
root), W_B at the crossing and at the root, and from them J_tip and J_ff by the
seed paper's Eqs 11-13:

* contour crossing inside the zone at x:  J_tip = J(x) - W_B(x),  J_ff = J_tip + W_B(root)
* contour enclosing the whole zone:       J_ff = J(x),           J_tip = J_ff - W_B(root)

W_B(x) is the work the crack-face tractions have done per unit area at x: the area
under the envelope while loading, less what was given back along the linear unloading
to the origin (seed Appendix).  The root particle is the one farthest from the tip in
the unbroken run of traction-carrying particles that starts at (or next to) the tip;
the notch root itself is the edge of that particle's share of crack length, halfway
to the next particle (``root_edge``), where W_B(root) and the root's opening are taken.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..plugins import registry
from .bundle import NR, CrackArrays
from .geometry import EXTERIOR_END, CrackSet
from .growth_watch import raise_edge_maxima
from .jintegral import (N_PER_MM_TO_J_PER_M2, NodalFields, StepAssignment, j_integral,
                        step_nodal_fields, stress_intensity, tip_cod, to_mpa_sqrt_m)

INTACT, ACTIVE, FAILED = 0, 1, 2   # crack-particle traction state (kernel ``cstate``)
NO_MODE = -1.0
WINDOW_REFRESH = 10   # steps between refreshes of the particles near a J window
UNLOAD_SAMPLES = 2000   # openings per law at which the growth watch's W_B >= 0 is tested
BUILTIN = "nairnmpm_py."   # envelope functions of the package's own traction laws
# the cracks.csv columns a lean propagation check computes (``_tip_row(lean=True)``)
J_COLUMNS = {"J_contour_J_m2", "J_tip_J_m2", "J_ff_J_m2", "W_B_crossing_J_m2",
             "W_B_root_J_m2", "W_B_rec_root_J_m2"}


@dataclass
class Tip:
    crack: int          # 0-based crack index
    end: str            # 'start' or 'end'
    material: int       # 0-based material index of the tip (for K); -1 unknown
    criterion: object = None   # propagation-criterion plugin instance, None = no growth
    new_law: int = -1          # traction law (material index) of new crack particles
    grown: int = 0             # growth steps so far
    stopped: str = ""          # why the tip stopped growing for good


@dataclass
class CrackScene:
    cracks: CrackSet
    laws: dict                      # material index -> traction-law plugin instance
    tips: list                      # Tip records that get J
    jcontour_size: int = 2
    contact_position: float | None = None   # ContactPosition (cells) or None
    jcontour_sizes: list = field(default_factory=list)   # extra sizes for jcontours.csv
    propagate_length: float = 0.5                        # cells per growth step
    # the step watches the growing tips (``growth_watch``); False runs Python's full
    # check at every interval (the same results, slower: for comparisons)
    watch_tips: bool = True

    def __post_init__(self):
        cs = self.cracks
        nc = cs.plane.shape[1]
        self.state = np.where(cs.law >= 0, ACTIVE, INTACT).astype(np.int8)
        self.hist = np.zeros((2, nc))
        # largest opening seen at each particle's edges (halfway to the previous and
        # the next particle), where a notch root sits (``root_edge``)
        self.edge_hist = np.zeros((2, nc))
        self.openings = np.zeros(nc)      # normal openings at the last J evaluation
        self.pid = np.arange(nc)          # identity of each crack particle (kept on growth)
        self._kernel_arrays()
        self.counts = np.zeros(4, dtype=np.int64)
        self.initial_tips = {(t.crack, t.end): self._tip_point(t).copy() for t in self.tips}
        self.initial_root = {(t.crack, t.end): int(self.pid[self.zone(t)[1]]) for t in self.tips}
        self.check_steps = 1
        self.growth_log: list[dict] = []
        self.full_checks = 0              # Python's full propagation checks so far
        self._subset = np.zeros(0, dtype=np.int64)   # particles near the J window
        self._subset_window = None
        self._subset_step = 0
        self._unload_ok = None

    # ---- kernel side ---------------------------------------------------------------
    n_rows = NR                      # grid rows per field: the core's and the contact rows

    @property
    def nf(self) -> int:
        """Velocity fields per node: 2 with one crack, NairnMPM's 4 with more."""
        return 2 if self.cracks.n_cracks == 1 else 4

    def envelope_functions(self) -> list[str]:
        """The traction envelopes the crack tasks dispatch over (law table kind = index):
        every built-in law's, then the scene's outside laws'.  Scenes that differ only
        in their laws then share one compiled crack kernel (a crack variant costs a
        minute or more to compile; the envelopes add a few seconds to it)."""
        own = {self.laws[m].envelope_function for m in self.laws}
        builtin = {info.cls.envelope_function for info in registry("traction_laws")
                   if getattr(info.cls, "envelope_function", "").startswith(BUILTIN)}
        return sorted(builtin) + sorted(own - builtin)

    def prepare(self, sim) -> None:
        functions = self.envelope_functions()
        used = sorted(self.laws)
        nlaw = len(sim.materials)
        width = 1 + max([len(self.laws[m].param_vector(1)) for m in used]
                        + [len(self.laws[m].param_vector(2)) for m in used
                           if self.laws[m].has_mode(2)] + [1])
        self.law1 = np.full((nlaw, width), NO_MODE)
        self.law2 = np.full((nlaw, width), NO_MODE)
        for m in used:
            law = self.laws[m]
            for mode, table in ((1, self.law1), (2, self.law2)):
                if law.has_mode(mode):
                    par = law.param_vector(mode)
                    table[m, 0] = functions.index(law.envelope_function)
                    table[m, 1:1 + len(par)] = par
        nn = sim.grid.n_nodes
        n = sim.particles.n
        na = 2 if sim.shape == 0 else 3
        self.vfld = np.zeros((n, na * na), dtype=np.int8)
        self.cut = np.zeros(n, dtype=np.int8)
        self.nslot = np.full((2, nn), -1, dtype=np.int64)
        ncells = (sim.grid.nodes_x - 1) * (sim.grid.nodes_y - 1)
        self.cstart = np.zeros((2, ncells), dtype=np.int64)   # chords of a cell (kernel)
        self.cnear = np.zeros(nn, dtype=np.uint8)   # by stencil origin (``crack_lists``)
        self.cbox = np.array([0, -1, 0, -1], dtype=np.int64)    # cells the lists cover
        self.chunk_counts = np.zeros(sim.nch, dtype=np.int64)
        self.cnodes = np.zeros(nn, dtype=np.int64)             # crack lists (see bundle)
        self.cnodes_old = np.zeros(nn, dtype=np.int64)
        self.nlist = np.zeros(3, dtype=np.int64)
        g = sim.grid
        self.wgeom = np.array([g.xmin, g.ymin, g.dx, g.dy, g.nx, g.ny], dtype=float)
        self.wstep = np.zeros(2, dtype=np.int64)
        self._chord_capacity()
        self._kernel_arrays()
        if self.growing:
            # NairnMPM checks for growth every CFL * cell / wave speed (at least a step)
            prop_time = 0.5 * min(sim.grid.dx, sim.grid.dy) / sim.max_wave_speed()
            self.check_steps = max(1, int(prop_time / sim.dt + 1e-9))

    def _chord_capacity(self) -> None:
        """Room for the chord-cell entries of the crack lists: a chord of up to a cell
        with its padding reaches 9 cells, an exterior end's extended chord a few times
        more, so 64 per crack particle is ample; kept when it already suffices."""
        need = 64 * self.cracks.plane.shape[1] + 1024
        if getattr(self, "chords", None) is None or self.chords.size < need:
            old = getattr(self, "chords", None)
            self.chords = np.zeros(need, dtype=np.int64)
            cxy = np.zeros((need, 4))
            if old is not None:   # the current lists stay valid until the next rebuild
                used = int(self.nlist[0])
                self.chords[:used] = old[:used]
                cxy[:used] = self.cxy[:used]
            self.cxy = cxy

    def _kernel_arrays(self) -> None:
        cs = self.cracks
        self.cfirst = np.ascontiguousarray(cs.first, dtype=np.int64)
        self.clast = np.ascontiguousarray(cs.first + cs.count - 1, dtype=np.int64)
        self.cext0 = np.ascontiguousarray(cs.tips[:, 0] == EXTERIOR_END)
        self.cext1 = np.ascontiguousarray(cs.tips[:, 1] == EXTERIOR_END)
        self.ccrack = np.ascontiguousarray(cs.crack, dtype=np.int64)
        self.cfixed = np.ascontiguousarray(cs.fixed, dtype=np.bool_)
        self.claw = np.ascontiguousarray(cs.law, dtype=np.int64)

    @property
    def growing(self) -> bool:
        return any(t.criterion is not None for t in self.tips)

    def bundle(self, sim) -> CrackArrays:
        """The crack bundle ``K`` of the step tasks, over the current crack arrays."""
        cs = self.cracks
        grid = sim.grid
        return CrackArrays(
            cs.plane, cs.above, cs.below, self.cfirst, self.clast, self.cext0, self.cext1,
            self.ccrack, self.cfixed, self.claw, self.state, self.hist, self.law1, self.law2,
            self.vfld, self.cut, self.nslot, self.cstart, self.cnear, self.cbox, self.chords,
            self.cxy, self.cnodes, self.cnodes_old, self.nlist, self.counts, self.chunk_counts,
            float(grid.thickness), self.contact_position is not None,
            float(self.contact_position or 0.0), grid.nodes_x - 1, grid.nodes_y - 1,
            self.edge_hist, self._openings(), self.watch_table(sim), self.wgeom,
            self._watch_steps(sim))

    def _openings(self) -> np.ndarray:
        if self.openings.size != self.cracks.plane.shape[1]:
            self.openings = np.zeros(self.cracks.plane.shape[1])
        return self.openings

    def _watch_steps(self, sim) -> np.ndarray:
        self.wstep[0] = sim.step
        self.wstep[1] = self.check_steps
        return self.wstep

    def watch_table(self, sim) -> np.ndarray:
        """The tips the step watches (``growth_watch``: crack, end, threshold in N/mm,
        contour size), while ``sim.watch_growth`` (a run) asks for it.  None when a
        growing tip's criterion has no J_tip threshold or a law could make W_B
        negative: Python's full check then runs at every interval."""
        tips = [t for t in self.tips if t.criterion is not None and not t.stopped]
        none = np.zeros((0, 4))
        if (not self.watch_tips or not getattr(sim, "watch_growth", False) or not tips
                or not self._laws_unload_safely()):
            return none
        rows = []
        for t in tips:
            threshold = t.criterion.growth_threshold(sim.materials[t.material])
            if threshold is None or math.isnan(threshold):
                return none
            rows.append((t.crack, 1.0 if t.end == "end" else 0.0,
                         threshold / N_PER_MM_TO_J_PER_M2, self.jcontour_size))
        return np.array(rows, dtype=float)

    def _laws_unload_safely(self) -> bool:
        """W_B >= 0 at every opening, which the growth watch's bound needs: each law's
        envelope is non-negative and its dissipated energy (loading work less the
        linear unloading's return) is too, tested at ``UNLOAD_SAMPLES`` openings up to
        delta_c and at its kinks."""
        if self._unload_ok is None:
            ok = True
            for law in self.laws.values():
                env = law.mode(1)
                h = np.union1d(np.linspace(0.0, law.delta_c(1), UNLOAD_SAMPLES + 1)[1:],
                               [p for p in env.breakpoints if 0.0 < p < law.delta_c(1)])
                tol = 1e-9 * abs(law.area(1))
                ok = ok and bool(np.all(law.envelope(h, 1) >= 0.0)
                                 and np.all(law.dissipated(h, 1) >= -tol))
            self._unload_ok = ok
        return self._unload_ok

    # ---- zone and traction work -------------------------------------------------------
    def _tip_point(self, tip: Tip) -> np.ndarray:
        cs = self.cracks
        k = cs.first[tip.crack] + (0 if tip.end == "start" else cs.count[tip.crack] - 1)
        return cs.plane[:, k]

    def _walk(self, tip: Tip) -> np.ndarray:
        """Crack-particle indices from the tip backwards."""
        cs = self.cracks
        s, n = int(cs.first[tip.crack]), int(cs.count[tip.crack])
        idx = np.arange(s, s + n)
        return idx if tip.end == "start" else idx[::-1]

    def zone(self, tip: Tip) -> tuple[list[int], int]:
        """(crack particles of the traction zone from the tip side, root particle);
        no zone gives ([], tip particle).  The zone is the unbroken run of
        traction-carrying particles that starts at the tip or its neighbour."""
        walk = self._walk(tip)
        active = self.state[walk] == ACTIVE
        start = 0 if active[0] else (1 if walk.size > 1 and active[1] else -1)
        if start < 0:
            return [], int(walk[0])
        ends = np.flatnonzero(~active[start:])
        run = walk[start:start + (int(ends[0]) if ends.size else walk.size - start)]
        return run.tolist(), int(run[-1])

    def traction_work(self, k: int, dn: float | None = None, h: float | None = None) -> float:
        """W_B (J/m^2) done by the tractions of crack particle k so far; ``dn`` and ``h``
        put another opening and largest opening on k's law (its edge, ``root_edge``)."""
        law_index = int(self.cracks.law[k])
        if law_index < 0 or law_index not in self.laws:
            return 0.0
        law = self.laws[law_index]
        if dn is None:
            dn = self.cod_at(k)[0]
        h = max(self.hist[0, k] if h is None else h, dn)
        if self.state[k] == FAILED or h >= law.delta_c(1):
            return float(law.area(1))
        if dn >= h:
            return float(law.work_to(max(dn, 0.0), 1))
        if h <= 0.0:
            return 0.0
        s_h = float(law.envelope(h, 1))
        return float(law.work_to(h, 1)) - 0.5 * s_h * h * 1000.0 * (1.0 - (max(dn, 0.0) / h) ** 2)

    def recoverable_work(self, k: int, dn: float | None = None, h: float | None = None) -> float:
        """W_B^(r) (J/m^2): what linear unloading from the current state gives back."""
        law_index = int(self.cracks.law[k])
        if law_index < 0 or law_index not in self.laws or self.state[k] != ACTIVE:
            return 0.0
        law = self.laws[law_index]
        if dn is None:
            dn = self.cod_at(k)[0]
        h = max(self.hist[0, k] if h is None else h, dn)
        if h <= 0.0 or h >= law.delta_c(1):
            return 0.0
        s_h = float(law.envelope(h, 1))
        d = min(max(dn, 0.0), h)
        return 0.5 * s_h / h * d * d * 1000.0

    def root_edge(self, tip: Tip, k: int) -> tuple[np.ndarray, float, float]:
        """(point, normal opening, largest opening so far) where the traction zone ends
        behind crack particle k: a law particle's force acts over half of each segment
        beside it, so the zone reaches halfway to the next particle away from the tip,
        and the opening there is the mean of the two.  A particle without a law, or the
        last one of its crack, stands for itself.  Uses the openings of the last
        ``update_edge_history`` (the start of every J evaluation)."""
        cs = self.cracks
        c = cs.crack[k]
        dn = self.openings
        side = 0 if tip.end == "end" else 1
        nxt = k - 1 if side == 0 else k + 1
        if int(cs.law[k]) < 0 or not cs.first[c] <= nxt < cs.first[c] + cs.count[c]:
            return cs.plane[:, k].copy(), float(dn[k]), float(self.hist[0, k])
        return (0.5 * (cs.plane[:, k] + cs.plane[:, nxt]), float(0.5 * (dn[k] + dn[nxt])),
                float(self.edge_hist[side, k]))

    def update_edge_history(self) -> None:
        """Raise each particle's edge maxima to the edges' current openings (called at
        every J evaluation: every propagation check while tips grow, else every
        archive)."""
        cs = self.cracks
        raise_edge_maxima(cs.plane, cs.above, cs.below, self.ccrack, self.cfirst, self.clast,
                          self.edge_hist, self._openings())

    def cod_at(self, k: int) -> tuple[float, float]:
        """(normal, tangential) opening (mm) at crack particle k."""
        cs = self.cracks
        c = cs.crack[k]
        s, n = cs.first[c], cs.count[c]
        kp, kn = max(k - 1, s), min(k + 1, s + n - 1)
        t = cs.plane[:, kn] - cs.plane[:, kp]
        t = t / np.hypot(t[0], t[1])
        d = cs.above[:, k] - cs.below[:, k]
        return float(-t[1] * d[0] + t[0] * d[1]), float(t[0] * d[0] + t[1] * d[1])

    # ---- J at the tips ------------------------------------------------------------------
    def tip_results(self, sim, sizes=None, tips=None) -> list[dict]:
        """One dict per tip (per contour size when ``sizes`` is given) with the
        cracks.csv columns."""
        tips = self.tips if tips is None else tips
        sizes = list(sizes or [self.jcontour_size])
        if not tips:
            return []
        fields = self._check_fields(sim, tips, max(sizes))
        rows = []
        for tip in tips:
            for size in sizes:
                rows.append(self._tip_row(sim, fields, tip, int(size)))
        return rows

    def _check_fields(self, sim, tips, size: int) -> NodalFields:
        """What every J evaluation starts with: the edge maxima raised to now, and J's
        nodal fields around these tips for contours up to ``size`` cells."""
        self.update_edge_history()
        return self.j_fields(sim, self._contour_window(sim, tips, size))

    def j_fields(self, sim, window) -> NodalFields:
        """J's nodal fields over ``window`` with the crack sides the time step assigned.
        The step assigns them at the end of every step; when the grid is not current
        (a crack grew at the propagation check just before, or the particles were
        changed) the assignment is for the old cracks, so the particles are
        extrapolated again first, as the next step would do anyway."""
        if not sim.grid_current:
            sim.advance(0, flush=False)
        # the arrays the step's bundles carry, read directly (building the five
        # bundles costs more than this whole call's Python)
        step = StepAssignment(self.vfld, self.cut, self.nslot, sim.g, sim.wij, sim.wc)
        return step_nodal_fields(sim.grid, sim.particles, step, sim.shape, strict=False,
                                 window=window, subset=self._window_particles(sim, window))

    def _contour_window(self, sim, tips, size: int) -> tuple[int, int, int, int]:
        """Real-grid node columns and rows (inclusive) holding the contours of
        half-size up to ``size`` cells around these tips (J needs nodal values on
        its contour only)."""
        g = sim.grid
        i = [math.floor((self._tip_point(t)[0] - g.xmin) / g.dx + 0.5) for t in tips]
        j = [math.floor((self._tip_point(t)[1] - g.ymin) / g.dy + 0.5) for t in tips]
        return min(i) - size, max(i) + size, min(j) - size, max(j) + size

    def _window_particles(self, sim, window) -> np.ndarray:
        """Particles that may reach the nodes of ``window``: found again when the window
        changes or every ``WINDOW_REFRESH`` steps, with a margin of a cell more than
        a particle can reach, which no particle crosses in that many steps (a CFL
        step moves a particle well under a tenth of a cell)."""
        if self._subset_window != window or sim.step - self._subset_step > WINDOW_REFRESH:
            g, p = sim.grid, sim.particles
            i0, i1, j0, j1 = window
            reach = 2.5      # cells: uGIMP reach (1.5) plus a cell of margin
            x, y = p.pos
            keep = ((x >= g.xmin + (i0 - reach) * g.dx) & (x <= g.xmin + (i1 + reach) * g.dx)
                    & (y >= g.ymin + (j0 - reach) * g.dy) & (y <= g.ymin + (j1 + reach) * g.dy))
            self._subset = np.flatnonzero(keep).astype(np.int64)
            self._subset_window = window
            self._subset_step = sim.step
        return self._subset

    def _tip_row(self, sim, fields, tip: Tip, size: int, lean: bool = False) -> dict:
        """The tip's cracks.csv row; ``lean`` leaves out what no J column needs (K and
        the COD at the original notch root stay NaN)."""
        cs = self.cracks
        key = (tip.crack, tip.end)
        xt = self._tip_point(tip)
        zone, root = self.zone(tip)
        root_xy, cod_root, h_root = self.root_edge(tip, root)
        w_root = self.traction_work(root, cod_root, h_root) if zone else 0.0
        w_rec = self.recoverable_work(root, cod_root, h_root) if zone else 0.0
        row = {"time_ms": sim.time, "crack": tip.crack + 1, "tip": tip.end,
               "contour_cells": size,
               "tip_x_mm": float(xt[0]), "tip_y_mm": float(xt[1]),
               "crack_growth_mm": float(np.hypot(*(xt - self.initial_tips[key]))),
               "root_x_mm": float(root_xy[0]), "root_y_mm": float(root_xy[1]),
               "zone_length_mm": float(np.hypot(*(xt - root_xy))) if zone else 0.0,
               "J_contour_J_m2": math.nan, "J_tip_J_m2": math.nan, "J_ff_J_m2": math.nan,
               "W_B_crossing_J_m2": math.nan,
               "W_B_root_J_m2": w_root, "W_B_rec_root_J_m2": w_rec, "R_J_m2": math.nan,
               "cod_root_mm": cod_root,
               "cod_notch0_mm": math.nan if lean else
               self.root_edge(tip, self._index_of(self.initial_root[key]))[1],
               "KI_MPa_sqrt_m": math.nan, "KII_MPa_sqrt_m": math.nan, "event": "archive",
               "error": ""}
        try:
            res = j_integral(sim.grid, fields, cs, tip.crack, tip.end, size)
        except ValueError as exc:
            row["error"] = str(exc)
            return row
        j_x = res.J1 * N_PER_MM_TO_J_PER_M2
        a, b, f = res.crossing_particle, res.crossing_beyond, res.crossing_fraction
        if a in zone or b in zone:          # the contour crosses the traction zone
            w_cross = ((1.0 - f) * (self.traction_work(a) if a in zone else 0.0)
                       + f * (self.traction_work(b) if b in zone else 0.0))
            j_tip = j_x - w_cross
            j_ff = j_tip + w_root
        elif zone and self._beyond_root(tip, a, zone):   # it encloses the whole zone
            w_cross = 0.0
            j_ff = j_x
            j_tip = j_ff - w_root
        else:                               # it crosses between the tip and the zone
            w_cross = 0.0
            j_tip = j_x
            j_ff = j_tip + w_root
        row.update({"J_contour_J_m2": j_x, "J_tip_J_m2": j_tip, "J_ff_J_m2": j_ff,
                    "W_B_crossing_J_m2": w_cross})
        if tip.criterion is not None and tip.grown > 0:
            # Eq 15: the energy released per unit growth
            jc = tip.criterion.critical_J(sim.materials[tip.material])
            row["R_J_m2"] = jc + w_root - w_rec
        if tip.material >= 0 and not lean:
            consts = sim.materials[tip.material].shear_and_poisson()
            if consts is not None:
                dn, dt = tip_cod(cs, tip.crack, tip.end)
                k1, k2 = stress_intensity(j_tip / N_PER_MM_TO_J_PER_M2, dn, dt, consts[0],
                                          consts[1], sim.plane_stress)
                row["KI_MPa_sqrt_m"] = to_mpa_sqrt_m(k1)
                row["KII_MPa_sqrt_m"] = to_mpa_sqrt_m(k2)
        return row

    def _index_of(self, pid: int) -> int:
        return int(np.flatnonzero(self.pid == pid)[0])

    def _beyond_root(self, tip: Tip, k: int, zone: list[int]) -> bool:
        """Is crack particle k farther from the tip than the root (zone[-1])?"""
        return k < zone[-1] if tip.end == "end" else k > zone[-1]

    # ---- propagation ------------------------------------------------------------------
    def propagate(self, sim) -> list[dict]:
        """Check every growing tip once (seed section 4, steps 2-3); grow those whose
        criterion says so by one step.  Returns the cracks.csv rows of the tips that
        grew, taken just before they grew (J_tip at growth, R by Eq 15)."""
        tips = [t for t in self.tips if t.criterion is not None and not t.stopped]
        if not tips:
            return []
        self.full_checks += 1
        # a check runs every step or so: with criteria that read J columns only, the
        # rest of a row is computed for a tip that grows only
        lean = all(t.criterion.row_keys is not None and set(t.criterion.row_keys) <= J_COLUMNS
                   for t in tips)
        size = self.jcontour_size
        fields = self._check_fields(sim, tips, size)
        growing = []
        for tip in tips:
            row = self._tip_row(sim, fields, tip, size, lean=lean)
            if row["error"]:
                continue
            if tip.criterion.should_grow(row, sim.materials[tip.material]):
                growing.append((tip, self._tip_row(sim, fields, tip, size) if lean else row))
        rows = []
        for tip, row in growing:
            material = sim.materials[tip.material]
            tip.grown += 1
            jc = tip.criterion.critical_J(material)
            row["R_J_m2"] = jc + row["W_B_root_J_m2"] - row["W_B_rec_root_J_m2"]
            row["event"] = "growth"
            if self._grow(sim, tip):
                rows.append(row)
        self.growth_log += rows
        return rows

    def _grow(self, sim, tip: Tip) -> bool:
        """Add one crack particle ahead of the tip: PropagateLength cells along the tip
        direction (self-similar growth), with the crack's new-particle traction law,
        zero opening and fresh history.  False (and the tip stops) if it would leave
        the grid."""
        from .jintegral import crack_tip
        cs = self.cracks
        k_tip, _, d = crack_tip(cs, tip.crack, tip.end)
        g = sim.grid
        h = g.dx if abs(d[0]) > abs(d[1]) else g.dy
        new = cs.plane[:, k_tip] + self.propagate_length * h * d
        if not (g.xmin < new[0] < g.xmax and g.ymin < new[1] < g.ymax):
            tip.stopped = "the next crack particle would leave the grid"
            return False
        at = k_tip + 1 if tip.end == "end" else k_tip
        col = new.reshape(2, 1)
        cs.plane = np.ascontiguousarray(np.insert(cs.plane, [at], col, axis=1))
        cs.above = np.ascontiguousarray(np.insert(cs.above, [at], col, axis=1))
        cs.below = np.ascontiguousarray(np.insert(cs.below, [at], col, axis=1))
        cs.crack = np.insert(cs.crack, at, tip.crack)
        cs.law = np.insert(cs.law, at, tip.new_law)
        cs.count[tip.crack] += 1
        cs.first[tip.crack + 1:] += 1
        self.state = np.ascontiguousarray(
            np.insert(self.state, at, ACTIVE if tip.new_law >= 0 else INTACT)).astype(np.int8)
        self.hist = np.ascontiguousarray(np.insert(self.hist, [at], 0.0, axis=1))
        self.edge_hist = np.insert(self.edge_hist, [at], 0.0, axis=1)
        self.pid = np.insert(self.pid, at, self.pid.max() + 1)
        if tip.grown == 1 and tip.new_law >= 0:
            # the notch root of the paper is where the bridging zone starts: the first
            # crack particle grown with a law (the initial tip itself stays traction
            # free, as in NairnMPM)
            self.initial_root[(tip.crack, tip.end)] = int(self.pid[at])
        self._kernel_arrays()
        self._chord_capacity()
        sim.grid_current = False
        return True

    # ---- checkpoints (``core.checkpoint``: the arrays are saved from outside) ---------
    def checkpoint_state(self) -> dict:
        """What a checkpoint needs besides this scene's arrays (JSON-ready)."""
        return {"tips": [{"crack": t.crack, "end": t.end, "grown": t.grown,
                          "stopped": t.stopped} for t in self.tips],
                "initial_root": [[c, end, int(pid)] for (c, end), pid in
                                 self.initial_root.items()],
                "growth_log": self.growth_log, "full_checks": int(self.full_checks)}

    def restore_checkpoint_state(self, state: dict, where: str) -> None:
        for tip, saved in zip(self.tips, state["tips"]):
            if (tip.crack, tip.end) != (saved["crack"], saved["end"]):
                raise ValueError(f"{where}: crack tips differ from the input's")
            tip.grown, tip.stopped = int(saved["grown"]), str(saved["stopped"])
        self.initial_root = {(c, end): pid for c, end, pid in state["initial_root"]}
        self.growth_log = list(state["growth_log"])
        self.full_checks = int(state["full_checks"])
        self._subset_window = None     # found again for the restored particles

    def rcurve_theory(self, sim, points: int = 121) -> list[dict]:
        """For each growing tip whose new crack particles get a traction law: R against
        the opening at the notch root by seed Eq 16 (Eq 22 for the cubic law), the law
        unloading linearly to the origin, from 0 to 1.2 delta_c.  It goes into run.json
        so that ``nairnmpm plot`` can draw it dashed beside the simulated R."""
        from ..analysis.rcurve import R_of_delta
        out = []
        for tip in self.tips:
            if tip.criterion is None or tip.new_law not in self.laws or tip.material < 0:
                continue
            law = self.laws[tip.new_law]
            jc = tip.criterion.critical_J(sim.materials[tip.material])
            if not math.isfinite(jc):
                continue
            delta = np.linspace(0.0, 1.2 * law.delta_c(1), points)
            out.append({"crack": tip.crack + 1, "tip": tip.end, "J_tip_c_J_m2": jc,
                        "J_B_J_m2": float(law.area(1)), "delta_c_mm": float(law.delta_c(1)),
                        "cod_mm": delta.tolist(),
                        "R_J_m2": np.asarray(R_of_delta(law, delta, jc), dtype=float).tolist()})
        return out

    def summary(self) -> dict:
        """Crack counters for run.json."""
        cs = self.cracks
        return {"cracks": int(cs.n_cracks), "crack_particles": int(cs.plane.shape[1]),
                "growth_steps": {f"crack {t.crack + 1} {t.end}": t.grown for t in self.tips},
                "stopped_tips": {f"crack {t.crack + 1} {t.end}": t.stopped
                                 for t in self.tips if t.stopped},
                "failed_traction_particles": int(np.sum(self.state == FAILED)),
                "propagation_check_steps": int(self.check_steps),
                "propagation_full_checks": int(self.full_checks),
                "field_conflicts": int(self.counts[0]),
                "surfaces_without_material": int(self.counts[1]),
                "blocked_crack_moves": int(self.counts[3])}


def propagate(sim) -> list[dict]:
    """The propagation check of ``core/tasks.PERIODIC``: ``CrackScene.propagate``."""
    return sim.cracks.propagate(sim)
