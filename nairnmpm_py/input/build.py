"""Input model -> Simulation: grid, particles, materials, boundary conditions.

Conversions to the engine's units (mm, g, ms; so N, MPa and mJ) happen here:
velocities mm/s -> mm/ms, densities g/cm^3 -> g/mm^3, damping 1/s -> 1/ms.
"""
from __future__ import annotations

import math
import os
import re

import numpy as np

from .. import plugins
from ..core.conditions import GRID_VELOCITY, PARTICLE_LOAD, ConditionRecord, Conditions
from ..core.grid import Grid
from ..core.particles import Particles
from ..core.shape import LINEAR, UGIMP
from ..core.simulation import GlobalQuantity, Simulation
from .models import AxisModel, BodyModel, ConditionModel, InputModel, ShapeModel
from .reader import read_input
from .xmlread import Reader

PER_S_TO_PER_MS = 1e-3
MM_PER_S_TO_MM_PER_MS = 1e-3


def load_simulation(path) -> Simulation:
    """Read, validate and build the simulation an input file describes."""
    return build_simulation(read_input(path))


def build_simulation(model: InputModel) -> Simulation:
    r = Reader(model.path)
    grid = _grid(r, model)
    r.check()
    _check_size(r, model, grid)
    r.check()
    _check_cracks(r, model, grid)
    r.check()
    materials, names = [], []
    for m in model.materials:
        info = plugins.resolve(m.group, m.plugin)
        if m.group == "materials":
            materials.append(info.cls(info.cls.Params(**m.params), label=m.name))
        else:  # traction laws live on cracks; their slot keeps NairnMPM's numbering
            materials.append(info.cls(info.cls.Params(**m.params)))
        names.append(m.name)
    particles = _particles(r, model, grid, materials, names)
    r.check()
    conditions = _conditions(r, model, grid, particles)
    quantities = _global_quantities(r, model, names)
    cracks = _crack_scene(r, model, materials, names)
    r.check()
    h = model.mpm
    sim = Simulation(
        grid=grid, particles=particles, materials=materials, conditions=conditions,
        plane_stress=model.analysis == 11, method=h.method,
        post_extrapolate=h.post_extrapolate, leave_limit=h.leave_limit,
        shape=UGIMP if h.shape == "uGIMP" else LINEAR, max_time=h.max_time_ms,
        time_step=h.time_step_ms, cfl=h.cfl, archive_time=h.archive_time_ms,
        archive_start=h.archive_start_ms,
        global_archive_time=h.global_archive_time_ms,
        damping=h.damping_per_s * PER_S_TO_PER_MS, global_quantities=quantities,
        title=model.title, source={"path": model.path, "sha256": model.sha256, "text": model.text},
        material_names=names, cracks=cracks)
    _check_steps(r, sim, h.max_time_line)
    r.check()
    return sim


MAX_STEPS = 10 ** 12   # about 30 years of this machine at a microsecond per step


def _check_steps(r: Reader, sim: Simulation, line: int | None) -> None:
    """A run of more steps than any machine finishes (a MaxTime in the wrong units, or
    a modulus that makes the time step vanish) is refused before it starts."""
    steps = sim.max_time / sim.dt if sim.dt > 0 else math.inf
    if not (math.isfinite(steps) and steps <= MAX_STEPS):
        r.problem(_at(line), f"MaxTime {sim.max_time:g} ms at a time step of {sim.dt:g} ms "
                             f"is {steps:.3g} steps (at most {MAX_STEPS:.0e})")


# ---- grid -----------------------------------------------------------------------
MAX_CELLS = 10 ** 15      # cells along an axis counted before the memory check refuses them


def _axis(lo: float, hi: float, axis: AxisModel) -> tuple[float, int]:
    """Cells along one axis; a cell size that does not divide the length extends the
    upper limit by one cell, as NairnMPM does."""
    if axis.cellsize is not None:
        cs = axis.cellsize
        if not (hi - lo) / cs < MAX_CELLS:
            # an absurd count is refused by its memory (``_check_size``), not here
            return hi, MAX_CELLS
        n = int(math.floor((hi - lo) / cs + 1e-9))
        if n == 0 or lo + n * cs < hi - 1e-9 * cs:
            n += 1
        return lo + n * cs, n
    return hi, axis.n


