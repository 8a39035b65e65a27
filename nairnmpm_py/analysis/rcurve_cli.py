"""``nairnmpm rcurve``: a thin command layer over ``analysis.rcurve``.

    nairnmpm rcurve theory --law Cubic --param sigmaI=1.0 --param JIc=100 --jtip 100
                           [--mode I] [--points 101] [--out R.csv] [--plot R.png]
    nairnmpm rcurve fig5 [--out fig5.png] [--csv fig5.csv]
    nairnmpm rcurve invert --csv R.csv [--smoothing gcv|LAMBDA] [--out sigma.csv] [--plot sigma.png]
    nairnmpm rcurve area --csv data.csv --thickness B [--smoothing gcv|LAMBDA]
                         [--out area.csv] [--plot area.png]

CSV columns in: ``delta_mm, R_J_m2`` (invert); ``d_mm, F_N, a_mm`` (area).
Units: mm, MPa, N, J/m^2 (J/m for U, energy per unit thickness).
``cli.py`` wires this in with ``add_parser(subparsers)``; the parser's default
``func`` is ``run``.  Exit codes: 0 done, 2 bad input (one line per problem).
"""
from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

import numpy as np
from pydantic import ValidationError

from .. import plugins

# the theory (through scipy) and matplotlib are imported where used: every command
# builds this parser, and importing them here cost ``nairnmpm run`` 1.8 s each time

EXIT_OK, EXIT_INPUT = 0, 2


class BadInput(Exception):
    """A problem with the command's input, reported as one line and exit code 2."""


# ---- parser --------------------------------------------------------------------------------
def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "rcurve", help="R-curve theory, Eq 18 inversion and the area method",
        description="R curves for cracks with bridging zones (Nairn's Eqs 14-27) from any "
                    "registered traction law, traction-law inversion and the area method.")
    sub = p.add_subparsers(dest="rcurve_command", required=True, metavar="ACTION")

    t = sub.add_parser("theory", help="R, R_eff, W_B, W_B^r against COD for a traction law")
    t.add_argument("--law", required=True, help="traction law name or NairnMPM Type number")
    t.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="a law parameter as in the XML (MPa, mm, J/m^2); repeat")
    t.add_argument("--jtip", type=float, required=True, help="crack-tip toughness J_tip,c (J/m^2)")
    t.add_argument("--mode", default="I", choices=["I", "II"], help="traction mode (default I)")
    t.add_argument("--points", type=int, default=101, help="COD grid points over 0..delta_c")
    t.add_argument("--out", help="write the table to this CSV (default: print it)")
    t.add_argument("--plot", help="write a PNG of the law and its R curves")

    f = sub.add_parser("fig5", help="the paper's Fig 5 (triangular vs cubic R, cubic R_eff)")
    f.add_argument("--out", default="fig5.png", help="PNG to write (default fig5.png)")
    f.add_argument("--csv", help="also write the curves to this CSV")

    i = sub.add_parser("invert", help="traction law from an R(delta) curve by Eq 18")
    i.add_argument("--csv", required=True, help="CSV with columns delta_mm, R_J_m2")
    i.add_argument("--smoothing", default=None,
                   help="differentiate R with a smoothing spline: 'gcv' or a penalty "
                        "(default: finite differences)")
    i.add_argument("--out", help="CSV to write (default: <input>_traction.csv)")
    i.add_argument("--plot", help="also write a PNG of R and sigma")

    a = sub.add_parser("area", help="R(a) by the area method (Eq 26 spline slope and Eq 25)")
    a.add_argument("--csv", required=True, help="CSV with columns d_mm, F_N, a_mm")
    a.add_argument("--thickness", "-B", type=float, required=True, help="specimen thickness B (mm)")
    a.add_argument("--smoothing", default="gcv",
                   help="smoothing-spline penalty for U(a): 'gcv' (default) or a number")
    a.add_argument("--out", help="CSV to write (default: <input>_area.csv)")
    a.add_argument("--plot", help="PNG to write (default: <input>_area.png)")

    p.set_defaults(func=run)
    return p


def run(args) -> int:
    actions = {"theory": _theory, "fig5": _fig5, "invert": _invert, "area": _area}
    try:
        return actions[args.rcurve_command](args)
    except BadInput as exc:
        for line in str(exc).splitlines():
            print(line, file=sys.stderr)
        return EXIT_INPUT


