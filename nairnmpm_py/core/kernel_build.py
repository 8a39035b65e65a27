"""Build the step kernels of one scene: its materials, shape functions, condition
expressions and velocity fields filled into the templates, and the driver composed
from the task list (``core/tasks.py``).

Numba caches a compiled function by its source file, and cannot cache a kernel that
receives a jitted function as an argument.  So for each scene kind we write a copy of
``step_kernels.py`` into a cache folder, with the default material import replaced by
a dispatcher over exactly the scene's updates.  A scene with
cracks also gets a copy of the crack tasks' template (``tasks.CRACKS``) with its
traction-law envelopes, imported by the step copy.  A copy is written once per
distinct source; later runs load it and its Numba cache, which makes warm starts
fast.  The condition expressions are a small module of their own, which the kernels
call through its address (``expressions``), so they never change the step's copy.
The driver is a module of its own too (``load_driver``): it calls the tasks through
their addresses (``task_addresses``, ``core/linking``), so it holds no scene's code.
"""
from __future__ import annotations

import hashlib
import importlib.util
import os
import sys
from pathlib import Path

import numba
import numpy as np

from . import step_kernels
from .expressions import condition_module_source
from .linking import address_of
from .tasks import CRACKS, driver_source, step_tasks, task_list

MARKER = "# KERNEL-MATERIALS"
SHAPE_MARKER = "# KERNEL-SHAPE"
FIELDS_MARKER = "# KERNEL-FIELDS"
MULTI_FIELD_MARKER = "# KERNEL-MULTI-FIELD"
UPDATE_STRESS_MARKER = "# KERNEL-UPDATE-STRESS"
PARALLEL_MARKER = "# KERNEL-PARALLEL"


def cache_dir() -> Path:
    root = os.environ.get("NAIRNMPM_PY_CACHE")
    if root:
        return Path(root)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "nairnmpm_py" / "kernels"


def _dispatch_source(functions: list[str]) -> str:
    """Source of ``material_update``: row ``par`` of the material table starts with
    the index of its update function in ``functions``, then the material's own
    parameters.  The source depends only on the set of functions, so scenes with the
    same kinds of material share one compiled kernel."""
    lines = ["from numba import njit as _njit_dispatch"]
    for i, ref in enumerate(functions):
        module, func = ref.split(":")
        lines.append(f"from {module} import {func} as _material_update_{i}")
    lines += [
        "",
        "",
        "@_njit_dispatch(cache=True, inline='always')",
        "def material_update(m, p, dt, L00, L01, L10, L11, F, stress, hist, w, par, plane_stress):",
        "    kind = int(par[0])",
        "    own = par[1:]",
    ]
    for i in range(len(functions)):
        keyword = "if" if i == 0 else "elif"
        lines.append(f"    {keyword} kind == {i}:")
        lines.append(f"        _material_update_{i}(p, dt, L00, L01, L10, L11, F, stress, hist, w, own, plane_stress)")
    return "\n".join(lines) + "\n"


def material_table(materials: list, plane_stress: bool) -> tuple[list[str], np.ndarray]:
    """(sorted unique update functions, table of [function index, parameters...]).

    Slots that are not solid materials (traction laws share NairnMPM's numbering)
    get a zero row; no particle refers to them."""
    solid = [m for m in materials if getattr(m, "update_function", "")]
    functions = sorted({m.update_function for m in solid})
    vectors = [m.param_vector(plane_stress) if m in solid else np.zeros(0) for m in materials]
    table = np.zeros((len(materials), 1 + max(len(v) for v in vectors)))
    for i, (m, v) in enumerate(zip(materials, vectors)):
        if m in solid:
            table[i, 0] = functions.index(m.update_function)
            table[i, 1:1 + len(v)] = v
    return functions, table


def _replace_marked(lines: list[str], marker: str, text: str, where: str) -> None:
    """Replace the one line of ``lines`` that carries ``marker``."""
    hits = [i for i, line in enumerate(lines) if marker in line]
    if len(hits) != 1:
        raise RuntimeError(f"{where} must have exactly one '{marker}' line")
    lines[hits[0]] = text


def condition_functions(expressions: dict[int, str]) -> tuple[int, np.ndarray]:
    """(address of ``condition_cfunc``, its constants) for a scene's style-6 condition
    expressions (record index -> expression of t); (0, empty) without any."""
    if not expressions:
        return 0, np.zeros(0)
    source, constants = condition_module_source(expressions)
    module = _load_source(source, "nairnmpm_conditions", [])
    return int(module.condition_cfunc.address), constants


