"""Parameter sweeps: one template input, a table of entity values, one run per row, on Dask.

The template is an ordinary NairnMPM XML input whose internal DTD declares the
parameters as entities::

    <!DOCTYPE JANFEAInput [
      <!ENTITY E "1000">
      <!ENTITY load "20">
    ]>
    ... <E>&E;</E> ... <LoadBC dir="1" style="2" load="&load;"/> ...

The table is a CSV whose header names entities of the template (plus an optional
``name`` column for each member's folder name; otherwise ``run_001``, ``run_002``...).
Each member gets a folder ``OUT/<name>`` holding its ``input.xml`` (the template with
the row's entity values) and its results (``run.json``, ``global.csv``, ...); ``OUT``
gets ``summary.csv`` with one row per member.

Members run as Dask tasks: on a local cluster of worker processes by default, or on
the cluster whose scheduler address is given (then ``OUT`` must be on a file system
the workers see at the same path).  A member that fails (bad input, unstable run, any
exception) is reported in its summary row and does not stop the others.
"""
from __future__ import annotations

import csv
import math
import re
import shutil
import time
from pathlib import Path
from typing import Callable

from .errors import InputError, InputProblem, SimulationUnstable

NAME_COLUMN = "name"
SUMMARY = "summary.csv"
INPUT_NAME = "input.xml"
STATUS_COLUMNS = ["exit_status", "message", "wall_seconds", "steps"]
ENERGY_COLUMNS = ["kinetic_energy_J", "strain_energy_J"]

# a general (not parameter, %) internal entity with a literal value
_ENTITY = re.compile(r"""<!ENTITY\s+(?!%)([A-Za-z_:][\w.:-]*)\s+(?:"([^"]*)"|'([^']*)')\s*>""")
_DOCTYPE = re.compile(r"<!DOCTYPE\b")
_SAFE_NAME = re.compile(r"^[A-Za-z0-9][\w.+-]*$")


# ---- the table --------------------------------------------------------------------------
def read_table(csv_path) -> list[dict]:
    """Rows of the sweep table as dicts (entity name -> value text), each with a
    ``name`` (from the ``name`` column, else ``run_001``, ``run_002``, ...)."""
    path = Path(csv_path)
    if not path.exists():
        raise InputError(InputProblem(str(path), None, "file not found"))
    with open(path, newline="") as f:
        lines = list(csv.reader(f))
    # line numbers (1-based) of non-blank rows
    numbered = [(i + 1, [c.strip() for c in r]) for i, r in enumerate(lines) if any(c.strip() for c in r)]
    if not numbered:
        raise InputError(InputProblem(str(path), None, "empty table (needs a header row naming entities)"))
    head_line, header = numbered[0]
    problems = []
    if any(not h for h in header):
        problems.append(InputProblem(str(path), head_line, "empty column name in the header"))
    dup = sorted({h for h in header if h and header.count(h) > 1})
    if dup:
        problems.append(InputProblem(str(path), head_line, f"repeated column(s): {', '.join(dup)}"))
    if not [h for h in header if h != NAME_COLUMN]:
        problems.append(InputProblem(str(path), head_line, "no entity columns in the header"))
    if len(numbered) < 2:
        problems.append(InputProblem(str(path), head_line, "no rows after the header"))
    if problems:
        raise InputError(problems)
    rows, seen = [], {}
    for k, (line, cells) in enumerate(numbered[1:], start=1):
        if len(cells) != len(header):
            problems.append(InputProblem(str(path), line,
                                         f"{len(cells)} values for {len(header)} columns"))
            continue
        row = dict(zip(header, cells))
        name = row.pop(NAME_COLUMN, "") or f"run_{k:03d}"
        if not _SAFE_NAME.match(name):
            problems.append(InputProblem(str(path), line, f"name '{name}' is not a usable folder name "
                                         "(letters, digits, _ . + - only)"))
        elif name in seen:
            problems.append(InputProblem(str(path), line, f"name '{name}' already used on line {seen[name]}"))
        seen.setdefault(name, line)
        empty = [h for h, v in row.items() if not v]
        if empty:
            problems.append(InputProblem(str(path), line, f"no value for {', '.join(empty)}"))
        rows.append({NAME_COLUMN: name, **row})
    if problems:
        raise InputError(problems)
    return rows


