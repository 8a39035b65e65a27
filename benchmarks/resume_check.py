"""A stopped or killed DCB, resumed, ends as if it had never stopped (``nairnmpm resume``).

    python benchmarks/resume_check.py [--threads 1 2] [--tmax 12] [--kills 3] [--seed 1]
                                      [--work /tmp/resume_check] [--out benchmarks/results]
    python benchmarks/resume_check.py --paper [--threads 2]

For each thread count, the DCB template (``inputs/dcb_bridging.xml``: 0.5 mm particles,
the cubic bridging law, criterion 7; its first growth near 10 ms) is run to --tmax ms

* in one go (the reference);
* stopped by SIGTERM once ``cracks.csv`` holds three growth rows (in the middle of
  the growth), then resumed;
* killed by SIGKILL --kills times at random moments (seeded), each time resumed from
  whatever checkpoint it left.

Each end must equal the reference: ``global.csv``, ``cracks.csv`` and the ``.pvd``
collections to the byte, ``archive.h5`` the same archives with identical arrays.
Rows go to ``resume_check.csv``.  ``--paper`` measures instead what a checkpoint of
the paper-resolution member (0.25 mm particles, 28,800 particles) costs: its size
and the time to write it (``paper_checkpoint.csv``).
"""
from __future__ import annotations

import argparse
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np

from csv_rows import write_rows

ROOT = Path(__file__).resolve().parents[1]
DCB = ROOT / "inputs" / "dcb_bridging.xml"
TEXT_FILES = ("global.csv", "cracks.csv", "particles.pvd", "cracks.pvd")


def _input(work: Path, tmax: float) -> Path:
    text = DCB.read_text()
    start = text.index('<!ENTITY tmax "') + len('<!ENTITY tmax "')
    text = text[:start] + f"{tmax:g}" + text[text.index('"', start):]
    path = work / "dcb.xml"
    path.write_text(text)
    return path


def _cmd(threads: int, *args: str) -> tuple[list[str], dict]:
    env = dict(os.environ, NUMBA_NUM_THREADS=str(threads))
    return [sys.executable, "-m", "nairnmpm_py.cli", *args, "-q"], env


def _run(threads: int, *args: str) -> int:
    cmd, env = _cmd(threads, *args)
    return subprocess.run(cmd, env=env, capture_output=True, text=True).returncode


def _start(threads: int, *args: str) -> subprocess.Popen:
    cmd, env = _cmd(threads, *args)
    return subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)


def _growth_rows(folder: Path) -> int:
    path = folder / "cracks.csv"
    return path.read_text().count(',"growth",') if path.exists() else 0


def _archives(folder: Path) -> tuple[list[str], dict]:
    with h5py.File(folder / "archive.h5", "r") as h5:
        keys = sorted(h5["archives"])
        out = {}
        for key in keys:
            h5["archives"][key].visititems(
                lambda name, obj: out.__setitem__(f"{key}/{name}", obj[()])
                if isinstance(obj, h5py.Dataset) else None)
        return keys, out


def _same(ref: Path, other: Path) -> str:
    """'' if ``other`` holds the same results as ``ref``, else what differs."""
    for name in TEXT_FILES:
        if (ref / name).exists() and (ref / name).read_bytes() != (other / name).read_bytes():
            return name
    try:
        keys_a, a = _archives(ref)
        keys_b, b = _archives(other)
    except OSError as exc:
        return f"archive.h5 unreadable: {exc}"
    if keys_a != keys_b:
        return f"archives {keys_a[-3:]} against {keys_b[-3:]}"
    bad = [k for k in a if not np.array_equal(a[k], b[k])]
    return f"arrays {bad[:3]}" if bad else ""


def _resume_until_done(threads: int, folder: Path) -> int:
    """Resume until the run ends (a resume of a finished run exits 2); the resumes."""
    resumes = 0
    while json.loads((folder / "run.json").read_text())["exit_status"] != "done":
        code = _run(threads, "resume", str(folder))
        resumes += 1
        if code != 0 or resumes > 10:
            raise RuntimeError(f"resume of {folder} exited {code}")
    return resumes


