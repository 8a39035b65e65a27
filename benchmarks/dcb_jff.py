"""J_ff before growth on the seed paper's DCB against beam theory (issue 4's first check).

    python benchmarks/dcb_jff.py [--spacings 1 0.5 0.25] [--threads 2] [--out benchmarks/results]

Runs ``inputs/dcb_bridging.xml`` to 10 ms with J_tip,c raised out of reach (the crack
does not grow; the moment is the template's), reads J_ff on the template's contour
(half-size 2) every 0.02 ms and compares it with 12 M^2 / (b^2 E h^3) (plane stress;
M from the arm's ``moment_Nmm_`` column of global.csv).  The check is the ratio of
the 1-ms means of the two, for each millisecond from 1 to 10 ms.

Writes ``dcb_jff.csv`` (spacing, window, ratio) and ``dcb_jff.png`` (J_ff / beam
theory against time, and the 1-ms means) to --out.  About 5 minutes at 0.25 mm
(the paper's resolution), seconds at 1 mm.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from csv_rows import write_rows

ROOT = Path(__file__).resolve().parents[1]
E, H, B = 2500.0, 6.0, 1.0          # MPa, mm (arm depth), mm (thickness)
SAMPLE_MS = 0.02


class JffSampler:
    """Output plugin: J_ff at the tip and the upper arm's moment at each global row."""

    def __init__(self):
        self.t, self.J, self.M = [], [], []

    def begin(self, sim):
        pass

    def on_global(self, sim, row):
        arm = next(k for k in row if k.startswith("moment_Nmm_"))
        self.t.append(sim.time)
        self.J.append(sim.cracks.tip_results(sim)[0]["J_ff_J_m2"])
        self.M.append(abs(row[arm]))

    def on_archive(self, sim):
        pass

    def end(self, sim, status):
        pass


def run(spacing: float, work: Path) -> dict[str, np.ndarray]:
    from dcb_cost import TEMPLATE, entities
    from nairnmpm_py.input import load_simulation
    from nairnmpm_py.sweep import member_input
    values = entities(spacing, 10.0)
    values["Jtipc"] = "1e6"          # no growth: J_ff over the whole ramp
    text = member_input(TEMPLATE.read_text(), values, TEMPLATE)
    text = text.replace('<GlobalArchiveTime units="ms">0.1</GlobalArchiveTime>',
                        f'<GlobalArchiveTime units="ms">{SAMPLE_MS:g}</GlobalArchiveTime>')
    work.mkdir(parents=True, exist_ok=True)
    path = work / f"dcb_jff_{spacing:g}mm.xml"
    path.write_text(text)
    sim = load_simulation(path)
    sampler = JffSampler()
    sim.run([sampler])
    t, J, M = (np.array(v) for v in (sampler.t, sampler.J, sampler.M))
    return {"t": t, "J": J, "theory": 12.0 * M ** 2 / (B ** 2 * E * H ** 3) * 1000.0}


def window_ratios(r: dict[str, np.ndarray]) -> list[float]:
    out = []
    for k in range(1, 10):
        sel = (r["t"] > k) & (r["t"] <= k + 1)
        out.append(float(r["J"][sel].mean() / r["theory"][sel].mean()))
    return out


def main() -> None:
    import sys
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spacings", type=float, nargs="+", default=[1.0, 0.5, 0.25],
                    help="particle spacings (mm); cells are twice as large")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--work", default="/tmp/dcb_jff")
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "results"))
    args = ap.parse_args()
    import numba
    numba.set_num_threads(args.threads)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    results, rows = {}, []
    for spacing in args.spacings:
        r = run(spacing, Path(args.work))
        results[spacing] = r
        ratios = window_ratios(r)
        print(f"{spacing:g} mm particles: " + " ".join(f"{x:.3f}" for x in ratios), flush=True)
        rows += [{"spacing_mm": spacing, "cell_mm": 2 * spacing, "window_ms": f"{k + 1}-{k + 2}",
                  "J_ff_over_beam_theory": round(x, 4)} for k, x in enumerate(ratios)]
    write_rows(out / "dcb_jff.csv", rows)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4))
    for spacing, r in results.items():
        late = r["t"] > 1.0
        line, = ax.plot(r["t"][late], r["J"][late] / r["theory"][late], lw=0.6, alpha=0.5)
        ax.plot(np.arange(1, 10) + 0.5, window_ratios(r), "o-", color=line.get_color(),
                label=f"{spacing:g} mm particles ({2 * spacing:g} mm cells): 1-ms means")
    ax.axhspan(0.98, 1.02, color="0.9", zorder=0, label="2 %")
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("J_ff / (12 M^2 / (b^2 E h^3))")
    ax.set_ylim(0.8, 1.2)
    ax.set_title("DCB before growth: J_ff against beam theory")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "dcb_jff.png", dpi=130)
    print(f"wrote {out / 'dcb_jff.csv'} and {out / 'dcb_jff.png'}")


if __name__ == "__main__":
    main()