# ---- member inputs ------------------------------------------------------------------------
def declared_entities(template_text: str) -> dict[str, tuple[int, str]]:
    """Internal general entities of a template: name -> (line, value)."""
    out = {}
    for m in _ENTITY.finditer(template_text):
        value = m.group(2) if m.group(2) is not None else m.group(3)
        out.setdefault(m.group(1), (template_text.count("\n", 0, m.start()) + 1, value))
    return out


def _quote(value: str) -> str:
    # an entity value may not hold a bare %, & or its own quote character
    return '"' + (value.replace("&", "&#38;").replace("%", "&#37;").replace('"', "&#34;")) + '"'


def member_input(template_text: str, values: dict, template_path="template") -> str:
    """The template with its ``<!ENTITY name "value">`` declarations overridden by
    ``values`` (the ``name`` key is ignored).  Every other key must name an entity the
    template declares, else InputError at the template's ``FILE:LINE``."""
    wanted = {k: str(v) for k, v in values.items() if k != NAME_COLUMN}
    declared = declared_entities(template_text)
    unknown = [k for k in wanted if k not in declared]
    if unknown:
        m = _DOCTYPE.search(template_text)
        line = template_text.count("\n", 0, m.start()) + 1 if m else 1
        have = ", ".join(declared) if declared else "none"
        raise InputError([InputProblem(str(template_path), line,
                                       f"table column '{k}' names no entity declared in the "
                                       f"template (declared: {have})") for k in unknown])
    done = set()

    def swap(m):
        name = m.group(1)
        if name not in wanted or name in done:     # the first declaration is the one XML uses
            return m.group(0)
        done.add(name)
        return f"<!ENTITY {name} {_quote(wanted[name])}>"
    return _ENTITY.sub(swap, template_text)


# ---- one member (runs in a worker) -----------------------------------------------------------
def run_member(xml_path, out_dir) -> dict:
    """Run one member; results go to ``out_dir``.  Never raises: returns
    {name, exit_status, message, wall_seconds, steps}; exit_status is 'done',
    'input error', 'unstable' or 'error'."""
    import numba
    t0 = time.perf_counter()
    out = Path(out_dir)
    result = {"name": out.name, "exit_status": "error", "message": "", "wall_seconds": 0.0, "steps": 0}
    try:
        numba.set_num_threads(1)          # members share the machine's cores: one thread each
        from .input import load_simulation
        from .outputs.defaults import default_outputs
        sim = load_simulation(xml_path)
        out.mkdir(parents=True, exist_ok=True)
        try:
            status = sim.run(default_outputs(out))
        except SimulationUnstable as exc:
            result.update(exit_status="unstable", message=str(exc), steps=int(exc.step))
        else:
            result.update(exit_status=status.get("exit_status", "done"),
                          message=status.get("message", ""), steps=int(status.get("steps", sim.step)))
    except InputError as exc:
        result.update(exit_status="input error", message="; ".join(str(p) for p in exc.problems))
    except Exception as exc:                     # any failure is reported, not raised
        result.update(exit_status="error", message=f"{type(exc).__name__}: {exc}")
    result["wall_seconds"] = time.perf_counter() - t0
    result["message"] = " ".join(str(result["message"]).split())   # one line in the summary
    return result


# ---- the sweep ------------------------------------------------------------------------------
def prepare_folder(out_dir: Path, force: bool = False) -> None:
    """Make ``out_dir`` empty: refuse to replace anything that is not a sweep folder."""
    out_dir = Path(out_dir)
    if out_dir.exists():
        if not out_dir.is_dir():
            raise InputError(InputProblem(str(out_dir), None, "exists and is not a folder"))
        if any(out_dir.iterdir()):
            if not force:
                raise InputError(InputProblem(str(out_dir), None,
                                              "sweep folder exists; use --force to replace it"))
            if not (out_dir / SUMMARY).exists():
                raise InputError(InputProblem(str(out_dir), None,
                                              "exists and is not a sweep folder (no summary.csv); "
                                              "not replacing it"))
        shutil.rmtree(out_dir)
    out_dir.mkdir(parents=True)


