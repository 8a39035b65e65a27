"""The revised area method (seed section 5.1, Eqs 25-26, Fig 11) on our own DCB output.

    python benchmarks/dcb_area_method.py RESULTS_DIR [--out benchmarks/results] [--name NAME]

RESULTS_DIR is a results folder of ``inputs/dcb_bridging.xml`` (a ``nairnmpm run``, a
sweep member or a ``dcb_cost.py`` run).  A moment-loaded DCB is the area method with
the moment M in place of the load and the arms' opening rotation theta in place of
the load-point displacement: the loads do work M d(theta), so Eq 26 gives
U = [int M d(theta) - M theta / 2] / B and R = dU/da.  From ``global.csv``:

* M = |F| d of the upper arm's outer row (the first two load records), d = ytop - qcs;
* theta = sum over the arms of (mean x displacement of the outer row - that of the
  crack-face row) / d, so that M theta is exactly the work of the axial end forces;

and the crack length a(t) from ``cracks.csv`` (the tip at the latest row at or before
t), over the first 40 mm of growth.  The script compares the area method's R(a) (smoothing-spline slope, and the
discrete Eq 25 points) with the R the simulation reported at each growth step (Eq
15), writes ``dcb_area_method[_NAME].csv`` (per growth step: a, simulated R, spline
R) and ``dcb_fig11[_NAME].png`` (A: M against theta; B: U against a with the spline;
C: R against a), and prints the RMS difference over the growth steps.
"""
from __future__ import annotations

import argparse
import csv
from pathlib import Path

import numpy as np


def entities(results: Path, given: str | None) -> dict:
    """The run's input entities: --input, else the path run.json records (relative to
    the folder the run started in, tried from here and from the results' parent),
    else ``input.xml`` beside the results (sweep members, dcb_cost.py runs)."""
    import json
    from nairnmpm_py.sweep import declared_entities
    recorded = json.loads((results / "run.json").read_text()).get("input", {}).get("path", "")
    candidates = ([Path(given)] if given else []) + (
        [Path(recorded), results.parent / Path(recorded).name] if recorded else []) + [
        results.parent / "input.xml", results / "input.xml"]
    for path in candidates:
        if path.is_file():
            return {k: v for k, (_, v) in declared_entities(path.read_text()).items()}
    raise SystemExit(f"{results}: cannot find the run's input; give it with --input")


def series(results: Path, lever: float):
    """(t, M, theta, a): global archive times, moment, opening rotation, crack length."""
    from nairnmpm_py.analysis.results import read_csv_columns
    cols, g = read_csv_columns(results / "global.csv")
    loads = [c for c in cols if c.startswith("load_N_")]
    disp_x = [c for c in cols if c.startswith("disp_mm_") and c.endswith("_x")]
    # load records in input order: upper outer, upper face, lower outer, lower face
    M = np.hypot(g[loads[0]], g[loads[1]]) * lever
    theta = ((g[disp_x[0]] - g[disp_x[1]]) + (g[disp_x[2]] - g[disp_x[3]])) / lever
    _, c = read_csv_columns(results / "cracks.csv")
    order = np.argsort(c["time_ms"], kind="stable")
    tc, xc = c["time_ms"][order], c["tip_x_mm"][order]
    idx = np.searchsorted(tc, g["time_ms"], side="right") - 1
    # the tip particle also drifts with the material by micrometres: only growth counts
    a = np.round(xc[np.clip(idx, 0, None)], 2)
    return g["time_ms"], M, theta, a, c


