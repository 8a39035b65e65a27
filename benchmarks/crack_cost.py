"""What a crack costs: step time of the 30k-particle block with and without a crack
of 200 crack particles.

    python benchmarks/crack_cost.py                    # 1 and 2 threads, best of 3
    python benchmarks/crack_cost.py --threads 1 --steps 400 --repeats 1

The scene is ``inputs/block_30k.xml`` of the throughput benchmark (150 x 50 mm,
1 mm cells, 30,000 particles, uGIMP, USAVG+).  The cracked version adds a horizontal
crack at y = 25.5 mm from the right edge (exterior end at x = 151 mm) to a tip at
x = 101.25 mm, 200 crack particles (quarter-cell segments), traction free, with J at
its tip (not computed during the timed steps: J runs only at archive times).

Writes ``OUT/crack_cost.csv``: threads, scene, seconds per step, particle updates per
second, and the crack's overhead in percent of the uncracked step.
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numba

from csv_rows import write_rows

HERE = Path(__file__).resolve().parent
CRACK = """  <CrackList>
    <Line xmin="151" ymin="25.5" xmax="101.25" ymax="25.5" resolution="199" start_tip="-2" end_tip="1"/>
  </CrackList>
"""


def scenes(folder: Path) -> dict[str, Path]:
    base = (HERE / "inputs" / "block_30k.xml").read_text()
    cracked = base.replace("  <Material Type", CRACK + "  <Material Type", 1)
    cracked = cracked.replace("<MPMHeader>", '<MPMHeader>\n    <Cracks><JContour type="1" size="2"/></Cracks>', 1)
    out = {}
    for name, text in (("no crack", base), ("200-particle crack", cracked)):
        path = folder / f"block_30k_{name.split()[0]}.xml"
        path.write_text(text)
        out[name] = path
    return out


def step_time(path: Path, threads: int, steps: int, repeats: int) -> float:
    from nairnmpm_py.input import load_simulation
    numba.set_num_threads(threads)
    best = float("inf")
    for _ in range(repeats + 1):          # the first round compiles / loads the cache
        sim = load_simulation(path)
        sim.parallel = threads > 1
        sim.prepare()
        sim.advance(2)
        t0 = time.perf_counter()
        sim.advance(steps)
        best = min(best, (time.perf_counter() - t0) / steps)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", default=str(HERE / "results"))
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    paths = scenes(HERE / "inputs")
    rows = []
    for threads in args.threads:
        base = None
        for name, path in paths.items():
            t = step_time(path, threads, args.steps, args.repeats)
            base = t if base is None else base
            rows.append({"threads": threads, "scene": name, "ms_per_step": round(t * 1e3, 4),
                         "M_updates_per_s": round(30000 / t / 1e6, 3),
                         "overhead_pct": round(100 * (t / base - 1), 1)})
            print(rows[-1], flush=True)
    write_rows(out / "crack_cost.csv", rows)


if __name__ == "__main__":
    main()
