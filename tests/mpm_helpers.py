"""Helpers for the simulation tests: build a scene from XML text, record a run."""
from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np

from nairnmpm_py.input import load_simulation


class Recorder:
    """The smallest output plugin: keeps every global row, and what ``probe(sim)``
    returns at each global archive time (the particle arrays are live numpy)."""

    def __init__(self, probe=None):
        self.probe = probe
        self.rows: list[dict] = []
        self.probes: list = []
        self.archives = 0
        self.status: dict | None = None

    def begin(self, sim) -> None:
        self.rows, self.probes, self.archives = [], [], 0

    def on_global(self, sim, row: dict) -> None:
        self.rows.append(dict(row))
        if self.probe is not None:
            self.probes.append(self.probe(sim))

    def on_archive(self, sim) -> None:
        self.archives += 1

    def end(self, sim, status: dict) -> None:
        self.status = dict(status)

    def column(self, name: str) -> np.ndarray:
        return np.array([r[name] for r in self.rows], dtype=float)


def scene_xml(header: str, grid: str, bodies: str, rest: str = "", analysis="11") -> str:
    """An input file with the tests' usual skeleton: ``header`` inside <MPMHeader>,
    ``grid`` inside <Mesh>, ``bodies`` inside <MaterialPoints>, then ``rest``
    (cracks, materials, conditions).  The parts are pasted as given, so they may
    carry ``str.format`` fields for the caller to fill."""
    def part(text: str, indent: int) -> str:
        return textwrap.indent(textwrap.dedent(text).strip("\n"), " " * indent)
    return (f'<?xml version="1.0"?>\n<JANFEAInput version="3">\n'
            f"  <Header><Analysis>{analysis}</Analysis></Header>\n"
            f"  <MPMHeader>\n{part(header, 4)}\n  </MPMHeader>\n"
            f"  <Mesh>\n{part(grid, 4)}\n  </Mesh>\n"
            f"  <MaterialPoints>\n{part(bodies, 4)}\n  </MaterialPoints>\n"
            f"{part(rest, 2)}\n</JANFEAInput>\n")


def write(tmp_path: Path, text: str, name: str = "scene.xml") -> Path:
    path = Path(tmp_path) / name
    path.write_text(text)
    return path


def build(tmp_path: Path, text: str, name: str = "scene.xml"):
    """Write ``text`` to a file and build its Simulation through the input language."""
    return load_simulation(write(tmp_path, text, name))


def line_of(text: str, needle: str, nth: int = 1) -> int:
    """1-based line number of the nth line of ``text`` containing ``needle``."""
    hits = [i + 1 for i, line in enumerate(text.splitlines()) if needle in line]
    assert len(hits) >= nth, f"{needle!r} not found {nth} times"
    return hits[nth - 1]
