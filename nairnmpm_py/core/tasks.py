"""The time step, as an ordered list of tasks (read it top to bottom).

Each entry names the task, the module that holds it and what it does.  Entries marked
``cracks`` are inserted only for scenes with cracks (their modules live in
``cracks/``); a scene without cracks never loads them.  ``kernel_build`` composes the
fused Numba driver from these lists (``driver_source``), so the order lives here and
nowhere else.  Every step task is a jitted ``task(P, G, C, K, S)`` over the state
bundles of ``core/state``, compiled on its own and called by the driver through its
address (``core/linking``), or a driver-side wrapper ``task(P, G, C, K, S, address)``
of one of the particle passes (``runs``).

Periodic work runs between calls of the driver, at its own cadence (``PERIODIC``).
"""
from __future__ import annotations

import functools
from dataclasses import dataclass

CORE = "nairnmpm_py.core.step_kernels"
CRACKS = "nairnmpm_py.cracks.crack_kernels"
WATCH = "nairnmpm_py.cracks.growth_watch"


@dataclass(frozen=True)
class Task:
    name: str
    module: str
    does: str
    cracks: bool = False   # only in scenes with cracks
    stops: bool = False    # may set a status that ends the run at once
    runs: str = ""         # a wrapper inlined into the driver: the pass it calls


# the particles' mass and momentum on the grid, when the grid is not current (first
# step, after a crack grew or the particles were changed from outside)
EXTRAPOLATE = (
    Task("crack_lists", CRACKS, "chords near each cell, crack slots of each node", cracks=True,
         stops=True),
    Task("weights_and_mass", CORE, "shape functions; mass and momentum to each particle's fields",
         runs="_particle_pass"),
    Task("reduce_extrapolation", CORE, "sum the chunks' field 0; velocities"),
    Task("reduce_crack_fields", CRACKS, "sum the other fields and contact rows at crack nodes", cracks=True),
    Task("contact_momenta", CRACKS, "frictionless contact on the extrapolated momenta", cracks=True),
    Task("momentum_conditions", CORE, "velocity conditions on the momenta, symmetry planes"),
)

STEP = (
    Task("scatter_loads", CORE, "clear forces; particle loads and tractions onto the grid"),
    Task("stress_and_forces", CORE, "velocity gradient, stress update, internal forces",
         runs="_stress_pass"),
    Task("reduce_forces", CORE, "sum the chunks' field-0 forces"),
    Task("reduce_crack_forces", CRACKS, "sum the other fields' forces at crack nodes", cracks=True),
    Task("crack_tractions", CRACKS, "traction laws pull the crack surfaces together", cracks=True),
    Task("contact_forces", CRACKS, "frictionless contact on the updated momenta", cracks=True),
    Task("accelerate", CORE, "field 0's acceleration and updated velocity"),
    Task("accelerate_crack_fields", CRACKS, "the other fields' at crack nodes", cracks=True),
    Task("velocity_conditions", CORE, "velocity conditions at t + dt; reactions"),
    Task("move_cracks", CRACKS, "crack surfaces and planes move with their fields", cracks=True,
         stops=True),
    Task("crack_lists", CRACKS, "chords and crack nodes of the moved cracks", cracks=True,
         stops=True),
    Task("update_and_extrapolate", CORE, "grid to particles; their mass and momentum back",
         runs="_particle_pass"),
    Task("load_work", CORE, "work of the particle loads"),
    Task("advance_clock", CORE, "t += dt; carry the USAVG+ / USL+ stress half"),
    Task("clear_crack_nodes", CRACKS, "empty the other fields at the old crack nodes", cracks=True),
    Task("reduce_extrapolation", CORE, "sum the chunks' field 0; velocities"),
    Task("reduce_crack_fields", CRACKS, "sum the other fields and contact rows at crack nodes", cracks=True),
    Task("contact_momenta", CRACKS, "frictionless contact on the extrapolated momenta", cracks=True),
    Task("momentum_conditions", CORE, "velocity conditions on the momenta, symmetry planes"),
    Task("check_status", CORE, "NaN, runaway or too many particles leaving", stops=True),
    Task("watch_growth", WATCH, "at a check: edge maxima; stop for Python's check when J nears "
         "a tip's threshold", cracks=True, stops=True),
)

# after the last step of a call that is followed by output, and when a run stops
FINISH = (
    Task("flush_stress", CORE, "apply the carried USAVG+ / USL+ stress half", runs="_stress_pass"),
)


@dataclass(frozen=True)
class Periodic:
    name: str
    where: str
    cadence: str
    does: str
    cracks: bool = False