# ---- theory ---------------------------------------------------------------------------------
def build_law(name: str, params: list[str]):
    """A traction law from its name or Type number and NAME=VALUE strings."""
    info = plugins.resolve("traction_laws", name)
    if info is None:
        known = ", ".join(f"{p.name}" + (f" ({p.nairn_type})" if p.nairn_type else "")
                          for p in plugins.registry("traction_laws"))
        raise BadInput(f"--law {name}: no traction law of that name or type (installed: {known})")
    values = {}
    for item in params:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise BadInput(f"--param {item}: expected NAME=VALUE")
        if key in values:
            raise BadInput(f"--param {key} given twice")
        try:
            values[key] = float(text)
        except ValueError:
            raise BadInput(f"--param {item}: {text!r} is not a number") from None
    try:
        return info.cls(info.cls.Params(**values))
    except ValidationError as exc:
        lines = []
        for e in exc.errors():
            msg = e["msg"].removeprefix("Value error, ")
            where = f" {e['loc'][0]}" if e["loc"] else ""
            if e["type"] == "extra_forbidden":
                msg = f"not a parameter of this law (allowed: {', '.join(info.cls.Params.model_fields)})"
            lines.append(f"--law {info.name}:{where}: {msg}" if where else f"--law {info.name}: {msg}")
        raise BadInput("\n".join(lines)) from None


def theory_table(law, J_tip_c: float, mode="I", points: int = 101) -> dict[str, np.ndarray]:
    """Columns of the theory table on a COD grid 0..delta_c (units in the names)."""
    from . import rcurve as rc
    env = law.mode(mode)
    d = np.linspace(0.0, env.delta_c, max(points, 2))
    table = {
        "delta_mm": d,
        "delta_over_delta_c": d / env.delta_c,
        "sigma_MPa": np.where(d < env.delta_c, env(d), 0.0),
        "W_B_J_m2": law.work_to(d, mode),
        "W_B_rec_J_m2": law.recoverable(d, mode),
        "R_J_m2": rc.R_of_delta(law, d, J_tip_c, mode),
        "R_eff_J_m2": rc.R_eff_of_delta(law, d, J_tip_c, mode),
        "dR_ddelta_J_m2_per_mm": rc.dR_ddelta(law, d, mode),
    }
    closed = rc.closed_form_R(law, d, J_tip_c, mode)
    if closed is not None:
        table["R_closed_form_J_m2"] = closed
    closed = rc.closed_form_R_eff(law, d, J_tip_c, mode)
    if closed is not None:
        table["R_eff_closed_form_J_m2"] = closed
    return table


def _summary(law, mode, J_tip_c) -> str:
    env = law.mode(mode)
    kind = f"{law.name}" + (f" (NairnMPM Type {law.nairn_type})" if law.nairn_type else "")
    return (f"# {kind}, mode {mode}: delta_c = {env.delta_c:.6g} mm, peak {env.peak_stress:.6g} MPa "
            f"at {env.peak_delta:.6g} mm, J_B = {env.area:.6g} J/m^2; J_tip,c = {J_tip_c:.6g} J/m^2, "
            f"steady state R = {J_tip_c + env.area:.6g} J/m^2")


def _theory(args) -> int:
    law = build_law(args.law, args.param)
    if not law.has_mode(args.mode):
        raise BadInput(f"--mode {args.mode}: law {law.name} has no mode {args.mode} tractions "
                       f"with these parameters")
    table = theory_table(law, args.jtip, args.mode, args.points)
    print(_summary(law, args.mode, args.jtip))
    if args.out:
        write_csv(args.out, table)
        print(f"wrote {args.out}")
    else:
        _write_rows(sys.stdout, table)
    if args.plot:
        plot_theory(law, table, args.mode, args.jtip, args.plot)
        print(f"wrote {args.plot}")
    return EXIT_OK


# ---- fig5 -----------------------------------------------------------------------------------
def _fig5(args) -> int:
    from . import rcurve as rc
    curves = rc.fig5_curves()
    plot_fig5(curves, args.out)
    print(f"wrote {args.out}")
    if args.csv:
        write_csv(args.csv, {"delta_over_delta_c": curves["x"],
                             "R_over_Jtip_triangular": curves["R_triangular"],
                             "R_over_Jtip_cubic": curves["R_cubic"],
                             "R_eff_over_Jtip_cubic": curves["R_eff_cubic"]})
        print(f"wrote {args.csv}")
    return EXIT_OK


