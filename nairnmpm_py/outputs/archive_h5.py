"""archive.h5: particle states at archive times plus the parsed input (HDF5, h5py).

Layout, as a reader sees it through ``archive.h5``::

    /                  attrs: title, units, plane_stress, material_names, grid_*,
                              exit_status (set at the end)
    /input_xml         the input text as parsed
    /archives/NNNNNN   one group per archive, named by step; attrs time_ms, step;
                       datasets pos vel stress F w mat mass vol0 pos0 lp hist pdamp,
                       component first like the engine's arrays ((2, n), (4, n), ...)

    /archives/NNNNNN/cracks   in scenes with cracks: plane above below (2, nc) mm,
                       crack law traction_state (nc,), traction_history (2, nc) mm
                       (maximum normal and tangential opening reached), edge_history
                       (2, nc) mm (maximum normal opening halfway to the previous and
                       the next particle, where a notch root is taken)

lp, hist and pdamp are not needed for plotting but are stored so an archive holds the
whole particle state.

So that a run killed at any moment leaves a readable file, each archive is a file of
its own, ``archive/NNNNNN.h5``, written aside and renamed into place when complete,
and ``archive.h5`` is a small index (the attributes, the input text and an HDF5
external link per archive) rewritten whole and renamed over the old one at every
archive.  h5py and other HDF5 readers follow the links as if the groups were in
``archive.h5`` (keep the ``archive`` folder beside it when moving the results).
"""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np

from ..core.durable import aside, replace_durably
from .base import OutputPlugin

UNITS = ("length mm, mass g, time ms, velocity m/s (= mm/ms), stress MPa, force N, "
         "energy J, strain energy density mJ/mm^3 (= MPa), energy release rate J/m^2")

# float arrays of every archive; mat is stored as int32 on its own
FLOAT_FIELDS = ("pos", "vel", "stress", "F", "w", "mass", "vol0", "pos0", "lp", "hist", "pdamp")


FOLDER = "archive"


class ArchiveH5(OutputPlugin):
    name = "archive_h5"
    filename = "archive.h5"

    def __init__(self, folder: Path):
        super().__init__(folder)
        self.attrs: dict = {}
        self.input_text = ""
        self.steps: list[int] = []

    @property
    def path(self) -> Path:
        return self.folder / self.filename

    def begin(self, sim) -> None:
        self._start(sim)
        self._write_index()

    def _start(self, sim) -> None:
        g = sim.grid
        self.attrs = {"title": getattr(sim, "title", "") or "", "units": UNITS,
                      "plane_stress": bool(sim.plane_stress),
                      "material_names": [str(n) for n in getattr(sim, "material_names", [])],
                      "exit_status": "running",
                      "grid_bounds_mm": [g.xmin, g.xmax, g.ymin, g.ymax],
                      "grid_cells": [g.nx, g.ny],
                      "thickness_mm": getattr(g, "thickness", 1.0)}
        self.input_text = (getattr(sim, "source", None) or {}).get("text", "") or ""
        self.steps = []
        (self.folder / FOLDER).mkdir(exist_ok=True)

    def _write_index(self) -> None:
        tmp = aside(self.path)
        with h5py.File(tmp, "w") as h5:
            for key, value in self.attrs.items():
                h5.attrs[key] = value
            h5.create_dataset("input_xml", data=self.input_text, dtype=h5py.string_dtype())
            archives = h5.create_group("archives")
            for step in self.steps:
                archives[f"{step:06d}"] = h5py.ExternalLink(f"{FOLDER}/{step:06d}.h5", "/")
        replace_durably(tmp, self.path)

    def on_archive(self, sim) -> None:
        if not self.attrs:
            self.begin(sim)
        step = int(sim.step)
        path = self.folder / FOLDER / f"{step:06d}.h5"
        tmp = aside(path)
        with h5py.File(tmp, "w") as grp:
            grp.attrs["time_ms"] = float(sim.time)
            grp.attrs["step"] = step
            p = sim.particles
            # uncompressed: archives of large scenes are written often and gzip would
            # dominate the output time; users can repack with h5repack if space matters
            for field in FLOAT_FIELDS:
                grp.create_dataset(field, data=np.asarray(getattr(p, field), dtype=np.float64))
            grp.create_dataset("mat", data=np.asarray(p.mat, dtype=np.int32))
            scene = getattr(sim, "cracks", None)
            if scene is not None:
                cg = grp.create_group("cracks")
                cs = scene.cracks
                for name in ("plane", "above", "below"):
                    cg.create_dataset(name, data=np.asarray(getattr(cs, name), dtype=np.float64))
                cg.create_dataset("crack", data=np.asarray(cs.crack, dtype=np.int32))
                cg.create_dataset("law", data=np.asarray(cs.law, dtype=np.int32))
                cg.create_dataset("traction_state", data=np.asarray(scene.state, dtype=np.int8))
                cg.create_dataset("traction_history", data=np.asarray(scene.hist, dtype=np.float64))
                cg.create_dataset("edge_history", data=np.asarray(scene.edge_hist,
                                                                  dtype=np.float64))
        replace_durably(tmp, path)
        if step not in self.steps:        # the same step archived twice: the latest
            self.steps.append(step)
        self._write_index()

    def resume(self, sim, step: int, time_ms: float) -> None:
        """Archives after the checkpoint's step (a run that went on past it) are
        dropped; new ones are added.  The index is rewritten once, with the kept
        ones: a kill during the resume leaves it whole."""
        self._start(sim)
        for path in (self.folder / FOLDER).glob("*.tmp"):    # a write that was cut off
            path.unlink()
        for path in sorted((self.folder / FOLDER).glob("*.h5")):
            if path.stem.isdigit() and int(path.stem) <= step:
                self.steps.append(int(path.stem))
            else:
                path.unlink()
        self._write_index()

    def end(self, sim, status: dict) -> None:
        if not self.attrs:
            return
        self.attrs["exit_status"] = status.get("exit_status", "unknown")
        if status.get("message"):
            self.attrs["message"] = str(status["message"])
        self._write_index()
