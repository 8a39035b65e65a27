"""The step as one task list (``core/tasks.py``): what a scene loads, the composed
driver, the per-task profile, and the engine's shape rules (no argument walls, a core
that imports nothing concrete)."""
from __future__ import annotations

import ast
import inspect
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

from nairnmpm_py.core import tasks
from nairnmpm_py.input import load_simulation
from nairnmpm_py.outputs.defaults import default_outputs

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "nairnmpm_py"
BAR = ROOT / "inputs" / "vibrating_bar.xml"


def test_crack_tasks_enter_only_scenes_with_cracks():
    for with_cracks in (False, True):
        extrapolate, step, finish = tasks.step_tasks(with_cracks)
        names = [t.name for t in extrapolate + step + finish]
        crack_names = [t.name for t in tasks.STEP + tasks.EXTRAPOLATE if t.cracks]
        assert any(n in names for n in crack_names) == with_cracks
        source = tasks.driver_source(with_cracks)
        # the driver calls exactly the listed tasks, in the listed order, each through
        # its own entry of the address array (a wrapper gets its pass's)
        order = tasks.profile_rows(with_cracks)
        called = []
        for line in source.splitlines():
            line = line.strip()
            if line.startswith("_call(T["):
                name = line.split("# ")[1]
            elif line.endswith("])") and "(P, G, C, K, S, T[" in line:
                name = line.split("(")[0]
            else:
                continue
            assert f"T[{order.index(name)}]" in line
            called.append(name)
        plain = called[:len(called) // 2]
        assert plain == [t.name for t in extrapolate + step + finish]
        assert called[len(called) // 2:] == plain     # the profiled driver


def test_a_scene_without_cracks_loads_no_crack_module():
    code = ("import sys\nfrom nairnmpm_py.input import load_simulation\n"
            f"sim = load_simulation({str(BAR)!r})\nsim.advance(2)\n"
            "print(sorted(m for m in sys.modules if m.startswith('nairnmpm_py.cracks')"
            " or 'crack_kernels' in m))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "[]"


def test_profiled_run_gives_the_same_numbers_and_shares_that_cover_the_run(tmp_path):
    plain = load_simulation(str(BAR))
    plain.max_time = 0.2
    plain.run([])
    profiled = load_simulation(str(BAR))
    profiled.max_time = 0.2
    folder = tmp_path / "run"
    folder.mkdir()
    status = profiled.run(default_outputs(folder), profile=True)
    assert np.array_equal(plain.particles.pos, profiled.particles.pos)
    assert np.array_equal(plain.particles.stress, profiled.particles.stress)
    rows = status["profile"]
    names = [r["task"] for r in rows]
    for t in tasks.STEP:
        assert (t.name in names) == (not t.cracks)
    assert "global_archive" in names and "archive" in names and "propagation" not in names
    assert abs(sum(r["share"] for r in rows) - 1.0) < 1e-9
    assert all(r["ms_per_step"] >= 0.0 for r in rows)
    by_name = {r["task"]: r for r in rows}
    assert by_name["stress_and_forces"]["ms_per_step"] > 0.0
    saved = json.loads((folder / "run.json").read_text())
    assert [r["task"] for r in saved["profile"]] == names


def _jitted_functions(path: Path):
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef) and any(
                "njit" in ast.unparse(d) or "jit" in ast.unparse(d).split("(")[0]
                for d in node.decorator_list):
            yield node


def test_no_jitted_function_takes_more_than_16_parameters():
    walls = []
    for path in PACKAGE.rglob("*.py"):
        for fn in _jitted_functions(path):
            n = len(fn.args.args) + len(fn.args.kwonlyargs)
            if n > 16:
                walls.append(f"{path.relative_to(ROOT)} {fn.name} ({n})")
    assert walls == []


def test_core_imports_nothing_concrete():
    bad = []
    for path in (PACKAGE / "core").glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = []
            if isinstance(node, ast.ImportFrom):
                names = [("." * node.level) + (node.module or "")]
            elif isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            for name in names:
                if any(part in name.split(".") for part in ("cracks", "materials", "traction")):
                    bad.append(f"{path.name}:{node.lineno} {name}")
    assert bad == []


def test_tasks_named_in_the_list_exist_in_their_modules():
    import importlib
    for t in tasks.EXTRAPOLATE + tasks.STEP + tasks.FINISH:
        module = importlib.import_module(t.module)
        params = list(inspect.signature(getattr(module, t.name).py_func).parameters)
        if not t.runs:
            assert params == ["P", "G", "C", "K", "S"]
            continue
        # a driver-side wrapper: the bundles and its pass's address; the pass takes the
        # bundles it reads and the extra arguments its compile types name
        assert params[:5] == ["P", "G", "C", "K", "S"] and len(params) == 6
        pass_params = list(inspect.signature(getattr(module, t.runs).py_func).parameters)
        assert pass_params[:4] == ["P", "G", "K", "S"]
        assert len(pass_params) == 4 + len(module.PASS_ARGS[t.runs])
    for p in tasks.PERIODIC:
        if ":" in p.where and p.where.startswith("nairnmpm_py"):
            assert callable(tasks.periodic_task(p.name))


def test_results_do_not_depend_on_how_the_run_is_cut_into_driver_calls():
    """A run returns to Python every ~0.2 s of wall time, so where its driver calls end
    follows the machine's speed.  The time is the step's own sum of dt, so loads that
    follow the time (here two ramps) see the same time to the bit either way."""
    ramp = ROOT / "inputs" / "ramped_load_bar.xml"
    whole, cut = load_simulation(str(ramp)), load_simulation(str(ramp))
    whole.advance(300)
    for n in (1, 7, 1, 91, 200):
        cut.advance(n)
    assert cut.step == whole.step == 300
    assert cut.time == whole.time
    assert np.array_equal(cut.particles.pos, whole.particles.pos)
    assert np.array_equal(cut.particles.vel, whole.particles.vel)