# ---- invert ---------------------------------------------------------------------------------
def _invert(args) -> int:
    from . import rcurve as rc
    cols = read_csv(args.csv, ("delta_mm", "R_J_m2"))
    d, R = cols["delta_mm"], cols["R_J_m2"]
    order = np.argsort(d)
    d, R = d[order], R[order]
    if len(d) < 3 or np.any(np.diff(d) <= 0) or d[0] < 0:
        raise BadInput(f"{args.csv}: delta_mm must hold at least 3 distinct values >= 0")
    smoothing = _smoothing(args.smoothing)
    try:
        Rp = rc.derivative(d, R, smoothing)
    except ValueError as exc:
        raise BadInput(f"{args.csv}: {exc}") from None
    sigma = rc.invert_traction(d, Rp)
    table = {"delta_mm": d, "R_J_m2": R, "dR_ddelta_J_m2_per_mm": Rp, "sigma_MPa": sigma}
    out = args.out or str(_beside(args.csv, "_traction.csv"))
    write_csv(out, table)
    k = int(np.argmax(sigma))
    print(f"# Eq 18: peak {sigma[k]:.6g} MPa at {d[k]:.6g} mm; R rises {R[-1] - R[0]:.6g} J/m^2 "
          f"(J_B if the data reach steady state)")
    print(f"wrote {out}")
    if args.plot:
        plot_inversion(table, args.plot)
        print(f"wrote {args.plot}")
    return EXIT_OK


# ---- area method ------------------------------------------------------------------------------
def area_table(d, F, a, B: float, smoothing="gcv"):
    """Per-row table of the area method plus the spline fit and the Eq 25 points."""
    from . import rcurve as rc
    fit = rc.R_from_area_method(d, F, a, B, smoothing=smoothing)
    a_mid, R_disc = rc.discrete_area_method(d, F, a, B)
    disc_rows = np.full(len(d), np.nan)
    grew = np.flatnonzero(np.diff(a) > 0)
    disc_rows[grew + 1] = R_disc  # Eq 25 from the previous row to this one
    table = {"d_mm": d, "F_N": F, "a_mm": a, "U_J_m": rc.area_method_U(d, F, B),
             "R_spline_J_m2": fit.R_at(a), "R_discrete_J_m2": disc_rows}
    return table, fit, (a_mid, R_disc)


def _area(args) -> int:
    if not args.thickness > 0:
        raise BadInput(f"--thickness must be > 0 (got {args.thickness:g})")
    cols = read_csv(args.csv, ("d_mm", "F_N", "a_mm"))
    smoothing = _smoothing(args.smoothing)
    try:
        table, fit, discrete = area_table(cols["d_mm"], cols["F_N"], cols["a_mm"], args.thickness,
                                          "gcv" if smoothing is None else smoothing)
    except ValueError as exc:
        raise BadInput(f"{args.csv}: {exc}") from None
    out = args.out or str(_beside(args.csv, "_area.csv"))
    png = args.plot or str(_beside(args.csv, "_area.png"))
    write_csv(out, table)
    plot_area(table, fit, discrete, png)
    print(f"# area method: R from {fit.R.min():.6g} to {fit.R.max():.6g} J/m^2 over "
          f"a = {fit.a[0]:.6g}..{fit.a[-1]:.6g} mm ({len(fit.a)} crack lengths)")
    print(f"wrote {out}")
    print(f"wrote {png}")
    return EXIT_OK


# ---- files ------------------------------------------------------------------------------------
def _beside(path, suffix: str) -> Path:
    p = Path(path)
    return p.with_name(p.stem + suffix)


def _smoothing(text):
    if text is None or str(text).lower() == "gcv":
        return None if text is None else "gcv"
    try:
        value = float(text)
    except ValueError:
        raise BadInput(f"--smoothing {text}: expected 'gcv' or a number") from None
    if value < 0:
        raise BadInput(f"--smoothing must be >= 0 (got {value:g})")
    return value


def read_csv(path, columns: tuple[str, ...]) -> dict[str, np.ndarray]:
    """Named float columns of a CSV with a header row (other columns are ignored)."""
    try:
        with open(path, newline="") as fh:
            rows = [r for r in csv.reader(fh) if r and not r[0].lstrip().startswith("#")]
    except OSError as exc:
        raise BadInput(f"{path}: {exc.strerror}") from None
    if not rows:
        raise BadInput(f"{path}: empty")
    header = [h.strip() for h in rows[0]]
    missing = [c for c in columns if c not in header]
    if missing:
        raise BadInput(f"{path}: missing column(s) {', '.join(missing)} (found {', '.join(header)})")
    out = {}
    for c in columns:
        j = header.index(c)
        try:
            out[c] = np.array([float(r[j]) for r in rows[1:]])
        except (ValueError, IndexError):
            raise BadInput(f"{path}: column {c} has a missing or non-numeric value") from None
    return out


def write_csv(path, table: dict[str, np.ndarray]) -> None:
    with open(path, "w", newline="") as fh:
        _write_rows(fh, table)


