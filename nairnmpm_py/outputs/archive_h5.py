"""archive.h5: particle states at archive times plus the parsed input (HDF5, h5py).

Layout::

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
whole particle state (enough to restart).
"""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np

from .base import OutputPlugin

UNITS = ("length mm, mass g, time ms, velocity m/s (= mm/ms), stress MPa, force N, "
         "energy J, strain energy density mJ/mm^3 (= MPa), energy release rate J/m^2")

# float arrays of every archive; mat is stored as int32 on its own
FLOAT_FIELDS = ("pos", "vel", "stress", "F", "w", "mass", "vol0", "pos0", "lp", "hist", "pdamp")


class ArchiveH5(OutputPlugin):
    name = "archive_h5"
    filename = "archive.h5"

    def __init__(self, folder: Path):
        super().__init__(folder)
        self._h5: h5py.File | None = None

    @property
    def path(self) -> Path:
        return self.folder / self.filename

    def begin(self, sim) -> None:
        h5 = self._h5 = h5py.File(self.path, "w")
        h5.attrs["title"] = getattr(sim, "title", "") or ""
        h5.attrs["units"] = UNITS
        h5.attrs["plane_stress"] = bool(sim.plane_stress)
        h5.attrs["material_names"] = [str(n) for n in getattr(sim, "material_names", [])]
        h5.attrs["exit_status"] = "running"
        g = sim.grid
        h5.attrs["grid_bounds_mm"] = [g.xmin, g.xmax, g.ymin, g.ymax]
        h5.attrs["grid_cells"] = [g.nx, g.ny]
        h5.attrs["thickness_mm"] = getattr(g, "thickness", 1.0)
        h5.create_dataset("input_xml", data=(getattr(sim, "source", None) or {}).get("text", "") or "",
                          dtype=h5py.string_dtype())
        h5.create_group("archives")
        h5.flush()

    def on_archive(self, sim) -> None:
        if self._h5 is None:
            self.begin(sim)
        archives = self._h5["archives"]
        key = f"{int(sim.step):06d}"
        if key in archives:          # same step archived twice: keep the latest
            del archives[key]
        grp = archives.create_group(key)
        grp.attrs["time_ms"] = float(sim.time)
        grp.attrs["step"] = int(sim.step)
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
            cg.create_dataset("edge_history", data=np.asarray(scene.edge_hist, dtype=np.float64))
        # after a flush the file on disk is consistent, so a killed run stays readable
        self._h5.flush()

    def resume(self, sim, step: int, time_ms: float) -> None:
        """Archives after the checkpoint's step (a run that went on past it) are
        dropped; new ones are added to the same file."""
        if not self.path.exists():
            self.begin(sim)
            return
        h5 = self._h5 = h5py.File(self.path, "a")
        archives = h5.require_group("archives")
        for key in [k for k in archives if int(k) > step]:
            del archives[key]
        h5.attrs["exit_status"] = "running"
        h5.flush()

    def end(self, sim, status: dict) -> None:
        if self._h5 is None:
            if not self.path.exists():
                return
            self._h5 = h5py.File(self.path, "a")
        try:
            self._h5.attrs["exit_status"] = status.get("exit_status", "unknown")
            if status.get("message"):
                self._h5.attrs["message"] = str(status["message"])
        finally:
            self._h5.close()
            self._h5 = None
