"""Overlay plots of a sweep folder (``summary.csv`` plus one results folder per member):
energies against time, each load against displacement (or time) and, for members with
cracks, J_tip and crack growth against time, R against crack growth and against the
opening at the original notch root (the seed paper's Figs 8B and 7, with each
member's Eq 16/22 theory dashed), the traction-zone length against the moment (Fig 10),
and each moment against the load-line opening (Figs 8A and 9A); one line per member,
legend by member name."""
from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from .plots import (ENERGY_COLUMNS, LOAD_PREFIXES, OPENING_PREFIX, TIME_LABEL, _figure,
                    _nonzero, _safe, _save, load_displacement, theory_lines)
from .results import read_csv_columns

SUMMARY = "summary.csv"


def sweep_members(folder) -> list[tuple[str, dict, list[str]]]:
    """(name, global.csv columns, column order) of every member of ``folder`` that has a
    non-empty global.csv, in summary order."""
    folder = Path(folder)
    with open(folder / SUMMARY, newline="") as f:
        names = [r["name"] for r in csv.DictReader(f) if r.get("name")]
    members = []
    for name in names:
        cols, data = _member_csv(folder / name / "global.csv")
        if data:
            members.append((name, data, cols))
    return members


def _member_csv(path: Path) -> tuple[list[str], dict | None]:
    """A member's CSV as columns, or (_, None) if it is missing, unreadable or has no
    rows (a member that failed early)."""
    if not path.exists():
        return [], None
    try:
        cols, data = read_csv_columns(path)
    except Exception:
        return [], None
    return (cols, data) if "time_ms" in data and len(data["time_ms"]) else ([], None)


def plot_sweep(folder, out_folder=None) -> list[Path]:
    """PNGs overlaying the members of a sweep into ``out_folder`` (default
    ``folder/plots``): ``sweep_energies.png`` (one panel per energy) and
    ``sweep_load_<bc>.png`` per load column (load vs displacement, else vs time).
    Returns the files written."""
    folder = Path(folder)
    out = Path(out_folder) if out_folder is not None else folder / "plots"
    out.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    members = sweep_members(folder)
    if not members:
        return written

    energies = [c for c in ENERGY_COLUMNS if any(c in g for _, g, _ in members)]
    if energies:
        fig, axes = _figure(len(energies))
        for ax, col in zip(axes, energies):
            for name, g, _ in members:
                if col in g:
                    ax.plot(g["time_ms"], g[col], label=name)
            ax.set_xlabel(TIME_LABEL)
            ax.set_ylabel(f"{ENERGY_COLUMNS[col]} energy (J)")
            ax.grid(alpha=0.3)
        axes[0].legend(fontsize="small")
        _save(fig, out / "sweep_energies.png", written)

    load_cols = []
    for _, _, cols in members:
        load_cols += [c for c in cols if c not in load_cols and any(c.startswith(p) for p in LOAD_PREFIXES)]
    for col in load_cols:
        prefix = next(p for p in LOAD_PREFIXES if col.startswith(p))
        bc = col[len(prefix):]
        have = [(n, g) for n, g, _ in members if col in g and _nonzero(g[col])]
        if not have:
            continue
        disps = [load_displacement(g, col) for _, g in have]
        labels = {label for _, label, _ in disps}
        vs_disp = all(d is not None for d, _, _ in disps) and len(labels) == 1
        # a moment against the opening of its arms is drawn as a magnitude (Figs 8A, 9A)
        magnitude = vs_disp and all(used.startswith(OPENING_PREFIX) for _, _, used in disps)
        fig, (ax,) = _figure()
        for (name, g), (disp, _, _) in zip(have, disps):
            y = np.abs(g[col]) if magnitude else g[col]
            ax.plot(disp if vs_disp else g["time_ms"], y, label=name)
        ax.set_xlabel(labels.pop() if vs_disp else TIME_LABEL)
        ax.set_ylabel(("|moment| (N mm)" if magnitude else LOAD_PREFIXES[prefix]))
        ax.set_title(f"boundary condition {bc}")
        ax.legend(fontsize="small")
        ax.grid(alpha=0.3)
        _save(fig, out / f"sweep_load_{_safe(bc)}.png", written)
    _plot_crack_overlays(folder, {name: g for name, g, _ in members}, out, written)
    return written


