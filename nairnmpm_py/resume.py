"""Continue a run from the checkpoint in its results folder (``nairnmpm resume``).

The simulation is built again from the input file (or, if that file is gone, from
the input text the checkpoint holds), its state restored from the checkpoint
(``core.checkpoint``), and every output told to go on with its files
(``OutputPlugin.resume``).  At the same thread count the resumed run equals one that
never stopped, to the bit: every row of global.csv and cracks.csv, and every archive.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

from .core.checkpoint import FILENAME, Checkpoint, read_checkpoint, restore


class ResumeError(Exception):
    """A results folder that cannot be resumed (one line, exit 2)."""


def load_resumable(folder: Path, max_time: float | None = None, force: bool = False):
    """(simulation at the folder's last checkpoint, that checkpoint), ready for
    ``Simulation.run(..., resumed=True)``.  ``max_time`` (ms) replaces the input's
    MaxTime (to extend a finished run).  The input file must be unchanged since the
    run started (its sha256), unless ``force``."""
    from .input import load_simulation
    folder = Path(folder)
    if not folder.is_dir():
        raise ResumeError(f"{folder}: no such results folder")
    try:
        ck = read_checkpoint(folder)
    except FileNotFoundError:
        raise ResumeError(f"{folder}: no checkpoint ({FILENAME}) to resume from; runs write "
                          "one after each archive and when interrupted") from None
    except (OSError, ValueError, KeyError) as exc:
        raise ResumeError(f"{folder / FILENAME}: unreadable checkpoint: {exc}") from None
    path = _input_path(folder, ck, force)
    sim = load_simulation(path)
    if max_time is not None:
        if max_time * (1 + 1e-12) < ck.time_ms:
            raise ResumeError(f"--max-time {max_time:g} ms is before the checkpoint "
                              f"({ck.time_ms:.6g} ms)")
        sim.max_time = float(max_time)
    try:
        restore(sim, ck)
    except ValueError as exc:
        raise ResumeError(str(exc)) from None
    sim.wall_before = ck.wall_seconds
    sim.couples = _couples(sim, ck.state.get("couples"))
    return sim, ck


def _couples(sim, saved):
    """global.csv's load groups as the first part found them."""
    if saved is None:
        return None
    import numpy as np

    from .outputs.load_couples import LoadCouple
    ids = np.asarray(sim.conditions.part_ids, dtype=np.int64)
    recs_of = np.asarray(sim.conditions.part_recs, dtype=np.int64)
    return [LoadCouple(name, np.array(recs, dtype=np.int64), [ids[recs_of == r] for r in recs])
            for name, recs in saved]


def _input_path(folder: Path, ck: Checkpoint, force: bool) -> Path:
    """The input to build from: the run's own file if it still exists (refused if it
    changed, unless ``force``), else the checkpoint's copy of its text."""
    try:
        recorded = json.loads((folder / "run.json").read_text())["input"]["path"]
    except (OSError, ValueError, KeyError, TypeError):
        recorded = None
    if recorded and Path(recorded).is_file():
        path = Path(recorded)
        sha = hashlib.sha256(path.read_bytes()).hexdigest()
        if sha != ck.input_sha256 and not force:
            raise ResumeError(f"{path}: changed since the run in {folder} started (sha256 "
                              "differs); use --force to resume with the file as it is now")
        return path
    copy = folder / "input_from_checkpoint.xml"
    copy.write_text(ck.input_xml)
    return copy
