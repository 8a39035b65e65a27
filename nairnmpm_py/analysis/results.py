"""Open a results folder (run.json, global.csv, cracks.csv, jcontours.csv,
archive.h5) as numpy arrays."""
from __future__ import annotations

import csv

import json
from pathlib import Path

import h5py
import numpy as np


def read_csv_columns(path: Path) -> tuple[list[str], dict[str, np.ndarray]]:
    """Columns of a CSV with one header row: numeric columns as float arrays (an empty
    cell is NaN), any other column (e.g. a tip name or an error message, quoted) as a
    string array."""
    with open(Path(path), newline="") as f:
        table = list(csv.reader(f))
    if not table or not table[0]:
        return [], {}
    names = [c.strip() for c in table[0]]
    rows = [r for r in table[1:] if r]
    columns = {}
    for i, n in enumerate(names):
        cells = [r[i] if i < len(r) else "" for r in rows]
        try:
            columns[n] = np.array([float(c) if c.strip() else np.nan for c in cells],
                                  dtype=np.float64)
        except ValueError:
            columns[n] = np.array(cells, dtype=str)
    return names, columns


class Results:
    """A results folder.  ``global_`` maps each global.csv column to an array;
    ``cracks`` and ``jcontours`` do the same for their CSV files, or are None."""

    def __init__(self, folder):
        self.folder = Path(folder)
        if not self.folder.is_dir():
            raise FileNotFoundError(f"no results folder {self.folder}")
        run = self.folder / "run.json"
        self.run: dict = json.loads(run.read_text()) if run.exists() else {}
        self.global_columns, self.global_ = self._csv("global.csv")
        self.crack_columns, self.cracks = self._csv("cracks.csv")
        self.jcontour_columns, self.jcontours = self._csv("jcontours.csv")

    def _csv(self, name: str):
        path = self.folder / name
        if not path.exists():
            return [], None
        return read_csv_columns(path)

    # ---- archive.h5 --------------------------------------------------------------
    @property
    def archive_path(self) -> Path:
        return self.folder / "archive.h5"

    def _archive_keys(self, h5) -> list[str]:
        return sorted(h5["archives"].keys()) if "archives" in h5 else []

    def archive_times(self) -> np.ndarray:
        """Times (ms) of the particle archives, in step order (empty if none)."""
        if not self.archive_path.exists():
            return np.zeros(0)
        with h5py.File(self.archive_path, "r") as h5:
            return np.array([h5["archives"][k].attrs["time_ms"] for k in self._archive_keys(h5)],
                            dtype=np.float64)

    def archive(self, k: int) -> dict:
        """Archive number k (0 = first, -1 = last): particle arrays, component first,
        plus ``time_ms`` and ``step`` (and ``cracks``, a dict of the crack arrays, in
        scenes with cracks)."""
        with h5py.File(self.archive_path, "r") as h5:
            keys = self._archive_keys(h5)
            if not keys:
                raise IndexError(f"{self.archive_path} holds no archives")
            grp = h5["archives"][keys[k]]
            data = {name: ({k: v[()] for k, v in ds.items()} if isinstance(ds, h5py.Group)
                           else ds[()]) for name, ds in grp.items()}
            data["time_ms"] = float(grp.attrs["time_ms"])
            data["step"] = int(grp.attrs["step"])
        return data

    def material_names(self) -> list[str]:
        if not self.archive_path.exists():
            return self.run.get("materials", [])
        with h5py.File(self.archive_path, "r") as h5:
            return [n.decode() if isinstance(n, bytes) else str(n)
                    for n in h5.attrs.get("material_names", [])]

    def input_xml(self) -> str:
        with h5py.File(self.archive_path, "r") as h5:
            text = h5["input_xml"][()]
        return text.decode() if isinstance(text, bytes) else str(text)


def open_results(folder) -> Results:
    """Open a results folder written by ``nairnmpm run``."""
    return Results(folder)
