"""cracks.csv (one row per crack tip per archive time) and jcontours.csv (J on every
contour size an input lists, per tip per archive time).

Columns are those of DESIGN.md section 3 plus ``contour_cells`` (the half-size of the
contour used), ``J_contour_J_m2`` (the contour value J(x) itself),
``W_B_crossing_J_m2`` (the traction work where the contour crosses the crack) and
``event`` (``archive`` for the rows written at archive times, ``growth`` for the row
of a tip taken at the check that made it grow) and ``error`` (why J could not be
computed at that tip, e.g. the contour left the grid).  R (Eq 15) needs the critical
J_tip of a propagation criterion: it is empty until the tip has grown.
"""
from __future__ import annotations

import math
from pathlib import Path

from .base import OutputPlugin, keep_csv_rows

COLUMNS = ["time_ms", "crack", "tip", "contour_cells", "tip_x_mm", "tip_y_mm",
           "crack_growth_mm", "root_x_mm", "root_y_mm", "zone_length_mm", "J_contour_J_m2",
           "J_tip_J_m2", "J_ff_J_m2", "W_B_crossing_J_m2", "W_B_root_J_m2",
           "W_B_rec_root_J_m2", "R_J_m2", "cod_root_mm", "cod_notch0_mm", "KI_MPa_sqrt_m",
           "KII_MPa_sqrt_m", "event", "error"]


def _cell(v) -> str:
    if isinstance(v, str):
        return '"' + v.replace('"', "'") + '"' if v else ""
    if isinstance(v, int):
        return str(v)
    v = float(v)
    return "" if math.isnan(v) else "%.10g" % v


class _CsvFile:
    def __init__(self, path: Path, append: bool = False):
        self.file = open(path, "a" if append else "w", newline="\n")
        if not append:
            self.file.write(",".join(COLUMNS) + "\n")

    def write(self, rows: list[dict]) -> None:
        for r in rows:
            self.file.write(",".join(_cell(r[c]) for c in COLUMNS) + "\n")
        self.file.flush()   # a killed run keeps every finished row

    def close(self) -> None:
        self.file.close()


class CracksCsv(OutputPlugin):
    name = "cracks_csv"
    filename = "cracks.csv"

    def __init__(self, folder: Path):
        super().__init__(folder)
        self._tips = None
        self._contours = None

    def begin(self, sim) -> None:
        scene = getattr(sim, "cracks", None)
        if scene is None or not scene.tips:
            return
        self._tips = _CsvFile(self.folder / self.filename)
        if scene.jcontour_sizes:
            self._contours = _CsvFile(self.folder / "jcontours.csv")

    def on_archive(self, sim) -> None:
        if self._tips is None:
            return
        scene = sim.cracks
        self._tips.write(scene.tip_results(sim))
        if self._contours is not None:
            self._contours.write(scene.tip_results(sim, sizes=scene.jcontour_sizes))

    def on_crack_growth(self, sim, rows: list[dict]) -> None:
        """Rows of the tips that just grew (``event`` = growth), taken at the check
        that made them grow."""
        if self._tips is not None:
            self._tips.write(rows)

    def resume(self, sim, step: int, time_ms: float) -> None:
        """Rows up to the checkpoint's time stay (the next step's are dt later)."""
        scene = getattr(sim, "cracks", None)
        if scene is None or not scene.tips:
            return
        late = time_ms + 0.5 * sim.dt
        names = [self.filename] + (["jcontours.csv"] if scene.jcontour_sizes else [])
        files = []
        for name in names:
            path = self.folder / name
            if keep_csv_rows(path, "time_ms", lambda cell: float(cell) <= late) == COLUMNS:
                files.append(_CsvFile(path, append=True))
            else:
                files.append(_CsvFile(path))
        self._tips = files[0]
        self._contours = files[1] if len(files) > 1 else None

    def end(self, sim, status: dict) -> None:
        for f in (self._tips, self._contours):
            if f is not None:
                f.close()
        self._tips = self._contours = None
