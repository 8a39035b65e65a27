"""VTU particle files per archive and the ParaView collection ``particles.pvd``."""
from __future__ import annotations

import os
from pathlib import Path
from xml.sax.saxutils import quoteattr

import meshio
import numpy as np

from .base import OutputPlugin


def write_pvd(path: Path, entries: list[tuple[float, str]]) -> None:
    """Write a ParaView collection atomically, so a reader never sees half a file."""
    lines = ['<?xml version="1.0"?>',
             '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
             "  <Collection>"]
    lines += [f'    <DataSet timestep="{t:.10g}" part="0" file={quoteattr(f)}/>'
              for t, f in entries]
    lines += ["  </Collection>", "</VTKFile>", ""]
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text("\n".join(lines))
    os.replace(tmp, path)


def particle_mesh(particles) -> meshio.Mesh:
    """Particles as VTK vertex cells with their fields (2D vectors padded to 3D)."""
    p = particles
    n = p.n
    zeros = np.zeros(n)
    points = np.column_stack((p.pos[0], p.pos[1], zeros))
    sxx, syy, sxy, szz = p.stress
    # full symmetric 3x3 (row-major) so ParaView sees a tensor; sxz = syz = 0 in 2D
    tensor = np.column_stack((sxx, sxy, zeros, sxy, syy, zeros, zeros, zeros, szz))
    point_data = {
        "velocity": np.column_stack((p.vel[0], p.vel[1], zeros)),
        "displacement": np.column_stack((p.pos[0] - p.pos0[0], p.pos[1] - p.pos0[1], zeros)),
        "stress": tensor,
        "sxx": np.ascontiguousarray(sxx), "syy": np.ascontiguousarray(syy),
        "sxy": np.ascontiguousarray(sxy), "szz": np.ascontiguousarray(szz),
        "material": np.asarray(p.mat, dtype=np.int32),
        "mass": np.ascontiguousarray(p.mass, dtype=np.float64),
        "strain_energy_density": np.ascontiguousarray(p.w, dtype=np.float64),
    }
    cells = [("vertex", np.arange(n, dtype=np.int64).reshape(-1, 1))]
    return meshio.Mesh(points, cells, point_data=point_data)


class VtuSeries(OutputPlugin):
    name = "vtu"

    def __init__(self, folder: Path):
        super().__init__(folder)
        self.entries: list[tuple[float, str]] = []

    def begin(self, sim) -> None:
        (self.folder / "vtu").mkdir(exist_ok=True)
        self.entries = []

    def on_archive(self, sim) -> None:
        rel = f"vtu/particles_{int(sim.step):06d}.vtu"
        (self.folder / "vtu").mkdir(exist_ok=True)
        # binary but uncompressed: zlib is the slowest part of meshio's writer
        meshio.write(self.folder / rel, particle_mesh(sim.particles), file_format="vtu",
                     binary=True, compression=None)
        self.entries = [e for e in self.entries if e[1] != rel] + [(float(sim.time), rel)]
        # rewritten every archive so the collection is valid whenever the run stops
        write_pvd(self.folder / "particles.pvd", self.entries)
