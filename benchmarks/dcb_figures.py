"""The seed paper's DCB figures (7, 8, 9, 10) from a sweep of ``inputs/dcb_bridging.xml``.

    nairnmpm sweep inputs/dcb_bridging.xml inputs/dcb_family.csv -o dcb_family
    python benchmarks/dcb_figures.py dcb_family --out benchmarks/results

Reads each member's ``cracks.csv`` (growth rows) and ``global.csv`` and the member's
entities from the sweep's ``summary.csv`` (J_tip,c, J_B, sigma_c, Tprop), and draws

* Fig 7: R against the opening at the notch root, Eq 22 dashed (bridging and
  cohesive members);
* Fig 8A/9A: moment against the load-line opening of the arms (8: bridging members,
  9: cohesive members, J_tip,c < 10 J/m^2; both with the fracture-mechanics members
  dotted, as the paper's);
* Fig 8B/9B: R against crack growth, the same members;
* Fig 10: bridging-zone length against the moment;

into ``OUT/dcb_fig7.png`` ... ``dcb_fig10.png`` and a CSV of the checks of issue 4:
R on the plateau against J_tip,c + J_B, the RMS of R - Eq 22 over delta/delta_c in
0.1-0.95 in percent of J_tip,c, the median J_tip at growth, and the steady zone length.
The moment on each arm is global.csv's ``moment_Nmm_`` column of that arm (the
moment of the arm's two loaded rows; results written before those columns existed
need a rerun).
"""
from __future__ import annotations

import argparse
import csv
from pathlib import Path

import numpy as np


def members(folder: Path) -> list[dict]:
    with open(folder / "summary.csv") as f:
        rows = list(csv.DictReader(f))
    out = []
    for r in rows:
        d = folder / r["name"]
        if not (d / "cracks.csv").exists():
            continue
        out.append({**r, "folder": d})
    return out


def growth_rows(d: Path) -> dict[str, np.ndarray]:
    from nairnmpm_py.analysis.results import read_csv_columns
    _, c = read_csv_columns(d / "cracks.csv")
    keep = c["event"] == "growth"
    return {k: v[keep] for k, v in c.items()}


def load_line_opening(d: Path) -> tuple[np.ndarray, np.ndarray]:
    """(time ms, opening mm) from the y displacements of the two loaded crack-face
    particles (upper arm minus lower arm)."""
    from nairnmpm_py.analysis.results import read_csv_columns
    cols, g = read_csv_columns(d / "global.csv")
    disp = [c for c in cols if c.startswith("disp_mm_") and c.endswith("_y")]
    # the four y loads in input order: upper top, upper face, lower bottom, lower face
    opening = g[disp[1]] - g[disp[3]]
    return g["time_ms"], opening


def moment(d: Path) -> tuple[np.ndarray, np.ndarray]:
    """(time ms, moment N mm on the upper arm): global.csv's first ``moment_Nmm_``
    column (one per arm; the upper arm's rows come first in the template)."""
    from nairnmpm_py.analysis.results import read_csv_columns
    cols, g = read_csv_columns(d / "global.csv")
    arm = next(c for c in cols if c.startswith("moment_Nmm_"))
    return g["time_ms"], np.abs(g[arm])


def main() -> None:
    from nairnmpm_py.analysis.rcurve import R_cubic
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("sweep", help="folder written by nairnmpm sweep")
    ap.add_argument("--out", default="benchmarks/results")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    ms = members(Path(args.sweep))
    figs = {k: plt.subplots(figsize=(6.4, 4.6)) for k in ("7", "8A", "8B", "9A", "9B", "10")}
    checks = []
    for m in ms:
        jc, jb, sc = float(m["Jtipc"]), float(m["JB"]), float(m["sigc"])
        bridged = int(float(m["tprop"])) > 0
        dc = 16.0 * jb / (9.0 * sc) / 1000.0
        g = growth_rows(m["folder"])
        if len(g["time_ms"]) == 0:
            checks.append({"name": m["name"], "growth_steps": 0})
            continue
        label = m["name"]
        R = g["R_J_m2"]
        d0 = g["cod_notch0_mm"]
        t, opening = load_line_opening(m["folder"])
        tm, mom = moment(m["folder"])
        if not bridged:      # fracture mechanics: dotted in both figures
            panels, style = ("8", "9"), ":"
        else:
            panels, style = ("9",) if jc < 10.0 else ("8",), "-"
        for fig_no in panels:
            figs[fig_no + "A"][1].plot(opening, np.interp(t, tm, mom), style, label=label)
            figs[fig_no + "B"][1].plot(g["crack_growth_mm"], R, "." + style, label=label)
        if bridged:
            ax = figs["7"][1]
            line, = ax.plot(d0 / dc, R / (jc + jb), ".", label=label)
            x = np.linspace(0, 1.5, 200)
            ax.plot(x, R_cubic(x * dc, jc, jb, dc) / (jc + jb), "--", color=line.get_color(), lw=1)
            figs["10"][1].plot(np.interp(g["time_ms"], tm, mom), g["zone_length_mm"], ".-", label=label)
        total = jc + (jb if bridged else 0.0)
        plateau = (d0 > 1.2 * dc) if bridged else np.ones(len(R), dtype=bool)
        rising = bridged & (d0 > 0.1 * dc) & (d0 < 0.95 * dc)
        rms = (float(np.sqrt(np.mean((R[rising] - R_cubic(d0[rising], jc, jb, dc)) ** 2))) / jc * 100
               if bridged and np.any(rising) else float("nan"))
        checks.append({
            "name": label, "growth_steps": int(len(R)),
            "growth_mm": float(g["crack_growth_mm"][-1]),
            "initiation_ms": float(g["time_ms"][0]),
            "median_J_tip_at_growth": float(np.median(g["J_tip_J_m2"])),
            "R_plateau_mean": float(np.mean(R[plateau])) if np.any(plateau) else float("nan"),
            "R_expected": total,
            "R_plateau_error_pct": (float(np.mean(R[plateau])) / total - 1) * 100 if np.any(plateau) else float("nan"),
            "R_minus_eq22_rms_pct_of_Jtipc": rms,
            "steady_zone_mm": float(np.median(g["zone_length_mm"][plateau])) if np.any(plateau) else float("nan"),
        })
    labels = {"7": ("COD at the notch root / delta_c", "R / (J_tip,c + J_B)"),
              "8A": ("load-line opening (mm)", "moment M (N mm)"),
              "8B": ("crack growth (mm)", "R (J/m^2)"),
              "9A": ("load-line opening (mm)", "moment M (N mm)"),
              "9B": ("crack growth (mm)", "R (J/m^2)"),
              "10": ("moment M (N mm)", "bridging zone length (mm)")}
    figs["7"][1].set_xlim(0, 3)
    for key, (fig, ax) in figs.items():
        ax.set_xlabel(labels[key][0])
        ax.set_ylabel(labels[key][1])
        ax.grid(alpha=0.3)
        ax.legend(fontsize="x-small")
        fig.tight_layout()
        fig.savefig(out / f"dcb_fig{key}.png", dpi=120)
    with open(out / "dcb_checks.csv", "w", newline="") as f:
        keys = sorted({k for c in checks for k in c}, key=lambda k: (k != "name", k))
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(checks)
    for c in checks:
        print(c)


if __name__ == "__main__":
    main()