def _grid(r: Reader, model: InputModel) -> Grid:
    gm = model.grid
    xmax, nx = _axis(gm.xmin, gm.xmax, gm.horiz)
    ymax, ny = _axis(gm.ymin, gm.ymax, gm.vert)
    grid = Grid(gm.xmin, xmax, gm.ymin, ymax, nx, ny, thickness=gm.thickness)
    for axis, am, lo, h in ((0, gm.horiz, gm.xmin, grid.dx), (1, gm.vert, gm.ymin, grid.dy)):
        for side, v in (("min", am.symmin), ("max", am.symmax)):
            if v is None:
                continue
            k = (v - lo) / h
            n_cells = nx if axis == 0 else ny
            if abs(k - round(k)) > 1e-3 or not 0 <= round(k) <= n_cells:
                r.problem(_at(am.line), f"sym{side}={v} is not on a grid line inside the grid")
                continue
            grid.symmetry.append((axis, lo + round(k) * h, side))
    return grid


class _at:
    def __init__(self, line):
        self.sourceline = line


# Rough memory per particle and per grid node, in bytes: the particle arrays and their
# copies (outputs, J), the grid rows of up to four velocity fields per node with one
# buffer per thread, and the candidate points particles are cut from (every cell of
# the grid, points_per_cell of them).  Measured runs stay well under these.
BYTES_PER_PARTICLE = 1000
BYTES_PER_NODE = 1000
BYTES_PER_CANDIDATE = 24


def _machine_memory() -> int | None:
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        return None


def _check_size(r: Reader, model: InputModel, grid: Grid) -> None:
    """Refuse, before anything is allocated, a resolution this machine cannot hold."""
    have = _machine_memory()
    if have is None:
        return
    ppc = max([b.points_per_cell or model.mpm.points_per_cell for b in model.bodies]
              + [model.mpm.points_per_cell])
    particles = 0.0
    for body in model.bodies:
        if not body.hole:
            for shape in body.shapes:
                x0, x1, y0, y1 = _bbox(shape)
                # per axis: a cell area can underflow to 0
                particles += (x1 - x0) / grid.dx * ((y1 - y0) / grid.dy) * ppc
    particles = min(particles, grid.n_cells * ppc)
    need = (particles * BYTES_PER_PARTICLE + grid.n_nodes * BYTES_PER_NODE
            + grid.n_cells * ppc * BYTES_PER_CANDIDATE)
    if need > have:
        r.problem(_at(model.grid.line),
                  f"the grid has {grid.n_cells:.3g} cells ({grid.dx:g} x {grid.dy:g} mm) and "
                  f"the bodies about {particles:.3g} particles: about {need / 2**30:.3g} GiB, "
                  f"more than this machine's {have / 2**30:.3g} GiB of memory; use larger cells")


# ---- cracks -------------------------------------------------------------------------
def _check_cracks(r: Reader, model: InputModel, grid: Grid) -> None:
    if not model.cracks:
        return
    from ..cracks.geometry import polyline_problems   # only scenes with cracks
    cell = min(grid.dx, grid.dy)
    for crack in model.cracks:
        pts = np.array([(p.x, p.y) for p in crack.points])
        for msg in polyline_problems(pts, (grid.xmin, grid.xmax), (grid.ymin, grid.ymax), cell):
            r.problem(_at(crack.line), f"<CrackList>: {msg}")


def _crack_material(r: Reader, model: InputModel, names: list, number, name, where,
                    group: str, what: str):
    """0-based index of the material a crack names by number or name, checked to be
    of the expected plugin group; None when none is named or it is wrong."""
    if (number is None or number <= 0) and not name:
        return None   # NairnMPM: a number <= 0 (or an empty name) means none
    if name is not None:
        if name not in names:
            r.problem(_at(where), f"{what}: no material named '{name}'")
            return None
        idx = names.index(name)
    else:
        if not 1 <= number <= len(model.materials):
            r.problem(_at(where), f"{what}: material {number} does not exist "
                                  f"({len(model.materials)} defined)")
            return None
        idx = number - 1
    if model.materials[idx].group != group:
        kind = "a traction law" if group == "traction_laws" else "a solid material"
        r.problem(_at(where), f"{what}: material {idx + 1} ('{names[idx]}') is not {kind}")
        return None
    return idx


