"""Files that are either whole or not there: written aside, then renamed into place.

A run killed at any moment (SIGKILL, a job scheduler's hard limit, a full disk) then
leaves the previous version of each such file intact; the rename is atomic on POSIX
file systems, and the data is flushed to disk before it, so a machine that goes down
does not leave a renamed but empty file either.
"""
from __future__ import annotations

import os
from pathlib import Path


def aside(path: Path) -> Path:
    """Where ``path`` is written before ``replace_durably`` puts it in place."""
    return path.with_name(path.name + ".tmp")


def replace_durably(tmp: Path, path: Path) -> None:
    """Flush the completely written ``tmp`` to disk and rename it over ``path``."""
    fd = os.open(tmp, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)
    os.replace(tmp, path)
