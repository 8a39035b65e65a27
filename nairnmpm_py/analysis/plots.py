"""PNG plots of a results folder: energies, load-time and load-displacement per
boundary condition, extra global columns, J and R curves, crack growth, J contours.

Figures are drawn on bare ``matplotlib.figure.Figure`` objects (Agg canvas, no
pyplot), so plotting needs no display and leaves no global figure state behind.
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from .results import open_results

TIME_LABEL = "time (ms)"
ENERGY_COLUMNS = {"kinetic_energy_J": "kinetic", "strain_energy_J": "strain",
                  "external_work_J": "external work"}
LOAD_PREFIXES = {"load_N_": "load (N)", "moment_Nmm_": "moment (N mm)"}
DISP_PREFIX = "disp_mm_"
OPENING_PREFIX = "opening_mm_"

# unit tokens as they appear in column names (longest first) and how to print them
UNIT_TOKENS = [("MPa_sqrt_m", "MPa m^1/2"), ("J_m2", "J/m^2"), ("mm_s", "mm/s"),
               ("m_s", "m/s"), ("Nmm", "N mm"), ("MPa", "MPa"), ("mm", "mm"),
               ("ms", "ms"), ("N", "N"), ("J", "J")]
QUANTITY_WORDS = {"velx": "x velocity", "vely": "y velocity", "dispx": "x displacement",
                  "dispy": "y displacement", "disp": "displacement"}


def column_label(name: str) -> str:
    """Axis label from a column name with its unit, e.g. ``velx_mm_s_Ti`` ->
    ``x velocity Ti (mm/s)``, ``J_tip_J_m2`` -> ``J tip (J/m^2)``."""
    parts = name.split("_")
    # a unit at the end (J_tip_J_m2) wins; else the first unit after the
    # quantity word (load_N_<bc>, velx_mm_s_<material>)
    for token, shown in UNIT_TOKENS:
        tp = token.split("_")
        if len(parts) > len(tp) and parts[-len(tp):] == tp:
            words = parts[:-len(tp)]
            return f"{' '.join(_words(words))} ({shown})"
    for i in range(1, len(parts)):
        for token, shown in UNIT_TOKENS:
            tp = token.split("_")
            if parts[i:i + len(tp)] == tp:
                words = parts[:i] + parts[i + len(tp):]
                return f"{' '.join(_words(words))} ({shown})"
    return name


def _words(words: list[str]) -> list[str]:
    return [QUANTITY_WORDS.get(words[0], words[0])] + words[1:] if words else words


def _safe(name: str) -> str:
    return re.sub(r"[^\w.-]+", "_", name)


def _figure(ncols: int = 1) -> tuple[Figure, list]:
    fig = Figure(figsize=(6.0 * ncols, 4.5), layout="constrained")
    axes = [fig.add_subplot(1, ncols, i + 1) for i in range(ncols)]
    return fig, axes


def _save(fig: Figure, path: Path, written: list[Path]) -> None:
    fig.savefig(path, dpi=150)
    written.append(path)


def _nonzero(a) -> bool:
    a = np.asarray(a, dtype=float)
    return a.size > 0 and bool(np.any(np.isfinite(a) & (a != 0)))


# ---- global.csv ------------------------------------------------------------------
def load_displacement(g: dict, load_col: str) -> tuple[np.ndarray | None, str, str | None]:
    """(x values, axis label, column) to plot a load column against: the condition's
    own ``disp_mm_`` column, or for a moment the opening of the two loaded groups
    (``opening_mm_<a>_<b>`` naming the moment's group; seed Figs 8A and 9A); None
    when there is neither."""
    for prefix in LOAD_PREFIXES:
        if load_col.startswith(prefix):
            bc = load_col[len(prefix):]
            break
    else:
        return None, "", None
    disp_col = DISP_PREFIX + bc
    if disp_col in g and _nonzero(g[disp_col]):
        return g[disp_col], "displacement (mm)", disp_col
    if prefix == "moment_Nmm_":
        for col in g:
            if col.startswith(OPENING_PREFIX) and _names_group(col, bc) and _nonzero(g[col]):
                return g[col], "load-line opening (mm)", col
    return None, "", None


def _names_group(opening_col: str, group: str) -> bool:
    """Does ``opening_mm_<a>_<b>`` name ``group`` as a or b?"""
    pair = opening_col[len(OPENING_PREFIX):]
    return pair.startswith(group + "_") or pair.endswith("_" + group)


def _plot_energies(g: dict, out: Path, written: list[Path]) -> None:
    if "time_ms" not in g or not any(c in g for c in ENERGY_COLUMNS):
        return
    t = g["time_ms"]
    fig, (ax,) = _figure()
    for col, label in ENERGY_COLUMNS.items():
        if col in g:
            ax.plot(t, g[col], label=label)
    if "kinetic_energy_J" in g and "strain_energy_J" in g:
        ax.plot(t, g["kinetic_energy_J"] + g["strain_energy_J"], "k--", label="total (kinetic + strain)")
    ax.set_xlabel(TIME_LABEL)
    ax.set_ylabel("energy (J)")
    ax.legend()
    ax.grid(alpha=0.3)
    _save(fig, out / "energies.png", written)


def _plot_loads(g: dict, columns: list[str], out: Path, written: list[Path]) -> set[str]:
    """One figure per loaded boundary condition; returns the columns used."""
    used = set()
    t = g.get("time_ms")
    for col in columns:
        prefix = next((p for p in LOAD_PREFIXES if col.startswith(p)), None)
        if prefix is None:
            continue
        bc = col[len(prefix):]
        used.update({col, DISP_PREFIX + bc})
        load = g[col]
        if not _nonzero(load) or t is None:
            continue
        disp, disp_label, disp_col = load_displacement(g, col)
        used.add(disp_col)
        fig, axes = _figure(2 if disp is not None else 1)
        axes[0].plot(t, load)
        axes[0].set_xlabel(TIME_LABEL)
        axes[0].set_ylabel(LOAD_PREFIXES[prefix])
        if disp is not None:
            # a moment against its arms' opening is drawn as a magnitude (Figs 8A, 9A)
            magnitude = disp_col.startswith(OPENING_PREFIX)
            axes[1].plot(disp, np.abs(load) if magnitude else load)
            axes[1].set_xlabel(disp_label)
            axes[1].set_ylabel("|moment| (N mm)" if magnitude else LOAD_PREFIXES[prefix])
        for ax in axes:
            ax.grid(alpha=0.3)
        fig.suptitle(f"boundary condition {bc}")
        _save(fig, out / f"load_{_safe(bc)}.png", written)
    # displacement columns of unloaded conditions are not extras either
    used.update(c for c in columns if c.startswith(DISP_PREFIX))
    return used


def _plot_extras(g: dict, columns: list[str], skip: set[str], out: Path, written: list[Path]) -> None:
    t = g.get("time_ms")
    if t is None:
        return
    for col in columns:
        if col in skip or col in ("time_ms", "step") or col in ENERGY_COLUMNS:
            continue
        y = g[col]
        if y.dtype.kind != "f" or not np.any(np.isfinite(y)):
            continue
        fig, (ax,) = _figure()
        ax.plot(t, y)
        ax.set_xlabel(TIME_LABEL)
        ax.set_ylabel(column_label(col))
        ax.grid(alpha=0.3)
        _save(fig, out / f"global_{_safe(col)}.png", written)


# ---- cracks.csv and jcontours.csv --------------------------------------------------
def _tip_series(c: dict) -> list[tuple[str, np.ndarray]]:
    """(label, row indices sorted by time) for each crack tip."""
    n = len(c["time_ms"])
    crack = c.get("crack", np.zeros(n))
    tip = c.get("tip", np.zeros(n))
    keys = np.array([f"crack {_fmt(a)} tip {_fmt(b)}" for a, b in zip(crack, tip)])
    series = []
    for key in dict.fromkeys(keys.tolist()):
        rows = np.flatnonzero(keys == key)
        series.append((key, rows[np.argsort(c["time_ms"][rows], kind="stable")]))
    return series


def _fmt(v) -> str:
    if isinstance(v, (float, np.floating)) and float(v).is_integer():
        return str(int(v))
    return str(v)


def theory_lines(run: dict) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """(label, opening mm, R J/m^2) of run.json's R-curve theory per growing tip (seed
    Eq 16; Eq 22 for the cubic law)."""
    lines = []
    for th in run.get("r_curve_theory", []):
        lines.append((f"crack {th['crack']} {th['tip']}", np.asarray(th["cod_mm"], dtype=float),
                      np.asarray(th["R_J_m2"], dtype=float)))
    return lines


def _plot_cracks(c: dict, out: Path, written: list[Path], run: dict | None = None) -> None:
    if "time_ms" not in c or len(c["time_ms"]) == 0:
        return
    series = _tip_series(c)
    t = c["time_ms"]
    if "J_tip_J_m2" in c or "J_ff_J_m2" in c:
        fig, (ax,) = _figure()
        for label, rows in series:
            if "J_tip_J_m2" in c:
                ax.plot(t[rows], c["J_tip_J_m2"][rows], label=f"J_tip, {label}")
            if "J_ff_J_m2" in c:
                ax.plot(t[rows], c["J_ff_J_m2"][rows], "--", label=f"J_ff, {label}")
        ax.set_xlabel(TIME_LABEL)
        ax.set_ylabel("J (J/m^2)")
        ax.legend(fontsize="small")
        ax.grid(alpha=0.3)
        _save(fig, out / "j_vs_time.png", written)
    if "crack_growth_mm" in c and "R_J_m2" in c and np.any(np.isfinite(c["R_J_m2"])):
        fig, (ax,) = _figure()
        for label, rows in series:
            ax.plot(c["crack_growth_mm"][rows], c["R_J_m2"][rows], label=f"R, {label}")
            if "J_ff_J_m2" in c:   # during growth J_ff should track R (Eq 15)
                ax.plot(c["crack_growth_mm"][rows], c["J_ff_J_m2"][rows], ":", label=f"J_ff, {label}")
        ax.set_xlabel("crack growth (mm)")
        ax.set_ylabel("R (J/m^2)")
        ax.legend(fontsize="small")
        ax.grid(alpha=0.3)
        _save(fig, out / "r_curve.png", written)
    if "cod_notch0_mm" in c and "R_J_m2" in c and np.any(np.isfinite(c["R_J_m2"])):
        # seed Fig 7: R against the opening at the original notch root
        fig, (ax,) = _figure()
        for label, rows in series:
            ok = rows[np.isfinite(c["R_J_m2"][rows])]
            ax.plot(c["cod_notch0_mm"][ok], c["R_J_m2"][ok], ".-", label=f"R, {label}")
        theory = theory_lines(run or {})
        for label, d, R in theory:
            ax.plot(d, R, "k--", lw=1, label=f"theory (Eq 16/22), {label}")
        if theory:   # the rise is below delta_c (theory runs to 1.2 delta_c)
            ax.set_xlim(0.0, 1.25 * max(float(d[-1]) for _, d, _ in theory))
        ax.set_xlabel("COD at the original notch root (mm)")
        ax.set_ylabel("R (J/m^2)")
        ax.legend(fontsize="small")
        ax.grid(alpha=0.3)
        _save(fig, out / "r_vs_cod.png", written)
    if "zone_length_mm" in c and np.any(np.asarray(c["zone_length_mm"]) > 0):
        fig, (ax,) = _figure()
        for label, rows in series:
            ax.plot(t[rows], c["zone_length_mm"][rows], label=label)
        ax.set_xlabel(TIME_LABEL)
        ax.set_ylabel("bridging zone length (mm)")
        ax.legend(fontsize="small")
        ax.grid(alpha=0.3)
        _save(fig, out / "zone_length.png", written)
    if "crack_growth_mm" in c:
        fig, (ax,) = _figure()
        for label, rows in series:
            ax.plot(t[rows], c["crack_growth_mm"][rows], label=label)
        ax.set_xlabel(TIME_LABEL)
        ax.set_ylabel("crack growth (mm)")
        ax.legend(fontsize="small")
        ax.grid(alpha=0.3)
        _save(fig, out / "crack_growth.png", written)


def _plot_jcontours(j: dict, columns: list[str], out: Path, written: list[Path]) -> None:
    """J against contour size: x is the first column naming a contour, y every
    J column (``J..._J_m2``)."""
    xcol = next((c for c in columns if "contour" in c.lower()), None)
    ycols = [c for c in columns if c.startswith("J") and c.endswith("_J_m2") and c != xcol]
    if xcol is None or not ycols or len(j[xcol]) == 0:
        return
    if "time_ms" in j:   # the last time written (every archive has all sizes)
        last = np.flatnonzero(j["time_ms"] == np.max(j["time_ms"]))
        j = {k: np.asarray(v)[last] for k, v in j.items()}
    order = np.argsort(j[xcol], kind="stable")
    fig, (ax,) = _figure()
    for col in ycols:
        ax.plot(j[xcol][order], j[col][order], "o-", label=column_label(col).replace(" (J/m^2)", ""))
    ax.set_xlabel(column_label(xcol))
    ax.set_ylabel("J (J/m^2)")
    ax.legend()
    ax.grid(alpha=0.3)
    _save(fig, out / "j_contours.png", written)


def plot_results(folder, out_folder=None) -> list[Path]:
    """Draw every plot the results in ``folder`` support; PNGs go to
    ``out_folder`` (default ``folder/plots``).  Returns the files written."""
    res = open_results(folder)
    out = Path(out_folder) if out_folder is not None else res.folder / "plots"
    out.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    if res.global_:
        g, cols = res.global_, res.global_columns
        _plot_energies(g, out, written)
        used = _plot_loads(g, cols, out, written)
        _plot_extras(g, cols, used, out, written)
    if res.cracks:
        _plot_cracks(res.cracks, out, written, res.run)
    if res.jcontours:
        _plot_jcontours(res.jcontours, res.jcontour_columns, out, written)
    return written
