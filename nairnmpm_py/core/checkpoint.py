"""Checkpoints: everything the step needs to continue a run exactly (``nairnmpm resume``).

``checkpoint.h5`` in the results folder holds

* attrs: ``format``, ``step``, ``time_ms``, ``input_sha256``, ``chunks`` (particle chunks
  of the step, from the thread count), ``wall_seconds`` (of the run so far);
* ``input_xml``: the input text, as parsed;
* ``arrays/<owner>/<name>``: every array of the simulation (grid, conditions, clock and
  carried stress half), of its particles and, in a scene with cracks, of the crack
  scene and its crack set (traction histories, edge maxima, crack lists);
* ``state``: JSON of the Python-side state: whether the grid holds the current
  extrapolation, global.csv's load groups and the crack scene's own
  (``CrackScene.checkpoint_state``: tips' growth, notch roots, growth log).

A checkpoint is taken between driver calls, after that call's outputs, so the state
and the files written agree.  It is written to a temporary file, flushed to disk and
renamed over the previous one: a kill at any moment leaves a whole checkpoint.
"""
from __future__ import annotations

import json
import time as wallclock
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

from .durable import aside, replace_durably

FORMAT = 1
FILENAME = "checkpoint.h5"
# process addresses, not state: a resumed run gets its own
NOT_STATE = {"sim": {"faddr", "task_at"}}
# arrays with one row per particle chunk (their count follows the thread count)
PER_CHUNK = {"sim": {"gbuf", "bad"}, "scene": {"chunk_counts"}}


def _owners(sim) -> dict:
    owners = {"sim": sim, "particles": sim.particles}
    if sim.cracks is not None:
        owners["scene"] = sim.cracks
        owners["crackset"] = sim.cracks.cracks
    return owners


def _python_state(sim) -> dict:
    state = {"grid_current": bool(sim.grid_current),
             # global.csv's load groups are found once, at the first row (the resume
             # rebuilds them from these: the grown cracks could split them otherwise)
             "couples": None if sim.couples is None else
             [[c.name, [int(r) for r in c.records]] for c in sim.couples]}
    if sim.cracks is not None:
        state["cracks"] = sim.cracks.checkpoint_state()
    return state


def write_checkpoint(sim, folder: Path, wall_seconds: float) -> Path:
    """Write ``folder/checkpoint.h5`` for ``sim`` as it stands (between driver calls)."""
    path = Path(folder) / FILENAME
    tmp = aside(path)
    with h5py.File(tmp, "w") as h5:
        h5.attrs["format"] = FORMAT
        h5.attrs["step"] = int(sim.step)
        h5.attrs["time_ms"] = float(sim.time)
        h5.attrs["input_sha256"] = (sim.source or {}).get("sha256") or ""
        h5.attrs["chunks"] = int(sim.nch)
        h5.attrs["wall_seconds"] = float(wall_seconds)
        h5.attrs["written"] = wallclock.strftime("%Y-%m-%dT%H:%M:%S")
        h5.create_dataset("input_xml", data=(sim.source or {}).get("text", "") or "",
                          dtype=h5py.string_dtype())
        arrays = h5.create_group("arrays")
        for owner, obj in _owners(sim).items():
            grp = arrays.create_group(owner)
            for name, value in vars(obj).items():
                if isinstance(value, np.ndarray) and name not in NOT_STATE.get(owner, ()):
                    grp.create_dataset(name, data=value)
        h5.attrs["state"] = json.dumps(_python_state(sim))
    replace_durably(tmp, path)
    return path


@dataclass
class Checkpoint:
    path: Path
    step: int
    time_ms: float
    input_sha256: str
    input_xml: str
    chunks: int
    wall_seconds: float
    arrays: dict        # owner -> {name: array}
    state: dict


def read_checkpoint(folder: Path) -> Checkpoint:
    """The checkpoint of a results folder; FileNotFoundError if it has none."""
    path = Path(folder) / FILENAME
    if not path.is_file():
        raise FileNotFoundError(path)
    with h5py.File(path, "r") as h5:
        if int(h5.attrs.get("format", 0)) != FORMAT:
            raise ValueError(f"{path}: checkpoint format {h5.attrs.get('format')} is not "
                             f"this version's ({FORMAT})")
        arrays = {owner: {name: ds[()] for name, ds in grp.items()}
                  for owner, grp in h5["arrays"].items()}
        return Checkpoint(path, int(h5.attrs["step"]), float(h5.attrs["time_ms"]),
                          str(h5.attrs["input_sha256"]),
                          h5["input_xml"][()].decode() if isinstance(h5["input_xml"][()], bytes)
                          else str(h5["input_xml"][()]),
                          int(h5.attrs["chunks"]), float(h5.attrs["wall_seconds"]), arrays,
                          json.loads(h5.attrs["state"]))


def restore(sim, ck: Checkpoint) -> None:
    """Put the checkpoint's state into ``sim``, a simulation freshly built from the same
    input and prepared.  With another thread count than the checkpoint's, the per-chunk
    scratch starts empty and the count of particles that left the grid is kept in the
    first chunk (the run continues, though not to the bit)."""
    sim.prepare()
    owners = _owners(sim)
    if set(ck.arrays) != set(owners):
        raise ValueError(f"{ck.path}: holds {sorted(ck.arrays)}, the input builds "
                         f"{sorted(owners)}")
    same_chunks = ck.chunks == sim.nch
    for owner, saved in ck.arrays.items():
        obj = owners[owner]
        for name, value in saved.items():
            if not same_chunks and name in PER_CHUNK.get(owner, ()):
                continue
            live = getattr(obj, name, None)
            if isinstance(live, np.ndarray) and live.dtype != value.dtype:
                raise ValueError(f"{ck.path}: {owner}.{name} is {value.dtype}, the input "
                                 f"builds {live.dtype}")
            setattr(obj, name, np.ascontiguousarray(value))
    if not same_chunks:
        sim.bad[:] = 0
        sim.bad[:, 0] = -1
        sim.bad[0, 2] = int(ck.arrays["sim"]["bad"][:, 2].sum())
    sim.step = ck.step
    sim.time = ck.time_ms
    sim.grid_current = bool(ck.state["grid_current"])
    if sim.cracks is not None:
        sim.cracks.restore_checkpoint_state(ck.state["cracks"], str(ck.path))


class Checkpoints:
    """When a run writes its checkpoint: at archive times, every ``every_minutes`` of
    wall time (None: never by time), and when it is stopped by a signal."""

    def __init__(self, folder: Path, every_minutes: float | None = None):
        self.folder = Path(folder)
        self.every = None if every_minutes is None else 60.0 * float(every_minutes)
        self.last = wallclock.perf_counter()
        self.written = 0
        self.last_step = -1
        self.seconds = 0.0      # spent writing them

    def due(self, archived: bool) -> bool:
        return archived or (self.every is not None
                            and wallclock.perf_counter() - self.last >= self.every)

    def write(self, sim, wall_seconds: float) -> None:
        t0 = wallclock.perf_counter()
        write_checkpoint(sim, self.folder, wall_seconds)
        self.last = wallclock.perf_counter()
        self.written += 1
        self.last_step = int(sim.step)
        self.seconds += self.last - t0
