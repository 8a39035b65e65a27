"""The outputs a run writes: every registered output plugin (built-in or not)."""
from __future__ import annotations

from pathlib import Path

from .. import plugins


def default_outputs(folder: Path) -> list:
    return [p.cls(Path(folder)) for p in plugins.registry("outputs")]
