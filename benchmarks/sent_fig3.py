"""The seed paper's Fig 3: J(x), J_tip and J_ff against the contour size for the SENT
specimen with (A) linear tractions over the whole crack, (B) over the 10 mm nearest
the tip, (C) a triangular law over 7.5 mm, (D) no tractions, normalised by the
handbook J0 of the traction-free specimen.

    python benchmarks/sent_fig3.py                  # the inputs as shipped (2 mm cells)
    python benchmarks/sent_fig3.py --threads 2 --out benchmarks/results
    python benchmarks/sent_fig3.py --cell 1         # finer: 40,000 particles, 1 mm cells

Runs ``inputs/sent_fig3_{A,B,C,D}.xml`` (each writes jcontours.csv for contours of
half-size 2-16 mm; with ``--cell 1`` the grid moves half a cell so that the crack line
and tip stay mid-cell) and writes ``OUT/sent_fig3[_cell1].csv`` (case, contour half-size in mm,
J(x), J_tip, J_ff, W_B at the root, all J/m^2 and over J0) and ``OUT/sent_fig3.png``.
J0 = 354.9 J/m^2 (Tada, Paris and Irwin; see sent_j_accuracy.py).
"""
from __future__ import annotations

import argparse
import csv
import tempfile
from pathlib import Path

import numba

from csv_rows import write_rows

HERE = Path(__file__).resolve().parent
INPUTS = HERE.parent / "inputs"
J0 = 354.88


def case_input(case: str, cell: float, folder: Path) -> Path:
    """The shipped input, or a copy with ``cell`` mm cells, the grid shifted to keep the
    crack line (y = 101) and tip (x = 20) mid-cell, and contours of the same 2-16 mm."""
    path = INPUTS / f"sent_fig3_{case}.xml"
    if cell == 2.0:
        return path
    if cell != 1.0:
        raise SystemExit("--cell must be 2 or 1")
    text = path.read_text()
    for old, new in (('<!ENTITY cs "2">', '<!ENTITY cs "1">'),
                     ('xmin="-5" xmax="55" ymin="-4" ymax="204"',
                      'xmin="-5.5" xmax="55.5" ymin="-4.5" ymax="204.5"'),
                     ("<JContourSizes>1 2 3 4 5 6 7 8</JContourSizes>",
                      "<JContourSizes>2 4 6 8 10 12 14 16</JContourSizes>")):
        if old not in text:
            raise SystemExit(f"{path.name}: cannot refine, '{old}' not found")
        text = text.replace(old, new)
    copy = folder / path.name
    copy.write_text(text)
    return copy


def run_case(case: str, folder: Path, cell: float = 2.0) -> list[dict]:
    from nairnmpm_py.cli import main
    out = folder / case
    code = main(["run", str(case_input(case, cell, folder)), "-o", str(out), "-q", "--force"])
    if code != 0:
        raise SystemExit(f"case {case} failed with exit code {code}")
    with open(out / "jcontours.csv") as f:
        rows = list(csv.DictReader(f))
    t_end = max(float(r["time_ms"]) for r in rows)
    result = []
    for r in rows:
        if float(r["time_ms"]) != t_end or r["error"]:
            continue
        result.append({"case": case, "contour_mm": int(r["contour_cells"]) * cell,
                       "J_x": float(r["J_contour_J_m2"]), "J_tip": float(r["J_tip_J_m2"]),
                       "J_ff": float(r["J_ff_J_m2"]), "W_B_root": float(r["W_B_root_J_m2"]),
                       "zone_mm": float(r["zone_length_mm"]),
                       "W_B_crossing": float(r["W_B_crossing_J_m2"])})
    return result


def checks(rows: list[dict]) -> list[dict]:
    """Issue 3's checks per case: the spread of J_tip and J_ff over contours of 4 mm and
    more (a 2 mm contour is one cell from the tip at 2 mm cells), and Eq 11 from
    independent contours, J(x) enclosing the zone less J_tip crossing it, against
    W_B(x_root) from the root's opening."""
    out = []
    for case in "ABCD":
        rs = [r for r in rows if r["case"] == case and r["contour_mm"] >= 4.0]
        if not rs:
            continue
        tip = [r["J_tip"] for r in rs]
        ff = [r["J_ff"] for r in rs]
        row = {"case": case, "J_tip_spread_pct": 100 * (max(tip) - min(tip)) / (sum(tip) / len(tip)),
               "J_ff_spread_pct": 100 * (max(ff) - min(ff)) / (sum(ff) / len(ff)),
               "W_B_root": rs[0]["W_B_root"], "eq11_difference": float("nan"),
               "eq11_error_pct": float("nan")}
        # crossing the zone or enclosing it, as the J code decided
        inside = [r for r in rs if r["W_B_crossing"] > 0]
        outside = [r for r in rs if r["W_B_crossing"] == 0]
        if case in "BC" and inside and outside:
            diff = (sum(r["J_x"] for r in outside) / len(outside)
                    - sum(r["J_tip"] for r in inside) / len(inside))
            row["eq11_difference"] = diff
            row["eq11_error_pct"] = 100 * (diff / row["W_B_root"] - 1)
        out.append(row)
    return out


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
    ap.add_argument("--cell", type=float, default=2.0, help="cell size, mm: 2 (as shipped) or 1")
    args = ap.parse_args()
    numba.set_num_threads(args.threads)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for case in "ABCD":
            rows += run_case(case, Path(tmp), args.cell)
            print(f"case {case} done", flush=True)
    stem = "sent_fig3" if args.cell == 2.0 else f"sent_fig3_cell{args.cell:g}"
    with open(out / f"{stem}.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]) + ["J_x_over_J0", "J_tip_over_J0",
                                                          "J_ff_over_J0"])
        w.writeheader()
        for r in rows:
            w.writerow({**r, "J_x_over_J0": r["J_x"] / J0, "J_tip_over_J0": r["J_tip"] / J0,
                        "J_ff_over_J0": r["J_ff"] / J0})
    summary = checks(rows)
    write_rows(out / f"{stem}_checks.csv", summary)
    for r in summary:
        print("  ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}"
                        for k, v in r.items()))
    plot(rows, out / f"{stem}.png")
    print(f"wrote {out / stem}.csv, {stem}_checks.csv and {stem}.png")


if __name__ == "__main__":
    main()
