"""Accuracy against cost: J of a traction-free SENT specimen (seed Fig 3D) against the
handbook, over cell sizes and both shape functions.

    python benchmarks/sent_j_accuracy.py                    # 4, 2, 1 mm cells (~15 min)
    python benchmarks/sent_j_accuracy.py --cells 4 2 1 0.5  # add the fine one (~1 h)
    python benchmarks/sent_j_accuracy.py --threads 2 --out benchmarks/results

The scene is ``inputs/sent_fig3_D.xml`` written for each cell size: 50 x 200 mm, a
20 mm edge crack at mid-length, E = 70 GPa, nu = 0.33, plane strain, 10 MPa ramped
over 0.4 ms and held to 1.2 ms with grid damping.  The grid is offset so the crack
line and the crack tip lie mid-cell at every size; crack segments are a quarter cell.
J is read at the end on contours of half-size 2 to 8 cells (those that stay inside
the specimen's grid).

Reference: J0 = K^2 (1 - nu^2) / E with K = sigma sqrt(pi a) F(a/W),
F = 0.265 (1 - a/W)^4 + (0.857 + 0.265 a/W) / (1 - a/W)^1.5 (Tada, Paris and Irwin,
The Stress Analysis of Cracks Handbook, 3rd ed., 2000; SENT with ends free to rotate,
quoted better than 1 % for any a/W).  J0 = 354.9 J/m^2 here.

Writes ``OUT/sent_j_accuracy.csv`` (one row per run and contour size) and
``OUT/sent_j_accuracy.png`` (J error against wall time, one line per shape function).
"""
from __future__ import annotations

import argparse
import csv
import math
import time
from pathlib import Path

import numba

HERE = Path(__file__).resolve().parent
SIGMA, A, W, E, NU = 10.0, 20.0, 50.0, 70000.0, 0.33


def handbook_j() -> float:
    """J0 in J/m^2 (plane strain)."""
    al = A / W
    F = 0.265 * (1 - al) ** 4 + (0.857 + 0.265 * al) / (1 - al) ** 1.5
    K = SIGMA * math.sqrt(math.pi * A) * F
    return K * K * (1 - NU * NU) / E * 1000.0


def scene(cell: float, gimp: bool) -> str:
    """The SENT D input at one cell size: crack line and tip mid-cell."""
    x0 = 20.0 - cell * (math.floor(25.0 / cell) + 0.5)     # a node line half a cell off x = 20
    y_crack = 100.0 + 0.5 * cell                            # ymin = -4 puts nodes on multiples
    ymin = -4.0 if (4.0 / cell).is_integer() else -cell * math.ceil(4.0 / cell)
    seg = cell / 4.0
    n_in = int(round(20.0 / seg))
    start = -seg * 4                                        # exterior end 4 segments outside
    res = n_in + 4
    return f"""<?xml version="1.0"?>
<JANFEAInput version="3">
  <Header><Description>SENT D, {cell:g} mm cells</Description><Analysis>10</Analysis></Header>
  <MPMHeader>
    <MPMMethod>2</MPMMethod>
    {'<GIMP/>' if gimp else ''}
    <Cracks><JContour type="1" size="2"/><JContourSizes>2 3 4 5 6 7 8</JContourSizes></Cracks>
    <MaxTime units="ms">1.2</MaxTime>
    <ArchiveTime units="ms">1.2</ArchiveTime>
    <GlobalArchiveTime units="ms">0.1</GlobalArchiveTime>
    <Damping>40000</Damping>
  </MPMHeader>
  <Mesh>
    <Grid xmin="{x0:g}" xmax="{x0 + cell * math.ceil((55 - x0) / cell):g}" ymin="{ymin:g}" ymax="{204 + cell:g}" thickness="1">
      <Horiz cellsize="{cell:g}"/><Vert cellsize="{cell:g}"/>
    </Grid>
  </Mesh>
  <MaterialPoints><Body mat="1" thick="1"><Rect xmin="0" xmax="50" ymin="0" ymax="200"/></Body></MaterialPoints>
  <CrackList>
    <Line xmin="{start:g}" ymin="{y_crack:g}" xmax="20" ymax="{y_crack:g}" resolution="{res}" start_tip="-2" end_tip="1"/>
  </CrackList>
  <Material Type="1" Name="aluminum"><rho>2.7</rho><E>70000</E><nu>0.33</nu></Material>
  <ParticleBCs>
    <LdRect xmin="0" xmax="50" ymin="{200 - cell / 2:g}" ymax="200">
      <net/><LoadBC dir="2" style="2" load="1250" time="0"/><LoadBC dir="2" style="2" load="-1250" time="0.4"/>
    </LdRect>
    <LdRect xmin="0" xmax="50" ymin="0" ymax="{cell / 2:g}">
      <net/><LoadBC dir="2" style="2" load="-1250" time="0"/><LoadBC dir="2" style="2" load="1250" time="0.4"/>
    </LdRect>
  </ParticleBCs>
</JANFEAInput>
"""