def _tip_propagation(r: Reader, model: InputModel, materials: list, names: list, tip,
                     tprop, used: dict, line) -> None:
    """The tip's propagation criterion, direction and new-particle traction law: the
    tip material's <Propagate> if it has one, else the first <Cracks><Propagate>; the
    crack's Tprop overrides the criterion's traction law (NairnMPM's rules)."""
    mm = model.materials[tip.material]
    header = model.mpm.cracks
    if mm.propagate is not None:
        criterion, direction, traction, where = mm.propagate
    elif header is not None and header.propagate:
        criterion, direction, traction, where = header.propagate[0]
    else:
        return
    where = where or line
    info = plugins.resolve("propagation", criterion)
    if info is None:
        known = ", ".join(f"{p.name} ({p.nairn_type})" for p in plugins.registry("propagation"))
        r.problem(_at(where), f"<Propagate criterion=\"{criterion}\">: no propagation criterion "
                              f"of that number (installed: {known})")
        return
    if info.nairn_type == 0:
        return
    if direction not in (0, 1):
        r.problem(_at(where), f"<Propagate direction=\"{direction}\">: only 0 and 1 (straight "
                              "ahead, along the crack-tip direction) are supported")
        return
    crit = info.cls()
    missing = crit.check(materials[tip.material])
    if missing:
        r.problem(_at(where), missing)
        return
    law = tprop
    if law is None and traction and traction > 0:
        law = _crack_material(r, model, names, traction, None, where, "traction_laws",
                              "<Propagate traction>")
    if law is not None:
        used[law] = materials[law]
    tip.criterion = crit
    tip.new_law = -1 if law is None else law


def _crack_scene(r: Reader, model: InputModel, materials: list, names: list):
    """The scene's cracks (None without any): crack particles, their traction laws
    and the tips that get J."""
    if not model.cracks:
        return None
    from ..cracks.geometry import CrackSet   # only scenes with cracks load crack modules
    from ..cracks.scene import CrackScene, Tip
    polylines, laws, tips, fixed, tip_list, used = [], [], [], [], [], {}
    for c, crack in enumerate(model.cracks):
        polylines.append(np.array([(p.x, p.y) for p in crack.points]))
        law_of = []
        for p in crack.points:
            idx = _crack_material(r, model, names, p.law, p.lawname, p.line or crack.line,
                                  "traction_laws", "crack mat")
            law_of.append(-1 if idx is None else idx)
            if idx is not None:
                used[idx] = materials[idx]
        laws.append(np.array(law_of, dtype=np.int64))
        ends = (crack.points[0].tip, crack.points[-1].tip)
        tips.append(ends)
        fixed.append(crack.fixed)
        tprop = _crack_material(r, model, names, crack.tprop, crack.tpropname, crack.line,
                                "traction_laws", "<CrackList> Tprop")
        if tprop is not None:
            used[tprop] = materials[tprop]
        for end, code, p in (("start", ends[0], crack.points[0]), ("end", ends[1], crack.points[-1])):
            if code > 0:
                idx = _crack_material(r, model, names, code, None, p.line or crack.line,
                                      "materials", "crack tip material")
                tip = Tip(c, end, -1 if idx is None else idx)
                if idx is not None:
                    _tip_propagation(r, model, materials, names, tip, tprop, used,
                                     p.line or crack.line)
                tip_list.append(tip)
    h = model.mpm.cracks
    return CrackScene(CrackSet.from_polylines(polylines, laws, tips, fixed), used, tip_list,
                      jcontour_size=h.jcontour_size if h else 2,
                      contact_position=h.contact_position if h else None,
                      jcontour_sizes=list(h.jcontour_sizes) if h else [],
                      propagate_length=h.propagate_length if h else 0.5)