def load_kernels(update_functions: list[str], shape: int = 1,
                 crack_envelopes: list[str] | None = None, update_stress: bool = True,
                 parallel: bool = True):
    """The kernel module for a scene whose materials use these update functions (in
    order), with one kind of shape function (0 linear, 1 uGIMP) and, for a scene
    with cracks, the traction envelopes of its laws ("module:function",
    index = kind in the law tables).  ``task_addresses`` gives its tasks to the driver.
    ``update_stress`` False (USF, USL+, USAVG+: the particle update never updates
    stresses) leaves the material updates out of the particle update's code.
    (A build without Numba's parallel loops for one-thread scenes compiles a third
    faster but ran the beam 2.7x slower on one thread; not used until that is
    understood.)"""
    lines = Path(step_kernels.__file__).read_text().splitlines()
    where = "step_kernels.py"
    _replace_marked(lines, MARKER, _dispatch_source(update_functions), where)
    _replace_marked(lines, SHAPE_MARKER, f"KIND = {int(shape)}  # shape functions of this build",
                    where)
    if not update_stress:
        _replace_marked(lines, UPDATE_STRESS_MARKER, "UPDATE_STRESS = False  # USF / USL+ / USAVG+",
                        where)
    refs = update_functions + ["nairnmpm_py.core.shape:x", "nairnmpm_py.core.grid_ops:x",
                               "nairnmpm_py.core.state:x", "nairnmpm_py.core.linking:x",
                               "nairnmpm_py.core.expressions:x"]
    with_cracks = crack_envelopes is not None
    if not parallel:
        _replace_marked(lines, PARALLEL_MARKER, "PARALLEL = False  # one chunk, serial loops",
                        where)
    if with_cracks:
        cracks = _load_crack_tasks(shape, crack_envelopes)
        crack_names = sorted({t.name for group in step_tasks(True) for t in group
                              if t.module == CRACKS})
        # crack tasks of their own modules (no template: nothing of the scene in them)
        own = sorted({(t.module, t.name) for group in step_tasks(True) for t in group
                      if t.cracks and t.module != CRACKS})
        _replace_marked(lines, FIELDS_MARKER, "\n".join(
            [f"from {cracks.__name__} import assign_and_scatter, field_lists, "
             + ", ".join(crack_names)] + [f"from {m} import {n}" for m, n in own]), where)
        _replace_marked(lines, MULTI_FIELD_MARKER, "MULTI_FIELD = True  # crack fields", where)
        refs += [cracks.__name__ + ":x"] + [f"{m}:x" for m, _ in own]
    return _load_source("\n".join(lines) + "\n", "nairnmpm_kernels", refs)


def load_driver(with_cracks: bool):
    """The step driver module (``advance``, ``advance_profiled``) of scenes with or
    without cracks."""
    refs = ["nairnmpm_py.core.step_kernels:x", "nairnmpm_py.core.linking:x",
            "nairnmpm_py.core.cycles:x", "nairnmpm_py.core.state:x"]
    return _load_source(driver_source(with_cracks), "nairnmpm_driver", refs)


def task_addresses(kernels, with_cracks: bool, bundles: tuple) -> np.ndarray:
    """The driver's ``T``: the address of each task of ``task_list`` in the kernel
    module ``kernels``, compiled (or loaded from the cache) for the types of these
    bundles (P, G, C, K, S); a wrapper's entry is its pass's."""
    P, G, C, K, S = (numba.typeof(b) for b in bundles)
    out = []
    for task in task_list(with_cracks):
        if task.runs:
            argtypes = (P, G, K, S) + kernels.PASS_ARGS[task.runs]
            out.append(address_of(getattr(kernels, task.runs), argtypes))
        else:
            out.append(address_of(getattr(kernels, task.name), (P, G, C, K, S)))
    return np.array(out, dtype=np.int64)


def _dependency_text(refs: list[str]) -> str:
    """Source of the modules a generated file imports functions from: Numba's cache
    of a function does not notice when a function it calls changes, so the file name
    (and with it the cache) must change with them."""
    out = []
    for module in sorted({ref.split(":")[0] for ref in refs}):
        try:
            spec = importlib.util.find_spec(module)
            out.append(Path(spec.origin).read_text() if spec and spec.origin else module)
        except (ImportError, OSError, ValueError):
            out.append(module)
    return "\n".join(out)


def _load_source(source: str, prefix: str, refs: list[str]):
    digest = hashlib.sha256((source + _dependency_text(refs)).encode()).hexdigest()[:16]
    name = f"{prefix}_{digest}"
    if name in sys.modules:
        return sys.modules[name]
    folder = cache_dir()
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{name}.py"
    if not path.exists() or path.read_text() != source:
        tmp = path.with_suffix(f".tmp{os.getpid()}")
        tmp.write_text(source)
        os.replace(tmp, path)  # atomic: parallel runs never see half a file
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


TRACTION_MARKER = "# KERNEL-TRACTION"
CRACK_DEPENDENCIES = ["nairnmpm_py.cracks.crossing:x", "nairnmpm_py.cracks.chords:x",
                      "nairnmpm_py.cracks.crack_lists:x", "nairnmpm_py.cracks.bundle:x",
                      "nairnmpm_py.core.state:x", "nairnmpm_py.core.grid_ops:x",
                      "nairnmpm_py.core.step_kernels:x"]


def _traction_source(functions: list[str]) -> str:
    """``traction_envelope(kind, delta, par)``: envelope ``kind`` of the scene's laws."""
    lines = ["from numba import njit as _njit_traction"]
    for i, ref in enumerate(functions):
        module, func = ref.split(":")
        lines.append(f"from {module} import {func} as _envelope_{i}")
    lines += ["", "", "@_njit_traction(cache=True, inline='always')",
              "def traction_envelope(kind, delta, par):"]
    for i in range(len(functions)):
        lines.append(f"    if kind == {i}:")
        lines.append(f"        return _envelope_{i}(delta, par)")
    lines.append("    return 0.0")
    return "\n".join(lines) + "\n"


def _load_crack_tasks(shape: int, envelope_functions: list[str]):
    """The crack tasks' template (``tasks.CRACKS``) built for this shape function and
    dispatching over these traction envelopes."""
    spec = importlib.util.find_spec(CRACKS)
    lines = Path(spec.origin).read_text().splitlines()
    where = Path(spec.origin).name
    _replace_marked(lines, TRACTION_MARKER, _traction_source(envelope_functions), where)
    _replace_marked(lines, SHAPE_MARKER, f"KIND = {int(shape)}  # shape functions of this build",
                    where)
    source = "\n".join(lines) + "\n"
    return _load_source(source, "nairnmpm_crack_kernels", envelope_functions + CRACK_DEPENDENCIES)
