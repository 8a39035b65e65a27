"""Same results before and after an engine change: dump a few runs' state, compare two dumps.

    python benchmarks/same_results.py dump OUT.npz [--threads 1 2] [--quick]
    python benchmarks/same_results.py compare BASE.npz NEW.npz [--csv benchmarks/results/same_results.csv]

``dump`` runs, with whatever ``nairnmpm_py`` the interpreter imports (so run it once
in a venv of the base commit and once in this one), on 1 and 2 threads:

* the throughput beam (``benchmarks/inputs/cantilever_beam.xml``): 2,000 steps;
* SENT B (``inputs/sent_fig3_B.xml``): 2,000 steps, then J at its tip;
* the DCB template (``inputs/dcb_bridging.xml``, 1 mm cells) to 12 ms, through its
  first growth (about 11.3 ms): crack tip, J_tip, J_ff and R at every growth step.

and stores positions, velocities, stresses, crack planes and the J / R numbers.
``compare`` prints, per array, the largest difference relative to the array's largest
magnitude, and writes them to a CSV.
"""
from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent


def _scene(path: Path, threads: int):
    import numba
    from nairnmpm_py.input import load_simulation
    numba.set_num_threads(threads)
    sim = load_simulation(str(path))
    sim.parallel = threads > 1
    return sim


def _state(out: dict, key: str, sim) -> None:
    p = sim.particles
    out[f"{key}/pos"] = p.pos.copy()
    out[f"{key}/vel"] = p.vel.copy()
    out[f"{key}/stress"] = p.stress.copy()
    if sim.cracks is not None:
        out[f"{key}/crack_plane"] = sim.cracks.cracks.plane.copy()


def dump(target: Path, threads: list[int], quick: bool) -> None:
    from nairnmpm_py.outputs.defaults import default_outputs
    steps = 200 if quick else 2000
    out = {}
    for n in threads:
        sim = _scene(ROOT / "benchmarks" / "inputs" / "cantilever_beam.xml", n)
        sim.advance(steps)
        _state(out, f"beam_t{n}", sim)

        sim = _scene(ROOT / "inputs" / "sent_fig3_B.xml", n)
        sim.advance(steps)
        _state(out, f"sentB_t{n}", sim)
        rows = sim.cracks.tip_results(sim)
        out[f"sentB_t{n}/J"] = np.array([[r["J_tip_J_m2"], r["J_ff_J_m2"]] for r in rows])

        sim = _scene(ROOT / "inputs" / "dcb_bridging.xml", n)
        sim.max_time = 2.0 if quick else 12.0
        with tempfile.TemporaryDirectory() as tmp:
            sim.run(default_outputs(Path(tmp)))
        _state(out, f"dcb_t{n}", sim)
        log = sim.cracks.growth_log
        out[f"dcb_t{n}/growth"] = np.array(
            [[r.get("time_ms", np.nan), r.get("J_tip_J_m2", np.nan), r.get("J_ff_J_m2", np.nan),
              r.get("R_J_m2", np.nan), r.get("tip_x_mm", np.nan)] for r in log]).reshape(-1, 5)
        print(f"threads {n}: DCB grew {len(log)} times by {sim.max_time} ms", flush=True)
        np.savez(target, **out)   # after each thread count, so a long run keeps its part
    print(f"wrote {target}")


def compare(base: Path, new: Path, csv_path: Path | None) -> int:
    a = np.load(base)
    b = np.load(new)
    rows = []
    worst = 0.0
    for key in sorted(set(a.files) | set(b.files)):
        if key not in a.files or key not in b.files:
            rows.append({"array": key, "shape_base": a[key].shape if key in a.files else "-",
                         "shape_new": b[key].shape if key in b.files else "-",
                         "max_rel_diff": "missing"})
            continue
        x, y = a[key], b[key]
        if x.shape != y.shape:
            rows.append({"array": key, "shape_base": x.shape, "shape_new": y.shape,
                         "max_rel_diff": "shape differs"})
            worst = np.inf
            continue
        scale = max(float(np.nanmax(np.abs(x))) if x.size else 0.0, 1e-300)
        diff = float(np.nanmax(np.abs(x - y))) / scale if x.size else 0.0
        worst = max(worst, diff)
        rows.append({"array": key, "shape_base": x.shape, "shape_new": y.shape,
                     "max_rel_diff": f"{diff:.3e}"})
    for r in rows:
        print(f"{r['array']:28s} {str(r['shape_new']):14s} {r['max_rel_diff']}")
    print(f"largest relative difference: {worst:.3e}")
    if csv_path is not None:
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        from csv_rows import write_rows
        write_rows(csv_path, rows)
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    d = sub.add_parser("dump")
    d.add_argument("out", type=Path)
    d.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    d.add_argument("--quick", action="store_true")
    c = sub.add_parser("compare")
    c.add_argument("base", type=Path)
    c.add_argument("new", type=Path)
    c.add_argument("--csv", type=Path)
    args = ap.parse_args(argv)
    if args.cmd == "dump":
        dump(args.out, args.threads, args.quick)
        return 0
    return compare(args.base, args.new, args.csv)


if __name__ == "__main__":
    sys.exit(main())