def _write_rows(fh, table: dict[str, np.ndarray]) -> None:
    w = csv.writer(fh, lineterminator="\n")
    w.writerow(list(table))
    for row in zip(*table.values()):
        w.writerow(["" if np.isnan(v) else f"{v:.10g}" for v in row])


# ---- plots (bare Figure objects: no pyplot, no display needed) ----------------------------------
def plot_theory(law, table, mode, J_tip_c, path) -> None:
    from matplotlib.figure import Figure
    fig = Figure(figsize=(11.0, 4.5), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    d = table["delta_mm"]
    ax1.plot(d, table["sigma_MPa"], "k-")
    ax1.set_xlabel("COD delta (mm)")
    ax1.set_ylabel("traction sigma (MPa)")
    ax1.set_title(f"A. {law.name} law, mode {mode}")
    ax2.plot(d, table["R_J_m2"], "k-", label="R (Eq 16)")
    ax2.plot(d, table["R_eff_J_m2"], "k:", label="R_eff (Eq 14)")
    ax2.axhline(J_tip_c, color="0.6", lw=0.8)
    ax2.axhline(J_tip_c + law.area(mode), color="0.6", lw=0.8)
    ax2.set_xlabel("notch-root COD delta (mm)")
    ax2.set_ylabel("R (J/m^2)")
    ax2.set_title("B. R curves")
    ax2.legend()
    fig.savefig(path, dpi=120)


def plot_fig5(curves, path) -> None:
    from matplotlib.figure import Figure
    fig = Figure(figsize=(6.0, 4.5), layout="constrained")
    ax = fig.subplots()
    x = curves["x"]
    ax.plot(x, curves["R_triangular"], "k-", label="triangular (peak 0.2259 delta_c)")
    ax.plot(x, curves["R_cubic"], "k--", label="cubic")
    ax.plot(x, curves["R_eff_cubic"], "k:", label="cubic R_eff")
    ax.set_xlim(0, 1)
    ax.set_ylim(1.0, 2.0)
    ax.set_xlabel("delta / delta_c")
    ax.set_ylabel("R / J_tip,c")
    ax.set_title("R curves for J_B = J_tip,c (Fig 5)")
    ax.legend(loc="lower right")
    fig.savefig(path, dpi=120)


def plot_inversion(table, path) -> None:
    from matplotlib.figure import Figure
    fig = Figure(figsize=(11.0, 4.5), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    ax1.plot(table["delta_mm"], table["R_J_m2"], "k.-")
    ax1.set_xlabel("COD delta (mm)")
    ax1.set_ylabel("R (J/m^2)")
    ax1.set_title("A. R curve")
    ax2.plot(table["delta_mm"], table["sigma_MPa"], "k-")
    ax2.set_xlabel("COD delta (mm)")
    ax2.set_ylabel("sigma (MPa)")
    ax2.set_title("B. traction law by Eq 18")
    fig.savefig(path, dpi=120)


def plot_area(table, fit, discrete, path) -> None:
    """Fig 11 style: A force and crack length against displacement, B U(a), C R(a)."""
    from matplotlib.figure import Figure
    fig = Figure(figsize=(15.0, 4.5), layout="constrained")
    ax1, ax2, ax3 = fig.subplots(1, 3)
    ax1.plot(table["d_mm"], table["F_N"], "k-")
    ax1.set_xlabel("displacement d (mm)")
    ax1.set_ylabel("force F (N)")
    ax1b = ax1.twinx()
    ax1b.plot(table["d_mm"], table["a_mm"], "b--")
    ax1b.set_ylabel("crack length a (mm)", color="b")
    ax1.set_title("A. force and crack length")
    a_fine = np.linspace(fit.a[0], fit.a[-1], 400)
    ax2.plot(fit.a, fit.U, "ko", ms=3, label="U(a) data (Eq 26)")
    ax2.plot(a_fine, fit.spline(a_fine), "k-", label="smoothing spline")
    ax2.set_xlabel("crack length a (mm)")
    ax2.set_ylabel("U (J/m)")
    ax2.set_title("B. cumulative energy released")
    ax2.legend()
    ax3.plot(a_fine, fit.R_at(a_fine), "k-", label="slope of U(a)")
    ax3.plot(*discrete, "ks", mfc="none", label="discrete area (Eq 25)")
    ax3.set_xlabel("crack length a (mm)")
    ax3.set_ylabel("R (J/m^2)")
    ax3.set_ylim(bottom=0)  # an R curve read against zero, not against an offset
    ax3.ticklabel_format(axis="y", useOffset=False)
    ax3.set_title("C. R curve")
    ax3.legend()
    fig.savefig(path, dpi=120)
