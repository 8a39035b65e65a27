"""``nairnmpm resume``: a run stopped at a checkpoint and resumed ends as if it had never
stopped, to the bit (same thread count), for a plain scene and for a crack stopped in
the middle of its growth; bad resumes are refused with one line and exit 2."""
from __future__ import annotations

import json
from pathlib import Path

import h5py
import numpy as np
import pytest

from nairnmpm_py.cli import main
from nairnmpm_py.core.checkpoint import Checkpoints
from nairnmpm_py.input import load_simulation
from nairnmpm_py.outputs.defaults import default_outputs

from test_propagation import sent_growing

ROOT = Path(__file__).resolve().parent.parent
RAMP = ROOT / "inputs" / "ramped_load_bar.xml"
TEXT_FILES = ("global.csv", "cracks.csv", "particles.pvd", "cracks.pvd")


def _stopped_run(xml: Path, folder: Path, stop) -> int:
    """Run ``xml`` into ``folder`` as ``nairnmpm run`` does, asking it to stop (as
    Ctrl-C does) at the first progress report where ``stop(sim)`` is true."""
    sim = load_simulation(xml)
    folder.mkdir()

    def progress(fraction, time_ms, step, rate):
        if stop(sim):
            sim.request_stop()
    with pytest.raises(KeyboardInterrupt):
        sim.run(default_outputs(folder), progress=progress, checkpoints=Checkpoints(folder))
    assert json.loads((folder / "run.json").read_text())["exit_status"] == "interrupted"
    return sim.step


def _last_archive(folder: Path) -> tuple[str, dict]:
    with h5py.File(folder / "archive.h5", "r") as h5:
        keys = sorted(h5["archives"])
        grp = h5["archives"][keys[-1]]
        arrays = {k: v[()] for k, v in grp.items() if isinstance(v, h5py.Dataset)}
        if "cracks" in grp:
            arrays.update({"cracks/" + k: v[()] for k, v in grp["cracks"].items()})
        return keys, arrays


def _assert_same_results(ref: Path, resumed: Path, resumes: int | None = 1) -> None:
    for name in TEXT_FILES:
        if (ref / name).exists():
            assert (resumed / name).read_text() == (ref / name).read_text(), name
    keys_ref, last_ref = _last_archive(ref)
    keys_res, last_res = _last_archive(resumed)
    assert keys_res == keys_ref
    assert last_res.keys() == last_ref.keys()
    for k in last_ref:
        assert np.array_equal(last_res[k], last_ref[k]), k
    info = json.loads((resumed / "run.json").read_text())
    assert info["exit_status"] == "done"
    assert info["steps_taken"] == json.loads((ref / "run.json").read_text())["steps_taken"]
    if resumes is not None:
        assert len(info["resumes"]) == resumes


def test_a_plain_run_resumed_equals_one_never_stopped(tmp_path):
    ref = tmp_path / "ref"
    assert main(["run", str(RAMP), "-o", str(ref), "-q"]) == 0
    stopped = tmp_path / "stopped"
    at = _stopped_run(RAMP, stopped, lambda sim: sim.step >= 700)
    total = json.loads((ref / "run.json").read_text())["steps_taken"]
    assert 700 <= at < total
    # rows a run killed after the checkpoint wrote past it are dropped on resume
    with open(stopped / "global.csv", "a") as f:
        f.write("9.9,99999" + ",0" * 20 + "\n1.0,12")
    assert main(["resume", str(stopped), "-q"]) == 0
    _assert_same_results(ref, stopped)


def test_a_crack_stopped_during_growth_resumes_to_the_same_R_curve(tmp_path):
    xml = sent_growing(tmp_path, tprop=True)
    ref = tmp_path / "ref"
    assert main(["run", str(xml), "-o", str(ref), "-q"]) == 0
    stopped = tmp_path / "stopped"
    _stopped_run(xml, stopped, lambda sim: len(sim.cracks.growth_log) >= 3)
    rows = (stopped / "cracks.csv").read_text().count("growth")
    assert 3 <= rows < (ref / "cracks.csv").read_text().count("growth")
    assert main(["resume", str(stopped), "-q"]) == 0
    _assert_same_results(ref, stopped)
    # growth counts, failed law particles, the watch's full checks: all the same
    assert (json.loads((stopped / "run.json").read_text())["cracks"]
            == json.loads((ref / "run.json").read_text())["cracks"])


def test_max_time_extends_a_finished_run(tmp_path):
    out = tmp_path / "out"
    assert main(["run", str(RAMP), "-o", str(out), "-q"]) == 0
    info = json.loads((out / "run.json").read_text())
    assert main(["resume", str(out), "-q"]) == 2          # done: nothing to resume
    t_end = 1.5 * info["max_time_ms"]
    assert main(["resume", str(out), "-q", "--max-time", str(t_end)]) == 0
    info = json.loads((out / "run.json").read_text())
    assert info["time_reached_ms"] == pytest.approx(t_end, abs=info["time_step_ms"])
    assert info["resumes"][0]["from_step"] > 0


def test_resume_refuses_a_changed_input_and_a_folder_without_checkpoint(tmp_path, capsys):
    xml = tmp_path / "bar.xml"
    xml.write_text(RAMP.read_text())
    stopped = tmp_path / "stopped"
    _stopped_run(xml, stopped, lambda sim: sim.step >= 200)
    xml.write_text(RAMP.read_text().replace("</MaxTime>", "</MaxTime><!-- edited -->", 1))
    capsys.readouterr()
    assert main(["resume", str(stopped), "-q"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"{xml}: changed since the run") and "--force" in err
    assert len(err.splitlines()) == 1
    assert main(["resume", str(stopped), "-q", "--force"]) == 0
    empty = tmp_path / "empty"
    empty.mkdir()
    assert main(["resume", str(empty), "-q"]) == 2
    assert "no checkpoint" in capsys.readouterr().err


def test_runs_killed_at_random_moments_resume_to_the_same_results(tmp_path):
    """SIGKILL gives no chance to clean up: whatever checkpoint and archives it leaves
    must be whole, and resuming from them must end as the run that was never killed."""
    import random
    import signal
    import subprocess
    import sys
    import time
    xml = tmp_path / "ramp.xml"
    xml.write_text(RAMP.read_text().replace('<MaxTime units="ms">2</MaxTime>',
                                            '<MaxTime units="ms">8</MaxTime>'))
    ref = tmp_path / "ref"
    assert main(["run", str(xml), "-o", str(ref), "-q"]) == 0
    wall = json.loads((ref / "run.json").read_text())["wall_seconds"]
    out = tmp_path / "killed"
    rng = random.Random(14)
    command = [sys.executable, "-m", "nairnmpm_py.cli", "run", str(xml), "-o", str(out), "-q"]
    kills = 0
    for _ in range(3):
        proc = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        deadline = time.monotonic() + 300
        while (proc.poll() is None and not (out / "checkpoint.h5").exists()
               and time.monotonic() < deadline):
            time.sleep(0.02)
        time.sleep(rng.uniform(0.0, 0.6 * wall))
        if proc.poll() is None:
            proc.send_signal(signal.SIGKILL)
            kills += 1
        proc.wait()
        command = [sys.executable, "-m", "nairnmpm_py.cli", "resume", str(out), "-q"]
    assert kills >= 2
    while json.loads((out / "run.json").read_text())["exit_status"] != "done":
        assert main(["resume", str(out), "-q"]) == 0
    _assert_same_results(ref, out, resumes=None)
