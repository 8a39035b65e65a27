"""run.json: what was run, with which settings, and how it ended."""
from __future__ import annotations

import json
import os
from pathlib import Path

from .. import __version__
from ..core.simulation import METHOD_NAMES, SHAPE_NAMES
from .base import OutputPlugin

UNITS = {"length": "mm", "mass": "g", "time": "ms", "stress": "MPa", "force": "N",
         "energy": "J", "energy release rate": "J/m^2", "velocity": "m/s",
         "density": "g/cm^3"}


def write_json_atomic(path: Path, data: dict) -> None:
    """Write via a temporary file and rename, so run.json is never half written."""
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(data, indent=2) + "\n")
    os.replace(tmp, path)


class RunJson(OutputPlugin):
    name = "run_json"
    filename = "run.json"

    def __init__(self, folder: Path):
        super().__init__(folder)
        self.info: dict = {}

    def begin(self, sim) -> None:
        source = getattr(sim, "source", None) or {}
        method = int(sim.method)
        # the time step and counts are fixed for the run: record them now, so the
        # file says what was planned even if the run never ends cleanly
        self.info = {
            "version": __version__,
            "title": getattr(sim, "title", "") or "",
            "input": {"path": source.get("path"), "sha256": source.get("sha256")},
            "units": UNITS,
            "analysis": "plane stress" if sim.plane_stress else "plane strain",
            "mpm_method": {"number": method, "name": METHOD_NAMES.get(method, str(method))},
            "shape_function": SHAPE_NAMES.get(sim.shape, str(sim.shape)),
            "particles": int(sim.particles.n),
            "cells": int(sim.grid.n_cells),
            "thickness_mm": float(getattr(sim.grid, "thickness", 1.0)),
            "materials": [str(n) for n in getattr(sim, "material_names", [])],
            "time_step_ms": float(sim.dt),
            "max_time_ms": float(sim.max_time),
            "steps_planned": int(sim.n_steps),
            "steps_taken": int(sim.step),
            "wall_seconds": None,
            "compile_seconds": None,
            "exit_status": "running",
        }
        scene = getattr(sim, "cracks", None)
        if scene is not None:
            theory = scene.rcurve_theory(sim)
            if theory:
                self.info["r_curve_theory"] = theory
        self._write(sim)

    def resume(self, sim, step: int, time_ms: float) -> None:
        """The first part's record, with the resume added; the wall seconds at the end
        are those of all parts."""
        path = self.folder / self.filename
        try:
            self.info = json.loads(path.read_text())
        except (OSError, ValueError):
            self.begin(sim)
            return
        self.info.setdefault("resumes", []).append(
            {"from_step": int(step), "from_time_ms": float(time_ms),
             "wall_seconds_before": float(getattr(sim, "wall_before", 0.0)),
             "max_time_ms": float(sim.max_time)})
        self.info["max_time_ms"] = float(sim.max_time)
        self.info["steps_planned"] = int(sim.n_steps)
        self.info["exit_status"] = "running"
        self._write(sim)

    def end(self, sim, status: dict) -> None:
        if not self.info:
            self.begin(sim)
        self.info["steps_taken"] = int(status.get("steps", sim.step))
        self.info["time_reached_ms"] = float(sim.time)
        self.info["wall_seconds"] = status.get("wall_seconds")
        self.info["exit_status"] = status.get("exit_status", "unknown")
        if status.get("message"):
            self.info["message"] = str(status["message"])
        if status.get("profile"):
            self.info["profile"] = status["profile"]
        if status.get("checkpoints"):
            self.info["checkpoints"] = status["checkpoints"]
        if "checkpoint_step" in status:
            self.info["checkpoint_step"] = status["checkpoint_step"]
        scene = getattr(sim, "cracks", None)
        if scene is not None:
            self.info["cracks"] = scene.summary()
        self._write(sim)

    def _write(self, sim) -> None:
        compile_seconds = getattr(sim, "compile_seconds", None)
        if compile_seconds is not None:
            self.info["compile_seconds"] = float(compile_seconds)
        write_json_atomic(self.folder / self.filename, self.info)
