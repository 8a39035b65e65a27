"""Engine speed against a base commit, side by side in one run.

    python benchmarks/side_by_side.py --base-python /path/to/base_venv/bin/python
    python benchmarks/side_by_side.py --base-python ... --cases beam block --threads 1 --rounds 2

This machine's speed drifts by 30 % and more between sessions, so a speed gate is a
ratio measured in one run: each case runs in a fresh process of this checkout's
interpreter and of the base's, in turn (A B A B ...), and the best time of each is
kept.  A worker compiles its kernels on a throw-away copy of the scene first, then
times the steps alone.  Cases (all with the public Python API of both versions):

* ``beam``: the throughput beam (4,800 particles), 3,000 steps;
* ``block``: the 30k-particle block, 600 steps;
* ``block_crack``: the same with the 200-particle crack of ``crack_cost.py``;
* ``dcb``: the DCB template at 0.5 mm particles (1 mm cells), run to 11 ms with its
  J checks and growth (outputs off).

A stepping case times its steps in five equal blocks and keeps five times the
fastest (other jobs slow a block down, never speed one up).  Writes
``OUT/side_by_side.csv``: case, threads, best seconds of each, base / new of the
best (above 1: this checkout is faster) and the median of the rounds' pair ratios.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
STEPS = {"beam": 3000, "block": 600, "block_crack": 600}
BLOCKS = 5


def _scene_path(case: str, folder: Path) -> Path:
    if case == "beam":
        return HERE / "inputs" / "cantilever_beam.xml"
    if case == "block":
        return HERE / "inputs" / "block_30k.xml"
    if case == "block_crack":
        sys.path.insert(0, str(HERE))
        from crack_cost import scenes
        return scenes(folder)["200-particle crack"]
    return ROOT / "inputs" / "dcb_bridging.xml"


def worker(case: str, threads: int) -> None:
    """Time one case with whatever nairnmpm_py this interpreter imports."""
    import numba
    from nairnmpm_py.input import load_simulation
    numba.set_num_threads(threads)
    with tempfile.TemporaryDirectory() as tmp:
        path = _scene_path(case, Path(tmp))

        def scene():
            sim = load_simulation(str(path))
            sim.parallel = threads > 1
            if case == "dcb":
                sim.max_time = 11.0
            return sim
        warm = scene()
        warm.advance(2)                     # compile (or load) the kernels
        if case == "dcb":
            warm.max_time = 3 * warm.dt     # and the run loop's J and growth code
            warm.run([])
        sim = scene()
        if case == "dcb":
            t0 = time.perf_counter()
            sim.run([])
            seconds = time.perf_counter() - t0
        else:
            # the steps in BLOCKS equal blocks, the fastest kept for all: other jobs on
            # the machine slow some blocks down, never speed one up
            block = STEPS[case] // BLOCKS
            best = float("inf")
            for _ in range(BLOCKS):
                t0 = time.perf_counter()
                sim.advance(block)
                best = min(best, time.perf_counter() - t0)
            seconds = best * BLOCKS
    print(json.dumps({"seconds": seconds, "steps": int(sim.step)}))


def _time(python: str, case: str, threads: int) -> dict:
    out = subprocess.run([python, str(Path(__file__).resolve()), "--worker", case, str(threads)],
                         capture_output=True, text=True, cwd=tempfile.gettempdir())
    if out.returncode != 0:
        raise RuntimeError(f"{python} {case}: {out.stderr[-2000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--base-python", required=False, help="interpreter of the base commit's venv")
    ap.add_argument("--cases", nargs="+", default=["beam", "block", "block_crack", "dcb"],
                    choices=["beam", "block", "block_crack", "dcb"])
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--rounds", type=int, default=3, help="A B pairs per case (best kept)")
    ap.add_argument("--out", default=str(HERE / "results"))
    ap.add_argument("--worker", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        worker(args.worker[0], int(args.worker[1]))
        return 0
    if not args.base_python:
        ap.error("--base-python is required")
    rows = []
    for case in args.cases:
        for threads in args.threads:
            new, base = [], []
            for _ in range(args.rounds):
                new.append(_time(sys.executable, case, threads))
                base.append(_time(args.base_python, case, threads))
            bn = min(r["seconds"] for r in new)
            bb = min(r["seconds"] for r in base)
            pairs = sorted(b["seconds"] / a["seconds"] for a, b in zip(new, base))
            row = {"case": case, "threads": threads, "steps": new[0]["steps"],
                   "new_s": round(bn, 3), "base_s": round(bb, 3),
                   "base_over_new": round(bb / bn, 3),
                   "median_pair_ratio": round(pairs[len(pairs) // 2], 3),
                   "new_all_s": " ".join(f"{r['seconds']:.3f}" for r in new),
                   "base_all_s": " ".join(f"{r['seconds']:.3f}" for r in base)}
            rows.append(row)
            print(row, flush=True)
    sys.path.insert(0, str(HERE))
    from csv_rows import write_rows
    Path(args.out).mkdir(parents=True, exist_ok=True)
    write_rows(Path(args.out) / "side_by_side.csv", rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