# ---- particles ----------------------------------------------------------------------
def _contains(shape: ShapeModel, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    if shape.kind == "Rect":
        inside = (x >= shape.xmin) & (x <= shape.xmax) & (y >= shape.ymin) & (y <= shape.ymax)
    elif shape.kind == "Oval":
        a = 0.5 * (shape.xmax - shape.xmin)
        b = 0.5 * (shape.ymax - shape.ymin)
        xc = 0.5 * (shape.xmax + shape.xmin)
        yc = 0.5 * (shape.ymax + shape.ymin)
        inside = ((x - xc) / a) ** 2 + ((y - yc) / b) ** 2 <= 1.0
    else:
        inside = _in_polygon(np.array(shape.points), x, y)
    for cut in shape.cutouts:
        inside &= ~_contains(cut, x, y)
    return inside


def _in_polygon(pts: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Crossing-number test; points on an edge count as inside."""
    inside = np.zeros(x.shape, dtype=bool)
    on_edge = np.zeros(x.shape, dtype=bool)
    n = len(pts)
    for i in range(n):
        x1, y1 = pts[i]
        x2, y2 = pts[(i + 1) % n]
        crosses = (y1 > y) != (y2 > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            xint = x1 + (y - y1) * (x2 - x1) / (y2 - y1)
        inside ^= crosses & (x < xint)
        seg = np.hypot(x2 - x1, y2 - y1)
        cross = (x2 - x1) * (y - y1) - (y2 - y1) * (x - x1)
        dot = (x - x1) * (x2 - x1) + (y - y1) * (y2 - y1)
        on_edge |= (np.abs(cross) <= 1e-9 * max(seg, 1e-300) * max(seg, 1.0)) & (dot >= 0) & (dot <= seg * seg)
    return inside | on_edge


def _bbox(shape: ShapeModel) -> tuple[float, float, float, float]:
    if shape.kind == "Polygon":
        p = np.array(shape.points)
        return p[:, 0].min(), p[:, 0].max(), p[:, 1].min(), p[:, 1].max()
    return shape.xmin, shape.xmax, shape.ymin, shape.ymax


def _candidates(grid: Grid, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Cell-centred sub-cell points, n per side in every cell."""
    sub = (np.arange(n) + 0.5) / n
    xs = (grid.xmin + (np.arange(grid.nx)[:, None] + sub[None, :]) * grid.dx).ravel()
    ys = (grid.ymin + (np.arange(grid.ny)[:, None] + sub[None, :]) * grid.dy).ravel()
    X, Y = np.meshgrid(xs, ys)
    return X.ravel(), Y.ravel()


def _material_index(r: Reader, body: BodyModel, names: list[str], model: InputModel) -> int | None:
    if body.matname is not None:
        if body.matname not in names:
            r.problem(_at(body.line), f"<Body> matname=\"{body.matname}\" names no <Material> "
                                      f"(defined: {', '.join(names)})")
            return None
        index = names.index(body.matname)
    elif body.mat is None:
        return None
    elif not 1 <= body.mat <= len(names):
        r.problem(_at(body.line), f"<Body> mat=\"{body.mat}\" but only {len(names)} material(s) defined")
        return None
    else:
        index = body.mat - 1
    if model.materials[index].group != "materials":
        r.problem(_at(body.line), f"<Body> material '{names[index]}' is a traction law "
                                  f"({model.materials[index].plugin}); bodies need a solid material")
        return None
    return index


def _particles(r: Reader, model: InputModel, grid: Grid, materials, names) -> Particles:
    h = model.mpm
    filled: dict[int, np.ndarray] = {}
    cand: dict[int, tuple] = {}
    chunks = []
    for body in model.bodies:
        mi = None if body.hole else _material_index(r, body, names, model)
        for s in body.shapes:
            x0, x1, y0, y1 = _bbox(s)
            if x0 < grid.xmin or x1 > grid.xmax or y0 < grid.ymin or y1 > grid.ymax:
                r.problem(_at(s.line), f"<{s.kind}> ({x0:g} to {x1:g}, {y0:g} to {y1:g}) extends "
                                       f"outside the grid ({grid.xmin:g} to {grid.xmax:g}, "
                                       f"{grid.ymin:g} to {grid.ymax:g})")
        ppc = body.points_per_cell or h.points_per_cell
        n = int(round(math.sqrt(ppc)))
        if n not in cand:
            cand[n] = _candidates(grid, n)
            filled[n] = np.zeros(cand[n][0].size, dtype=bool)
        X, Y = cand[n]
        mask = np.zeros(X.size, dtype=bool)
        for s in body.shapes:
            mask |= _contains(s, X, Y)
        mask &= ~filled[n]
        filled[n] |= mask
        if body.hole or mi is None:
            continue
        if not mask.any():
            r.problem(_at(body.line), "<Body> creates no particles (shapes empty, outside the "
                                      "grid, or covered by earlier bodies)")
            continue
        thick = body.thick if body.thick is not None else grid.thickness
        vol = grid.dx * grid.dy / (n * n) * thick
        k = int(mask.sum())
        chunks.append(dict(x=X[mask], y=Y[mask], vol=np.full(k, vol),
                           mass=np.full(k, vol * materials[mi].rho),
                           vx=np.full(k, body.vx * MM_PER_S_TO_MM_PER_MS),
                           vy=np.full(k, body.vy * MM_PER_S_TO_MM_PER_MS),
                           lp=np.full(k, 0.5 / n), mat=np.full(k, mi), thick=np.full(k, thick),
                           n=np.full(k, n)))
    if not chunks:
        return None
    cat = {key: np.concatenate([c[key] for c in chunks]) for key in chunks[0]}
    pd = np.array([(model.materials[m].pdamping_per_s if model.materials[m].pdamping_per_s
                    is not None else h.pdamping_per_s) for m in range(len(materials))])
    n_hist = max(getattr(m, "n_history", 0) for m in materials)
    p = Particles.allocate(np.vstack([cat["x"], cat["y"]]), np.vstack([cat["vx"], cat["vy"]]),
                           cat["mass"], cat["vol"], np.vstack([cat["lp"], cat["lp"]]),
                           cat["mat"], n_hist, pd[cat["mat"]] * PER_S_TO_PER_MS)
    p.thick = cat["thick"]
    p.per_side = cat["n"]
    for i, m in enumerate(materials):
        sel = p.mat == i
        if sel.any() and getattr(m, "n_history", 0):
            p.hist[:m.n_history, sel] = m.initial_history(int(sel.sum()))
    return p


# ---- boundary conditions --------------------------------------------------------------
_KEYWORD = re.compile(r"^(min|max)([+-]?)(\d*\.?\d*)$")


def _coordinate(raw: str, lo: float, hi: float, cell: float) -> float:
    """A coordinate: a number, or min/max of the grid shifted by cells (min-, max+2)."""
    m = _KEYWORD.match(raw.strip())
    if not m:
        return float(raw)
    base = lo if m.group(1) == "min" else hi
    sign = {"+": 1.0, "-": -1.0, "": 1.0}[m.group(2)]
    if m.group(3):
        amount = float(m.group(3))
    else:
        amount = 1.0 if m.group(2) else 0.0
    return base + sign * amount * cell


def _select(r: Reader, cond: ConditionModel, grid: Grid, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    cell = min(grid.dx, grid.dy)
    c = cond.coords
    try:
        if cond.shape == "BCLine":
            x1 = _coordinate(c["x1"], grid.xmin, grid.xmax, cell)
            y1 = _coordinate(c["y1"], grid.ymin, grid.ymax, cell)
            x2 = _coordinate(c["x2"], grid.xmin, grid.xmax, cell)
            y2 = _coordinate(c["y2"], grid.ymin, grid.ymax, cell)
            tol_raw = c.get("tolerance")
            if tol_raw is None:
                tol = 0.1 * cell
            elif tol_raw.startswith("*"):
                tol = float(tol_raw[1:]) * cell
            else:
                tol = float(tol_raw)
            dx, dy = x2 - x1, y2 - y1
            length = math.hypot(dx, dy)
            if length == 0:
                return np.nonzero(np.hypot(x - x1, y - y1) <= tol)[0]
            ux, uy = dx / length, dy / length
            along = (x - x1) * ux + (y - y1) * uy
            across = np.abs(-(x - x1) * uy + (y - y1) * ux)
            return np.nonzero((across <= tol) & (along >= -1e-9 * length) & (along <= length * (1 + 1e-9)))[0]
        if cond.shape == "BCPt":
            px = _coordinate(c["x"], grid.xmin, grid.xmax, cell)
            py = _coordinate(c["y"], grid.ymin, grid.ymax, cell)
            return np.array([int(np.argmin(np.hypot(x - px, y - py)))])
        x1 = _coordinate(c["xmin"], grid.xmin, grid.xmax, cell)
        x2 = _coordinate(c["xmax"], grid.xmin, grid.xmax, cell)
        y1 = _coordinate(c["ymin"], grid.ymin, grid.ymax, cell)
        y2 = _coordinate(c["ymax"], grid.ymin, grid.ymax, cell)
        x1, x2 = sorted((x1, x2))
        y1, y2 = sorted((y1, y2))
        return np.nonzero((x >= x1) & (x <= x2) & (y >= y1) & (y <= y2))[0]
    except ValueError as exc:
        r.problem(_at(cond.shape_line), f"<{cond.shape}> has a coordinate that is not a number "
                                        f"or min/max keyword ({exc})")
        return np.array([], dtype=np.int64)


FACE_NORMALS = {1: (0.0, -1.0), 2: (1.0, 0.0), 3: (0.0, 1.0), 4: (-1.0, 0.0)}


def _conditions(r: Reader, model: InputModel, grid: Grid, particles: Particles) -> Conditions:
    conds = Conditions()
    nx_all, ny_all = grid.node_coordinates()
    for cond in model.conditions:
        axis_name = "x" if cond.direction in (1,) else "y"
        if cond.element == "DisBC":
            members = _select(r, cond, grid, nx_all, ny_all)
            if members.size == 0:
                r.problem(_at(cond.shape_line), f"<{cond.shape}> selects no grid nodes")
                continue
            # a function gives the velocity itself (mm/s): its factor is the unit change
            value = 1.0 if cond.style == 6 else cond.value
            rec = ConditionRecord(f"bc{cond.line}_{axis_name}", GRID_VELOCITY, cond.direction - 1,
                                  cond.style, value * MM_PER_S_TO_MM_PER_MS, cond.time,
                                  cond.ftime, function=cond.function)
            conds.add_grid_velocity(rec, members)
            continue
        members = _select(r, cond, grid, particles.pos[0], particles.pos[1])
        if members.size == 0:
            r.problem(_at(cond.shape_line), f"<{cond.shape}> selects no particles")
            continue
        if cond.element == "LoadBC":
            scale = np.full(members.size, 1.0 / members.size if cond.net else 1.0)
            direction = cond.direction - 1
        else:  # TractionBC: stress times the particle's face area
            nrm = FACE_NORMALS[cond.face]
            vec = {1: (1.0, 0.0), 2: (0.0, 1.0), 11: nrm, 12: (-nrm[1], nrm[0])}[cond.direction]
            direction = 0 if vec[0] != 0 else 1
            sign = vec[direction]
            per_side = particles.per_side[members]
            edge = np.where(cond.face in (1, 3), grid.dx / per_side, grid.dy / per_side)
            scale = sign * edge * particles.thick[members]
            axis_name = "x" if direction == 0 else "y"
        rec = ConditionRecord(f"bc{cond.line}_{axis_name}", PARTICLE_LOAD, direction,
                              cond.style, 1.0 if cond.style == 6 else cond.value, cond.time,
                              cond.ftime, function=cond.function,
                              shape_line=cond.shape_line or 0)
        conds.add_particle_load(rec, members, scale,
                                face=cond.face if cond.element == "TractionBC" else 0)
    return conds


def _global_quantities(r: Reader, model: InputModel, names: list[str]) -> list[GlobalQuantity]:
    out = []
    for ga in model.mpm.global_archives:
        if ga.type not in ("velx", "vely", "dispx", "dispy"):
            continue  # energies and work are always in global.csv
        if ga.matname is not None:
            if ga.matname not in names:
                r.problem(_at(ga.line), f"<GlobalArchive> matname=\"{ga.matname}\" names no material")
                continue
            mi = names.index(ga.matname)
        elif ga.mat:
            if not 1 <= ga.mat <= len(names):
                r.problem(_at(ga.line), f"<GlobalArchive> mat=\"{ga.mat}\" is not a material number")
                continue
            mi = ga.mat - 1
        else:
            mi = -1
        unit = "mm_s" if ga.type.startswith("vel") else "mm"
        label = "all" if mi < 0 else re.sub(r"\W+", "_", names[mi]).strip("_")
        out.append(GlobalQuantity(ga.type, mi, f"{ga.type}_{unit}_{label}"))
    return out
