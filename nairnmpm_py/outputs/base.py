"""The output-plugin interface the run loop calls (every hook is optional)."""
from __future__ import annotations

import os
from pathlib import Path


class OutputPlugin:
    """Base class for output plugins.

    The run loop calls ``begin`` once, ``on_global`` at each global archive time,
    ``on_archive`` at each particle archive time and ``end`` always, also after an
    instability or Ctrl-C, so a plugin should leave its files valid after every call.
    """

    name = "output"

    def __init__(self, folder: Path):
        self.folder = Path(folder)

    def begin(self, sim) -> None:
        pass

    def on_global(self, sim, row: dict) -> None:
        pass

    def on_archive(self, sim) -> None:
        pass

    def end(self, sim, status: dict) -> None:
        pass

    def resume(self, sim, step: int, time_ms: float) -> None:
        """Go on with this plugin's files after a checkpoint at ``step`` (``time_ms``),
        for ``nairnmpm resume``: keep what they hold up to it, drop what a run that
        went on past it wrote, and append from there, so the files end as if the run
        had never stopped.  Default: start them afresh (``begin``)."""
        self.begin(sim)


def keep_csv_rows(path: Path, column: str, keep) -> list[str]:
    """Rewrite the CSV ``path`` with its header and the complete rows (ending in a
    newline: a killed run may leave half a row) whose ``column`` cell passes
    ``keep(text)``; returns the header's columns ([] if there is no file or no such
    column: nothing is rewritten).  Atomic: a reader never sees half the file."""
    if not path.exists():
        return []
    lines = path.read_text().splitlines(keepends=True)
    if not lines or not lines[0].endswith("\n"):
        return []
    header = lines[0].rstrip("\n").split(",")
    if column not in header:
        return []
    at = header.index(column)
    rows = [ln for ln in lines[1:] if ln.endswith("\n") and keep(ln.rstrip("\n").split(",")[at])]
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text("".join([lines[0]] + rows))
    os.replace(tmp, path)
    return header
