"""The seed paper's Fig 3: J(x), J_tip and J_ff against the contour size for the SENT
specimen with (A) linear tractions over the whole crack, (B) over the 10 mm nearest
the tip, (C) a triangular law over 7.5 mm, (D) no tractions, normalised by the
handbook J0 of the traction-free specimen.

    python benchmarks/sent_fig3.py                  # the inputs as shipped (2 mm cells)
    python benchmarks/sent_fig3.py --threads 2 --out benchmarks/results

Runs ``inputs/sent_fig3_{A,B,C,D}.xml`` (each writes jcontours.csv for contours of
half-size 1-8 cells) and writes ``OUT/sent_fig3.csv`` (case, contour half-size in mm,
J(x), J_tip, J_ff, W_B at the root, all J/m^2 and over J0) and ``OUT/sent_fig3.png``.
J0 = 354.9 J/m^2 (Tada, Paris and Irwin; see sent_j_accuracy.py).
"""
from __future__ import annotations

import argparse
import csv
import tempfile
from pathlib import Path

import numba

HERE = Path(__file__).resolve().parent
INPUTS = HERE.parent / "inputs"
J0 = 354.88


def run_case(case: str, folder: Path) -> list[dict]:
    from nairnmpm_py.cli import main
    out = folder / case
    code = main(["run", str(INPUTS / f"sent_fig3_{case}.xml"), "-o", str(out), "-q", "--force"])
    if code != 0:
        raise SystemExit(f"case {case} failed with exit code {code}")
    with open(out / "jcontours.csv") as f:
        rows = list(csv.DictReader(f))
    t_end = max(float(r["time_ms"]) for r in rows)
    cell = 2.0
    result = []
    for r in rows:
        if float(r["time_ms"]) != t_end or r["error"]:
            continue
        result.append({"case": case, "contour_mm": int(r["contour_cells"]) * cell,
                       "J_x": float(r["J_contour_J_m2"]), "J_tip": float(r["J_tip_J_m2"]),
                       "J_ff": float(r["J_ff_J_m2"]), "W_B_root": float(r["W_B_root_J_m2"]),
                       "zone_mm": float(r["zone_length_mm"])})
    return result


def plot(rows: list[dict], png: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 2, figsize=(9, 7), sharex=True)
    for ax, case in zip(axes.ravel(), "ABCD"):
        rs = sorted((r for r in rows if r["case"] == case), key=lambda r: r["contour_mm"])
        if not rs:
            continue
        x = [r["contour_mm"] for r in rs]
        ax.plot(x, [r["J_x"] / J0 for r in rs], "o-", label="J(x)")
        if case != "D":
            ax.plot(x, [r["J_tip"] / J0 for r in rs], "s--", label="J_tip")
            if case != "A":
                ax.plot(x, [r["J_ff"] / J0 for r in rs], "^:", label="J_ff")
                ax.axvline(rs[0]["zone_mm"], color="gray", ls=":", lw=1)
        ax.set_title(f"Fig 3{case}")
        ax.grid(alpha=0.3)
        ax.legend(fontsize="small")
    for ax in axes[1]:
        ax.set_xlabel("contour half-size (mm)")
    for ax in axes[:, 0]:
        ax.set_ylabel("J / J0")
    fig.tight_layout()
    fig.savefig(png, dpi=120)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, default=numba.config.NUMBA_NUM_THREADS)
    ap.add_argument("--out", default=str(HERE / "results"))
    args = ap.parse_args()
    numba.set_num_threads(args.threads)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for case in "ABCD":
            rows += run_case(case, Path(tmp))
            print(f"case {case} done", flush=True)
    with open(out / "sent_fig3.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]) + ["J_x_over_J0", "J_tip_over_J0",
                                                          "J_ff_over_J0"])
        w.writeheader()
        for r in rows:
            w.writerow({**r, "J_x_over_J0": r["J_x"] / J0, "J_tip_over_J0": r["J_tip"] / J0,
                        "J_ff_over_J0": r["J_ff"] / J0})
    plot(rows, out / "sent_fig3.png")
    print(f"wrote {out / 'sent_fig3.csv'} and {out / 'sent_fig3.png'}")


if __name__ == "__main__":
    main()
