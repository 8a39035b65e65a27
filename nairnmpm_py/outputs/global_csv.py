"""global.csv: one row of global quantities per global archive time."""
from __future__ import annotations

from numbers import Integral
from pathlib import Path

from .base import OutputPlugin, keep_csv_rows


def _format(value) -> str:
    # integers (the step) in full; floats with 10 significant digits
    if isinstance(value, Integral):
        return str(int(value))
    return "%.10g" % float(value)


class GlobalCsv(OutputPlugin):
    name = "global_csv"
    filename = "global.csv"

    def __init__(self, folder: Path):
        super().__init__(folder)
        self._file = None
        self._columns: list[str] | None = None

    def begin(self, sim) -> None:
        self._file = open(self.folder / self.filename, "w", newline="\n")
        self._columns = None

    def on_global(self, sim, row: dict) -> None:
        if self._file is None:
            self.begin(sim)
        if self._columns is None:
            self._columns = list(row)
            self._file.write(",".join(self._columns) + "\n")
        # a run resumed with --force from a changed input may lack a column: empty
        self._file.write(",".join(_format(row[c]) if c in row else "" for c in self._columns)
                         + "\n")
        # flushed per row so a crash or kill leaves every finished row on disk
        self._file.flush()

    def resume(self, sim, step: int, time_ms: float) -> None:
        path = self.folder / self.filename
        header = keep_csv_rows(path, "step", lambda cell: int(cell) <= step)
        if not header:
            self.begin(sim)
            return
        self._file = open(path, "a", newline="\n")
        self._columns = header

    def end(self, sim, status: dict) -> None:
        if self._file is not None:
            self._file.close()
            self._file = None