def _final_energies(folder: Path) -> dict:
    g = folder / "global.csv"
    if not g.exists():
        return {}
    try:
        from .analysis.results import read_csv_columns
        _, cols = read_csv_columns(g)
    except Exception:
        return {}
    out = {}
    for c in ENERGY_COLUMNS:
        a = cols.get(c)
        if a is not None and len(a):
            out[c] = float(a[-1])
    return out


def write_summary(out_dir: Path, rows: list[dict], results: dict[str, dict]) -> Path:
    entity_cols = []
    for r in rows:
        entity_cols += [k for k in r if k != NAME_COLUMN and k not in entity_cols]
    head = [NAME_COLUMN] + entity_cols + STATUS_COLUMNS + ENERGY_COLUMNS
    path = Path(out_dir) / SUMMARY
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(head)
        for r in rows:
            res = results.get(r[NAME_COLUMN], {"exit_status": "not run", "message": ""})
            energies = _final_energies(Path(out_dir) / r[NAME_COLUMN])
            ws = res.get("wall_seconds", "")
            w.writerow([r[NAME_COLUMN]] + [r.get(c, "") for c in entity_cols]
                       + [res.get("exit_status", ""), res.get("message", ""),
                          f"{ws:.3f}" if isinstance(ws, float) and math.isfinite(ws) else ws,
                          res.get("steps", "")]
                       + [repr(energies[c]) if c in energies else "" for c in ENERGY_COLUMNS])
    return path


def run_sweep(template, table, out_dir, scheduler: str | None = None, workers: int | None = None,
              threads_per_worker: int = 1, force: bool = False,
              on_result: Callable[[dict], None] | None = None) -> list[dict]:
    """Run every member of a sweep and write ``out_dir/summary.csv``.

    ``table`` is a CSV path or a list of rows as ``read_table`` returns them.  All
    members' inputs are checked against the template (InputError) before anything
    runs.  ``scheduler`` is a Dask scheduler address (else a local cluster of
    ``workers`` processes, default 2, ``threads_per_worker`` threads each).
    ``on_result(status)`` is called as each member finishes.  Returns the members'
    status dicts in table order."""
    template = Path(template)
    if not template.exists():
        raise InputError(InputProblem(str(template), None, "file not found"))
    text = template.read_text(encoding="utf-8")
    rows = read_table(table) if not isinstance(table, list) else [dict(r) for r in table]
    for k, r in enumerate(rows, start=1):
        r.setdefault(NAME_COLUMN, f"run_{k:03d}")
    inputs = {r[NAME_COLUMN]: member_input(text, r, template) for r in rows}   # all checked first
    out_dir = Path(out_dir)
    if out_dir.exists() and (not out_dir.is_dir() or (any(out_dir.iterdir()) and (
            not force or not (out_dir / SUMMARY).exists()))):
        prepare_folder(out_dir, force)              # raises the right InputError

    from dask.distributed import Client, LocalCluster, as_completed
    results: dict[str, dict] = {}
    cluster = None
    if scheduler:
        client = Client(scheduler)
    else:
        import logging
        cluster = LocalCluster(n_workers=workers or 2, threads_per_worker=threads_per_worker,
                               processes=True, dashboard_address=None,
                               silence_logs=logging.ERROR)
        client = Client(cluster)
    try:
        # only once connected: a scheduler that cannot be reached replaces nothing
        prepare_folder(out_dir, force)
        paths = {}
        for name, xml in inputs.items():
            d = out_dir / name
            d.mkdir()
            (d / INPUT_NAME).write_text(xml, encoding="utf-8")
            paths[name] = (str((d / INPUT_NAME).resolve()), str(d.resolve()))
        futures = {client.submit(run_member, xml, d, key=f"nairnmpm-{name}-{time.time_ns()}",
                                 pure=False): name for name, (xml, d) in paths.items()}
        for fut in as_completed(list(futures)):
            name = futures[fut]
            try:
                res = fut.result()
            except Exception as exc:          # the worker died, was lost, ...
                res = {"name": name, "exit_status": "error",
                       "message": " ".join(f"{type(exc).__name__}: {exc}".split()),
                       "wall_seconds": float("nan"), "steps": 0}
            res["name"] = name
            results[name] = res
            if on_result is not None:
                on_result(res)
            write_summary(out_dir, rows, results)     # kept current: a crash loses nothing done
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    write_summary(out_dir, rows, results)
    return [results[r[NAME_COLUMN]] for r in rows]
