"""VTU files per archive and their ParaView collections: particles (``particles.pvd``)
and, in scenes with cracks, the crack polylines (``cracks.pvd``)."""
from __future__ import annotations

import os
import re
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


def read_pvd(path: Path) -> list[tuple[float, str]]:
    """The (time, file) entries of a collection ``write_pvd`` wrote ([] if none)."""
    if not path.exists():
        return []
    return [(float(t), f) for t, f in
            re.findall(r'<DataSet timestep="([^"]+)" part="0" file="([^"]+)"/>', path.read_text())]


def _step_of(rel: str) -> int:
    return int(re.search(r"_(\d+)\.vtu$", rel).group(1))


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


def crack_mesh(scene) -> meshio.Mesh:
    """Crack planes as VTK polylines (one line cell per chord) with, per crack particle,
    the above and below surface positions, the normal and tangential opening, the
    traction history and state (0 no law, 1 carrying traction, 2 failed)."""
    cs = scene.cracks
    n = cs.plane.shape[1]
    zeros = np.zeros(n)
    points = np.column_stack((cs.plane[0], cs.plane[1], zeros))
    chords = [(k, k + 1) for c in range(cs.n_cracks)
              for k in range(cs.first[c], cs.first[c] + cs.count[c] - 1)]
    dn, dt = cs.cod()
    point_data = {
        "above": np.column_stack((cs.above[0], cs.above[1], zeros)),
        "below": np.column_stack((cs.below[0], cs.below[1], zeros)),
        "cod_normal": np.ascontiguousarray(dn), "cod_tangential": np.ascontiguousarray(dt),
        "max_cod_normal": np.ascontiguousarray(scene.hist[0]),
        "traction_state": np.asarray(scene.state, dtype=np.int32),
        "traction_law": np.asarray(cs.law, dtype=np.int32),
        "crack": np.asarray(cs.crack, dtype=np.int32),
    }
    cells = [("line", np.array(chords, dtype=np.int64).reshape(-1, 2))]
    return meshio.Mesh(points, cells, point_data=point_data)


class VtuSeries(OutputPlugin):
    name = "vtu"

    def __init__(self, folder: Path):
        super().__init__(folder)
        self.entries: list[tuple[float, str]] = []
        self.crack_entries: list[tuple[float, str]] = []

    def begin(self, sim) -> None:
        (self.folder / "vtu").mkdir(exist_ok=True)
        self.entries = []
        self.crack_entries = []

    def on_archive(self, sim) -> None:
        rel = f"vtu/particles_{int(sim.step):06d}.vtu"
        (self.folder / "vtu").mkdir(exist_ok=True)
        # binary but uncompressed: zlib is the slowest part of meshio's writer
        meshio.write(self.folder / rel, particle_mesh(sim.particles), file_format="vtu",
                     binary=True, compression=None)
        self.entries = [e for e in self.entries if e[1] != rel] + [(float(sim.time), rel)]
        # rewritten every archive so the collection is valid whenever the run stops
        write_pvd(self.folder / "particles.pvd", self.entries)
        if getattr(sim, "cracks", None) is not None:
            rel = f"vtu/cracks_{int(sim.step):06d}.vtu"
            meshio.write(self.folder / rel, crack_mesh(sim.cracks), file_format="vtu",
                         binary=True, compression=None)
            self.crack_entries = ([e for e in self.crack_entries if e[1] != rel]
                                  + [(float(sim.time), rel)])
            write_pvd(self.folder / "cracks.pvd", self.crack_entries)

    def resume(self, sim, step: int, time_ms: float) -> None:
        """The collections keep the files up to the checkpoint's step; later ones (a
        run that went on past it) are removed and written again."""
        (self.folder / "vtu").mkdir(exist_ok=True)
        for attr, name in (("entries", "particles.pvd"), ("crack_entries", "cracks.pvd")):
            kept = []
            for t, rel in read_pvd(self.folder / name):
                if _step_of(rel) <= step:
                    kept.append((t, rel))
                else:
                    (self.folder / rel).unlink(missing_ok=True)
            setattr(self, attr, kept)
            if (self.folder / name).exists():
                write_pvd(self.folder / name, kept)