def main() -> None:
    from nairnmpm_py.analysis import rcurve as rc
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", help="results folder of inputs/dcb_bridging.xml")
    ap.add_argument("--out", default="benchmarks/results")
    ap.add_argument("--name", default="", help="suffix of the output files")
    ap.add_argument("--input", help="the run's input file (found from run.json if omitted)")
    ap.add_argument("--max-growth", type=float, default=40.0,
                    help="mm of growth used (later the growth runs away under the rising moment)")
    ap.add_argument("--smoothing", default="300",
                    help="spline penalty lambda, or 'gcv'.  GCV follows the dynamic ripple of "
                         "the undamped run (R swinging 0-300 J/m^2), so a fixed penalty is the default")
    args = ap.parse_args()
    results, out = Path(args.results), Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    ent = entities(results, args.input)
    lever = float(ent["ytop"]) - float(ent["qcs"])
    B = 1.0    # mm: the template's thickness
    t, M, theta, a, c = series(results, lever)
    keep = a <= a[0] + args.max_growth
    t, M, theta, a = t[keep], M[keep], theta[keep], a[keep]
    smoothing = args.smoothing if args.smoothing == "gcv" else float(args.smoothing)
    fit = rc.R_from_area_method(theta, M, a, B, smoothing=smoothing)
    a_mid, R_disc = rc.discrete_area_method(theta, M, a, B)
    grew = (c["event"] == "growth") & (c["tip_x_mm"] <= a[0] + args.max_growth)
    a_sim, R_sim = c["tip_x_mm"][grew], c["R_J_m2"][grew]
    inside = (a_sim > fit.a[1]) & (a_sim < fit.a[-2])
    R_fit = fit.R_at(a_sim)
    rms = float(np.sqrt(np.mean((R_fit[inside] - R_sim[inside]) ** 2)))
    mean_sim = float(np.mean(R_sim[inside]))
    mean_fit = float(np.mean(R_fit[inside]))
    suffix = f"_{args.name}" if args.name else ""
    with open(out / f"dcb_area_method{suffix}.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["a_mm", "R_simulated_J_m2", "R_area_method_J_m2"])
        for row in zip(a_sim, R_sim, R_fit):
            w.writerow([f"{v:.6g}" for v in row])
    fig, ax = plt.subplots(1, 3, figsize=(13, 4))
    ax[0].plot(theta, M)
    ax[0].set_xlabel("arm opening rotation theta (rad)")
    ax[0].set_ylabel("moment M (N mm)")
    ax[0].set_title("A")
    ax[1].plot(fit.a, fit.U, ".", ms=3, label="Eq 26")
    aa = np.linspace(fit.a[0], fit.a[-1], 300)
    ax[1].plot(aa, fit.spline(aa), "-", label="smoothing spline")
    ax[1].set_xlabel("crack length a (mm)")
    ax[1].set_ylabel("U (J/m)")
    ax[1].set_title("B")
    ax[1].legend(fontsize="small")
    ax[2].plot(a_sim, R_sim, ".", ms=3, label="simulated (Eq 15)")
    ax[2].plot(aa, fit.R_at(aa), "-", label="area method: spline slope")
    ax[2].plot(a_mid, R_disc, "x", ms=3, label="area method: Eq 25")
    ax[2].set_xlabel("crack length a (mm)")
    ax[2].set_ylabel("R (J/m^2)")
    ax[2].set_ylim(0, 1.5 * max(np.nanmax(R_sim), 1.0))
    ax[2].set_title("C")
    ax[2].legend(fontsize="small")
    for x in ax:
        x.grid(alpha=0.3)
    fig.suptitle(f"Area method on the simulated DCB ({results}): mean R {mean_fit:.1f} against "
                 f"{mean_sim:.1f} J/m^2 simulated; RMS difference {rms:.1f} J/m^2", fontsize="small")
    fig.tight_layout()
    fig.savefig(out / f"dcb_fig11{suffix}.png", dpi=120)
    print(f"{len(a_sim)} growth steps; area method against simulated R over {int(inside.sum())} "
          f"of them: mean {mean_fit:.1f} against {mean_sim:.1f} J/m^2 "
          f"({100 * (mean_fit / mean_sim - 1):+.1f} %), RMS difference {rms:.1f} J/m^2")


if __name__ == "__main__":
    main()