def check(threads: int, tmax: float, kills: int, seed: int, work: Path) -> list[dict]:
    work.mkdir(parents=True, exist_ok=True)
    xml = _input(work, tmax)
    rows = []
    ref = work / f"ref_t{threads}"
    t0 = time.perf_counter()
    assert _run(threads, "run", str(xml), "-o", str(ref), "--force") == 0
    wall = time.perf_counter() - t0
    info = json.loads((ref / "run.json").read_text())
    ck = info.get("checkpoints", {})
    size = (ref / "checkpoint.h5").stat().st_size / 1e6
    rows.append({"threads": threads, "case": "uninterrupted", "interruptions": 0,
                 "resumes": 0, "identical": "", "growth_rows": _growth_rows(ref),
                 "checkpoints": ck.get("written"), "checkpoint_mb": round(size, 2),
                 "checkpoint_ms": round(1e3 * ck.get("seconds", 0) / max(ck.get("written", 1), 1), 2),
                 "wall_s": round(wall, 1)})

    # SIGTERM in the middle of the growth
    folder = work / f"sigterm_t{threads}"
    shutil.rmtree(folder, ignore_errors=True)     # no stale files to wait on
    proc = _start(threads, "run", str(xml), "-o", str(folder), "--force")
    while proc.poll() is None and _growth_rows(folder) < 3:
        time.sleep(0.05)
    proc.send_signal(signal.SIGTERM)
    code = proc.wait()
    if code != 130:
        raise RuntimeError(f"the run was not stopped by SIGTERM (exit {code})")
    stopped_at = json.loads((folder / "run.json").read_text())["steps_taken"]
    resumes = _resume_until_done(threads, folder)
    diff = _same(ref, folder)
    rows.append({"threads": threads, "case": f"SIGTERM at step {stopped_at} (exit {code})",
                 "interruptions": 1, "resumes": resumes, "identical": not diff,
                 "growth_rows": _growth_rows(folder), "note": diff})

    # SIGKILL at random moments: of the first run, then of the resumes
    rng = random.Random(seed + threads)
    folder = work / f"sigkill_t{threads}"
    shutil.rmtree(folder, ignore_errors=True)
    proc = _start(threads, "run", str(xml), "-o", str(folder), "--force")
    done_kills = 0
    while done_kills < kills:
        # once stepping (a few rows written), somewhere in the next half of the run
        while proc.poll() is None and not (folder / "checkpoint.h5").exists():
            time.sleep(0.05)
        time.sleep(rng.uniform(0.0, 0.5 * wall))
        if proc.poll() is not None:
            break
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        done_kills += 1
        if done_kills < kills:
            proc = _start(threads, "resume", str(folder))
    resumes = _resume_until_done(threads, folder)
    diff = _same(ref, folder)
    rows.append({"threads": threads, "case": "SIGKILL at random moments",
                 "interruptions": done_kills, "resumes": resumes, "identical": not diff,
                 "growth_rows": _growth_rows(folder), "note": diff})
    return rows


def paper_checkpoint(threads: int, work: Path) -> list[dict]:
    """Size and write time of the paper-resolution member's checkpoint."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    from dcb_cost import make_input
    xml = make_input(0.25, "uGIMP", 0.2, work / "paper")
    folder = work / "paper_run"
    assert _run(threads, "run", str(xml), "-o", str(folder), "--force",
                "--checkpoint-every", "0.001") == 0
    info = json.loads((folder / "run.json").read_text())
    ck = info["checkpoints"]
    return [{"threads": threads, "particles": info["particles"],
             "steps": info["steps_taken"], "checkpoints": ck["written"],
             "checkpoint_mb": round((folder / "checkpoint.h5").stat().st_size / 1e6, 2),
             "checkpoint_ms": round(1e3 * ck["seconds"] / max(ck["written"], 1), 1),
             "wall_s": round(info["wall_seconds"], 1)}]


def _fields(rows: list[dict]) -> list[str]:
    return list(dict.fromkeys(k for r in rows for k in r))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--tmax", type=float, default=12.0)
    ap.add_argument("--kills", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--paper", action="store_true")
    ap.add_argument("--work", type=Path, default=Path("/tmp/resume_check"))
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    args = ap.parse_args(argv)
    if args.paper:
        rows = [r for n in args.threads for r in paper_checkpoint(n, args.work)]
        write_rows(args.out / "paper_checkpoint.csv", rows, _fields(rows))
    else:
        rows = [r for n in args.threads for r in check(n, args.tmax, args.kills, args.seed,
                                                       args.work)]
        write_rows(args.out / "resume_check.csv", rows, _fields(rows))
    for r in rows:
        print(r)
    return 0 if all(r.get("identical", True) is not False for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