# between driver calls, in this order (``Simulation.run``); ``where`` is the function
# the run loop calls (with the simulation), or for the archive the outputs' hook
PERIODIC = (
    Periodic("propagation", "nairnmpm_py.cracks.scene:propagate",
             "when the step's watch stops it, else every check interval (CFL time of a cell)",
             "J at the growing tips and each tip's criterion; grow the cracks", cracks=True),
    Periodic("global_archive", "nairnmpm_py.outputs.global_row:global_row", "GlobalArchive time",
             "energies, loads, displacements and moments: the row every output gets"),
    Periodic("archive", "outputs' on_archive", "ArchiveTime",
             "J and K at every tip (cracks.csv), HDF5 and VTU archives"),
    Periodic("checkpoint", "nairnmpm_py.core.checkpoint:write_checkpoint",
             "after each archive, every --checkpoint-every minutes, on SIGINT / SIGTERM",
             "the whole state, for nairnmpm resume"),
)


@functools.lru_cache(maxsize=None)
def periodic_task(name: str):
    """The function of the periodic task ``name`` (imported when first asked for, so a
    scene loads only the modules of the tasks it runs)."""
    import importlib
    entry = next(p for p in PERIODIC if p.name == name)
    module, func = entry.where.split(":")
    return getattr(importlib.import_module(module), func)


def step_tasks(with_cracks: bool) -> tuple[tuple[Task, ...], tuple[Task, ...], tuple[Task, ...]]:
    """(extrapolate, step, finish) for a scene with or without cracks."""
    def keep(tasks):
        return tuple(t for t in tasks if with_cracks or not t.cracks)
    return keep(EXTRAPOLATE), keep(STEP), keep(FINISH)


ARGS = "P, G, C, K, S"
# no reference counting in the driver: it only passes the bundles on (the tasks own
# none of their arrays), and counting each of their ~60 arrays at every call doubled
# the driver's compile time
JIT = "@_njit_driver(cache=True, error_model='numpy', _nrt=False)"


def _calls(tasks, indent: str, profile: bool, index: dict, stop: str) -> list[str]:
    """Calls of ``tasks`` (task i of ``task_list`` at address ``T[i]``); after a task
    that may stop the run, ``stop`` (a line that leaves the loop) or, with ``stop``
    empty, the rest nested under a status test."""
    out = []
    for task in tasks:
        i = index[task.name]
        if profile:
            out.append(f"{indent}_c0 = _cycles()")
        if task.runs:
            out.append(f"{indent}{task.name}({ARGS}, T[{i}])")
        else:
            out.append(f"{indent}_call(T[{i}], ({ARGS}))  # {task.name}")
        if profile:
            out.append(f"{indent}prof[{i}] += _cycles() - _c0")
        if task.stops:
            if stop:
                out += [f"{indent}if S.status[0] != 0:", f"{indent}    {stop}"]
            else:
                out.append(f"{indent}if S.status[0] == 0:")
                indent += "    "
    if not tasks or (out and out[-1].endswith(":")):
        out.append(f"{indent}pass")
    return out


def task_list(with_cracks: bool) -> list[Task]:
    """Each task of the step once, in the order of the driver's address array ``T``
    and of the profile array."""
    seen = {}
    for group in step_tasks(with_cracks):
        for t in group:
            seen.setdefault(t.name, t)
    return list(seen.values())


def profile_rows(with_cracks: bool) -> list[str]:
    """Task names in the order of the profile array (each name once)."""
    return [t.name for t in task_list(with_cracks)]


def driver_source(with_cracks: bool) -> str:
    """Source of the step driver: ``advance`` (and ``advance_profiled``, which also
    counts each task's clock cycles into ``prof``, indexed as ``profile_rows``).  It
    calls the tasks through their addresses ``T`` (``task_list`` order), so it holds
    no task's code and one compiled driver serves every scene with these bundles."""
    extrapolate, step, finish = step_tasks(with_cracks)
    index = {name: i for i, name in enumerate(profile_rows(with_cracks))}
    wrappers = sorted({t.name for group in (extrapolate, step, finish) for t in group if t.runs})
    lines = ["from numba import njit as _njit_driver",
             "from nairnmpm_py.core.cycles import cycles as _cycles",
             "from nairnmpm_py.core.linking import call_task as _call",
             f"from {CORE} import {', '.join(wrappers)}"]
    for suffix, profile in (("", False), ("_profiled", True)):
        extra = ", prof" if profile else ""
        lines += ["", "", JIT, f"def advance{suffix}({ARGS}, T, nsteps, resume, flush{extra}):",
                  '    """Up to nsteps steps, extrapolating first unless ``resume``; returns the',
                  '    steps taken (S.status says why it stopped early)."""',
                  "    S.status[0] = 0",
                  "    S.status[1] = -1",
                  "    done = 0",
                  "    if not resume:"]
        lines += _calls(extrapolate, "        ", profile, index, "")
        lines += ["    for step in range(nsteps if S.status[0] == 0 else 0):",
                  "        done = step + 1"]
        lines += _calls(step, "        ", profile, index, "break")
        # a watched tip's stop is not the end of the run: the carried stress half
        # stays carried, as at any step that is not followed by output
        lines += ["    if S.status[0] > 0 or (flush and done == nsteps):"]
        lines += _calls(finish, "        ", profile, index, "")
        lines += ["    return done"]
    return "\n".join(lines) + "\n"
