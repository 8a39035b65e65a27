"""Build the step kernels of one scene, with its materials' updates inlined.

Numba caches a compiled function by its source file, and cannot cache a kernel that
receives a jitted function as an argument.  So for each set of material update
functions we write a copy of ``step_kernels.py`` into a cache folder, with the
default material import replaced by a dispatcher over exactly those updates.  The
copy is written once per (kernel source, materials) pair; later runs load it and its
Numba cache, which makes warm starts fast.
"""
from __future__ import annotations

import hashlib
import importlib.util
import os
import sys
from pathlib import Path

import numpy as np

from . import step_kernels
from .conditions import expression_source

MARKER = "# KERNEL-MATERIALS"
SHAPE_MARKER = "# KERNEL-SHAPE"
FUNCTIONS_MARKER = "# KERNEL-FUNCTIONS"


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


def _condition_source(expressions: dict[int, str]) -> str:
    """``condition_function(r, t, x, y, q)``: the style-6 expression of record r."""
    lines = ["import math as _math_fn", "from numba import njit as _njit_fn", "", "",
             "@_njit_fn(cache=True, inline='always')", "def condition_function(r, t, x, y, q):"]
    for r, text in sorted(expressions.items()):
        src = expression_source(text).replace("math.", "_math_fn.")
        lines.append(f"    if r == {int(r)}:")
        lines.append(f"        return {src}")
    lines.append("    return 0.0")
    return "\n".join(lines) + "\n"


def load_kernels(update_functions: list[str], shape: int = 1,
                 expressions: dict[int, str] | None = None):
    """Return the kernel module dispatching over these update functions (in order),
    compiled for one kind of shape function (0 linear, 1 uGIMP) and with the scene's
    style-6 condition expressions (record index -> expression of t)."""
    template = Path(step_kernels.__file__).read_text()
    lines = template.splitlines()
    marked = [i for i, line in enumerate(lines) if line.rstrip().endswith(MARKER)]
    shaped = [i for i, line in enumerate(lines) if SHAPE_MARKER in line]
    if len(marked) != 1 or len(shaped) != 1:
        raise RuntimeError("step_kernels.py must have exactly one material import marker "
                           "and one shape marker")
    lines[marked[0]] = _dispatch_source(update_functions)
    lines[shaped[0]] = f"KIND = {int(shape)}  # shape functions of this build"
    if expressions:
        fn = [i for i, line in enumerate(lines) if line.rstrip().endswith(FUNCTIONS_MARKER)]
        if len(fn) != 1:
            raise RuntimeError("step_kernels.py must have one condition-function marker")
        lines[fn[0]] = _condition_source(expressions)
    source = "\n".join(lines) + "\n"
    return _load_source(source, "nairnmpm_kernels", update_functions + ["nairnmpm_py.core.shape:x"])


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


CRACK_BASE_MARKER = "# KERNEL-BASE"
TRACTION_MARKER = "# KERNEL-TRACTION"
CRACK_DEPENDENCIES = ["nairnmpm_py.cracks.crossing:x", "nairnmpm_py.cracks.chords:x"]


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


def load_crack_kernels(base, envelope_functions: list[str]):
    """The crack step for a scene whose no-crack kernels are ``base`` (from
    ``load_kernels``), dispatching over these traction envelopes ("module:function",
    index = kind in the law tables)."""
    from . import crack_step_kernels
    lines = Path(crack_step_kernels.__file__).read_text().splitlines()
    based = [i for i, line in enumerate(lines) if line.rstrip().endswith(CRACK_BASE_MARKER)]
    traced = [i for i, line in enumerate(lines) if line.rstrip().endswith(TRACTION_MARKER)]
    if len(based) != 1 or len(traced) != 1:
        raise RuntimeError("crack_step_kernels.py must have one base and one traction marker")
    lines[based[0]] = lines[based[0]].replace("nairnmpm_py.core.step_kernels", base.__name__)
    lines[traced[0]] = _traction_source(envelope_functions)
    source = "\n".join(lines) + "\n"
    return _load_source(source, "nairnmpm_crack_kernels",
                        envelope_functions + CRACK_DEPENDENCIES + [base.__name__ + ":x"])
