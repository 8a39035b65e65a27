"""The output-plugin interface the run loop calls (every hook is optional)."""
from __future__ import annotations

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