def run_case(cell: float, gimp: bool, folder: Path) -> list[dict]:
    from nairnmpm_py.input import load_simulation
    path = folder / f"sent_D_{cell:g}mm_{'uGIMP' if gimp else 'linear'}.xml"
    path.write_text(scene(cell, gimp))
    sim = load_simulation(path)
    sim.prepare()
    sim.advance(2)                       # compile outside the timing
    sim2 = load_simulation(path)
    t0 = time.perf_counter()
    sim2.run([])
    wall = time.perf_counter() - t0
    j0 = handbook_j()
    ke = sim2.particles.kinetic_energy() / max(sim2.particles.strain_energy(), 1e-30)
    rows = []
    for r in sim2.cracks.tip_results(sim2, sizes=sim2.cracks.jcontour_sizes):
        rows.append({"shape": "uGIMP" if gimp else "linear", "cell_mm": cell,
                     "particles": sim2.particles.n, "steps": sim2.step,
                     "wall_s": round(wall, 2), "contour_cells": r["contour_cells"],
                     "J_J_m2": r["J_contour_J_m2"], "J0_J_m2": j0,
                     "error_pct": 100.0 * (r["J_contour_J_m2"] / j0 - 1.0),
                     "kinetic_over_strain": ke,
                     # contours that stay a cell inside the specimen (the tip is 20 mm
                     # from its cracked edge) are the ones a user would read
                     "inside_specimen": r["contour_cells"] * cell <= 20.0 - cell,
                     "error": r["error"]})
    return rows


def plot(rows: list[dict], png: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for shape, marker in (("linear", "s"), ("uGIMP", "o")):
        runs = sorted({(r["cell_mm"], r["wall_s"]) for r in rows if r["shape"] == shape},
                      key=lambda v: -v[0])
        if not runs:
            continue
        walls, mid, lo, hi = [], [], [], []
        for cell, wall in runs:
            errs = [abs(r["error_pct"]) for r in rows if r["shape"] == shape
                    and r["cell_mm"] == cell and not r["error"] and r["inside_specimen"]]
            if errs:
                walls.append(wall)
                mid.append(sorted(errs)[len(errs) // 2])
                lo.append(min(errs))
                hi.append(max(errs))
        ax.plot(walls, mid, marker + "-", label=f"{shape} (median over contours)")
        ax.fill_between(walls, lo, hi, alpha=0.2)
        for cell, w, m in zip([c for c, _ in runs], walls, mid):
            ax.annotate(f"{cell:g} mm", (w, m), textcoords="offset points", xytext=(4, 4),
                        fontsize="small")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time (s)")
    ax.set_ylabel("|J / J0 - 1| (%)")
    ax.set_title("Traction-free SENT: J error against cost\n(line: median, band: contours of 2-8 cells inside the specimen)",
                 fontsize="medium")
    ax.grid(alpha=0.3, which="both")
    ax.legend()
    fig.tight_layout()
    fig.savefig(png, dpi=120)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", type=float, nargs="+", default=[4.0, 2.0, 1.0])
    ap.add_argument("--shapes", nargs="+", default=["linear", "uGIMP"])
    ap.add_argument("--threads", type=int, default=numba.config.NUMBA_NUM_THREADS)
    ap.add_argument("--out", default=str(HERE / "results"))
    ap.add_argument("--plot-only", action="store_true",
                    help="redraw the PNG from the CSV already written")
    ap.add_argument("--keep", action="store_true",
                    help="keep the rows already in the CSV for shapes not run now")
    args = ap.parse_args()
    numba.set_num_threads(args.threads)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    work = HERE / "inputs"
    work.mkdir(exist_ok=True)
    rows = []
    csv_path = out / "sent_j_accuracy.csv"
    if args.plot_only:
        args.keep, args.shapes = True, []
    if args.keep and csv_path.exists():
        with open(csv_path) as f:
            for r in csv.DictReader(f):
                if r["shape"] not in args.shapes:
                    for key in ("cell_mm", "wall_s", "J_J_m2", "J0_J_m2", "error_pct",
                                "kinetic_over_strain"):
                        r[key] = float(r[key])
                    for key in ("particles", "steps", "contour_cells"):
                        r[key] = int(r[key])
                    r["inside_specimen"] = r["inside_specimen"] == "True"
                    rows.append(r)
    for shape in args.shapes:
        for cell in args.cells:
            rows += run_case(cell, shape == "uGIMP", work)
            with open(csv_path, "w", newline="") as f:      # rewritten after every run
                w = csv.DictWriter(f, fieldnames=list(rows[0]))
                w.writeheader()
                w.writerows(rows)
            last = [r for r in rows if r["cell_mm"] == cell and r["shape"] == shape]
            print(f"{shape:6s} {cell:g} mm: {last[0]['wall_s']} s, J error "
                  + " ".join(f"{r['error_pct']:+.2f}" for r in last), flush=True)
    plot(rows, out / "sent_j_accuracy.png")
    print(f"wrote {csv_path} and {out / 'sent_j_accuracy.png'}")


if __name__ == "__main__":
    main()