def _plot_crack_overlays(folder: Path, globals_: dict, out: Path, written: list[Path]) -> None:
    """``sweep_cracks.png``: J_tip and crack growth against time (first tip of each
    member); at the growth steps, ``sweep_r_curve.png``: R (Eq 15) against growth,
    ``sweep_r_cod.png``: R against the opening at the original notch root, and
    ``sweep_zone_moment.png``: zone length against the first moment column of
    global.csv (its magnitude, at the growth times)."""
    tables = []
    for name in globals_:
        _, c = _member_csv(folder / name / "cracks.csv")
        if c is None:
            continue
        first = (c["crack"] == c["crack"][0]) & (c["tip"] == c["tip"][0])
        tables.append((name, {k: v[first] for k, v in c.items()}))
    if not tables:
        return
    fig, axes = _figure(2)
    for name, c in tables:
        order = np.argsort(c["time_ms"], kind="stable")
        axes[0].plot(c["time_ms"][order], c["J_tip_J_m2"][order], label=name)
        axes[1].plot(c["time_ms"][order], c["crack_growth_mm"][order], label=name)
    axes[0].set_ylabel("J_tip (J/m^2)")
    axes[1].set_ylabel("crack growth (mm)")
    for ax in axes:
        ax.set_xlabel(TIME_LABEL)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize="small")
    _save(fig, out / "sweep_cracks.png", written)
    # at the growth steps: (x, y) of each member for one overlay
    grown = [(n, c, c["event"] == "growth") for n, c in tables if np.any(c["event"] == "growth")]
    if not grown:
        return
    _growth_overlay([(n, c["crack_growth_mm"][g], c["R_J_m2"][g]) for n, c, g in grown],
                    "crack growth (mm)", "R (J/m^2)", out / "sweep_r_curve.png", written)
    theory = {n: theory_lines(_member_run(folder / n)) for n, _, _ in grown}
    _growth_overlay([(n, c["cod_notch0_mm"][g], c["R_J_m2"][g]) for n, c, g in grown],
                    "opening at the original notch root (mm)", "R (J/m^2)",
                    out / "sweep_r_cod.png", written,
                    dashed={n: lines[0][1:] for n, lines in theory.items() if lines})
    lines = []
    for name, c, g in grown:
        gl = globals_[name]
        col = next((k for k in gl if k.startswith("moment_Nmm_")), None)
        if col is not None:
            moment = np.interp(c["time_ms"][g], gl["time_ms"], np.abs(gl[col]))
            lines.append((name, moment, c["zone_length_mm"][g]))
    if lines:
        _growth_overlay(lines, "moment (N mm)", "traction zone length (mm)",
                        out / "sweep_zone_moment.png", written)


def _member_run(folder: Path) -> dict:
    try:
        return json.loads((folder / "run.json").read_text())
    except (OSError, ValueError):
        return {}


def _growth_overlay(lines: list, xlabel: str, ylabel: str, path: Path,
                    written: list[Path], dashed: dict | None = None) -> None:
    """One overlay of (name, x, y) lines, points at the growth steps; ``dashed`` maps a
    name to an (x, y) curve drawn dashed in its colour (the theory for that member)."""
    fig, (ax,) = _figure()
    dashed = dashed or {}
    for name, x, y in lines:
        (line,) = ax.plot(x, y, ".-", ms=3, label=name)
        if name in dashed:
            ax.plot(*dashed[name], "--", lw=1, color=line.get_color())
    if dashed:
        # the rise is below delta_c (theory runs to 1.2 delta_c; the notch root opens
        # much further once broken)
        ax.plot([], [], "k--", lw=1, label="theory (Eq 16/22)")
        ax.set_xlim(0.0, 1.25 * max(float(np.max(x)) for x, _ in dashed.values()))
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.legend(fontsize="small")
    ax.grid(alpha=0.3)
    _save(fig, path, written)
