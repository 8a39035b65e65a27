"""Throughput benchmark: particle-updates per second, thread speed-up, compile and
start-up time and peak memory of two elastic scenes.

    python benchmarks/throughput.py                 # full version (a few minutes)
    python benchmarks/throughput.py --quick         # short runs, one repeat
    python benchmarks/throughput.py --threads 1 2 --out benchmarks/results

It (re)writes its inputs into ``benchmarks/inputs/`` (``cantilever_beam.xml``, the
NairnMPM comparison case, and ``block_30k.xml``), then for each case

* starts a fresh Python process with empty Numba and kernel caches (cold) and then
  one more with the same, now filled, caches (warm), each running import, load,
  prepare and one step: the cold one gives the compile time, the warm one the time
  from process start to the first step done;
* for each thread count: compiles that count's kernels into the cache in one process
  (kernels are compiled per scene), then in a second process
  loads them on a throw-away copy of the scene, and times ``sim.run([])`` on a fresh copy (best of
  ``--repeats``), and reports the peak resident memory of that process.

Results: ``OUT/throughput.csv`` (``throughput_quick.csv`` with ``--quick``) and a JSON
file with the details (machine, load averages, start-up break-down, every repeat).
See ``benchmarks/README.md``.
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
INPUTS = HERE / "inputs"

# ---- the scenes -----------------------------------------------------------------------
# One material for both: plane-strain wave speed c = sqrt((lambda + 2G) / rho).  With the
# default CFL factor 0.5 and 1 mm cells, dt = 0.5 mm / c; the beam's 3 ms should take
# about 11,500 steps (the NairnMPM reference run), so c = 0.5 * 11500 / 3 = 1917 m/s.
E_MPA = 3720.0
NU = 0.33
RHO = 1.5          # g/cm^3


def wave_speed(E=E_MPA, nu=NU, rho=RHO) -> float:
    """Plane-strain dilatational wave speed in m/s (= mm/ms)."""
    g = E / (2 * (1 + nu))
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    return math.sqrt((lam + 2 * g) / (rho * 1e-3))


def _one_body(grid: str, rect: str, name: str) -> str:
    """The mesh (1 mm cells), the one rectangular body and its material: the part of
    both scenes that differs only in sizes (``{rho:g}`` and ``{nu:g}`` stay fields)."""
    return f"""  <Mesh>
    <Grid {grid}>
      <Horiz cellsize="1"/>
      <Vert cellsize="1"/>
    </Grid>
  </Mesh>
  <MaterialPoints>
    <Body mat="1" thick="1">
      <Rect {rect}/>
    </Body>
  </MaterialPoints>
  <Material Type="1" Name="{name}">
    <rho>{{rho:g}}</rho>
    <E>&E;</E>
    <nu>{{nu:g}}</nu>
  </Material>
"""


BEAM_XML = """<?xml version="1.0"?>
<!DOCTYPE JANFEAInput [
  <!ENTITY E "{E:g}">
  <!ENTITY load "-1">
]>
<!-- Throughput benchmark (written by benchmarks/throughput.py; edit it there).
     Elastic cantilever beam, 100 x 12 mm, 1 mm cells, 2x2 particles per cell = 4,800
     particles; uGIMP, USAVG+, plane strain.  E = {E:g} MPa, nu = {nu:g}, rho = {rho:g} g/cm^3
     give c = sqrt((lambda + 2G)/rho) = {c:.1f} m/s, so dt = 0.5 * 1 mm / c = {dt:.5g} ms
     and 3 ms takes {steps} steps.  Clamped at x = 0, a 1 N (net) downward end load
     (the first bending period is about 3.3 ms). -->
<JANFEAInput version="3">
  <Header>
    <Description>Cantilever beam throughput benchmark (4,800 particles, uGIMP)</Description>
    <Analysis>10</Analysis>
  </Header>
  <MPMHeader>
    <MPMMethod>2</MPMMethod>
    <GIMP/>
    <MaxTime units="ms">3</MaxTime>
    <ArchiveTime units="ms">0.1</ArchiveTime>
    <TimeFactor>0.5</TimeFactor>
  </MPMHeader>
""" + _one_body('xmin="-4" xmax="108" ymin="-12" ymax="24"',
                   'xmin="0" xmax="100" ymin="0" ymax="12"', "beam") + """  <GridBCs>
    <BCLine x1="0" y1="min" x2="0" y2="max">
      <DisBC dir="1" vel="0"/>
      <DisBC dir="2" vel="0"/>
    </BCLine>
  </GridBCs>
  <ParticleBCs>
    <BCLine x1="99.75" y1="0" x2="99.75" y2="12">
      <net/>
      <LoadBC dir="2" style="1" load="&load;"/>
    </BCLine>
  </ParticleBCs>
</JANFEAInput>
"""

BLOCK_XML = """<?xml version="1.0"?>
<!DOCTYPE JANFEAInput [
  <!ENTITY E "{E:g}">
  <!ENTITY traction "-1">
]>
<!-- Throughput benchmark (written by benchmarks/throughput.py; edit it there).
     A larger scene: 150 x 50 mm block, 1 mm cells, 2x2 particles per cell = 30,000
     particles; uGIMP, USAVG+, plane strain, the material of cantilever_beam.xml.  Bottom
     edge on rollers (y velocity 0), left edge on rollers (x velocity 0), a 1 MPa
     compressive traction on the left half of the top face and a 1 N (net) downward load
     on the right edge.  TimeStep 2.5e-4 ms (under the CFL limit {dt:.5g} ms), so
     0.5 ms = 2,000 steps. -->
<JANFEAInput version="3">
  <Header>
    <Description>30k-particle block throughput benchmark (uGIMP)</Description>
    <Analysis>10</Analysis>
  </Header>
  <MPMHeader>
    <MPMMethod>2</MPMMethod>
    <GIMP/>
    <MaxTime units="ms">0.5</MaxTime>
    <TimeStep units="ms">2.5e-4</TimeStep>
    <ArchiveTime units="ms">0.05</ArchiveTime>
  </MPMHeader>
""" + _one_body('xmin="-4" xmax="160" ymin="-4" ymax="60"',
                   'xmin="0" xmax="150" ymin="0" ymax="50"', "block") + """  <GridBCs>
    <BCLine x1="min" y1="0" x2="max" y2="0">
      <DisBC dir="2" vel="0"/>
    </BCLine>
    <BCLine x1="0" y1="min" x2="0" y2="max">
      <DisBC dir="1" vel="0"/>
    </BCLine>
  </GridBCs>
  <ParticleBCs>
    <LdRect xmin="0" xmax="75" ymin="49.5" ymax="50">
      <TractionBC dir="2" face="3" stress="&traction;" style="1"/>
    </LdRect>
    <BCLine x1="149.75" y1="0" x2="149.75" y2="50">
      <net/>
      <LoadBC dir="2" style="1" load="-1"/>
    </BCLine>
  </ParticleBCs>
</JANFEAInput>
"""

# name -> (file, template, steps in --quick mode; full mode runs the file as written)
CASES = {
    "cantilever_beam": ("cantilever_beam.xml", BEAM_XML, 1150),
    "block_30k": ("block_30k.xml", BLOCK_XML, 200),
}


def write_inputs() -> dict[str, Path]:
    c = wave_speed()
    dt = 0.5 * 1.0 / c
    steps = math.ceil(3.0 / dt - 1e-9)
    INPUTS.mkdir(parents=True, exist_ok=True)
    paths = {}
    for name, (fname, template, _) in CASES.items():
        text = template.format(E=E_MPA, nu=NU, rho=RHO, c=c, dt=dt, steps=steps)
        path = INPUTS / fname
        if not path.exists() or path.read_text() != text:
            path.write_text(text)
        paths[name] = path
    return paths


# ---- workers (run in their own processes) -----------------------------------------------
def _busy_cpu_s() -> float | None:
    """CPU seconds all processes have used (user + system, all cores), from /proc/stat."""
    try:
        fields = Path("/proc/stat").read_text().splitlines()[0].split()[1:]
    except OSError:
        return None
    user, nice, system, idle, iowait, irq, softirq, steal = (int(x) for x in fields[:8])
    return (user + nice + system + irq + softirq) / os.sysconf("SC_CLK_TCK")


def _rss_mb() -> float:
    import resource
    kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # KiB on Linux
    return kb / (1024.0 * 1024.0) if sys.platform == "darwin" else kb / 1024.0


def worker_start(path: str, threads: int = 0) -> None:
    """Import, load, prepare and one step; print the time of each part."""
    t0 = time.perf_counter()
    from nairnmpm_py.input import load_simulation
    if threads:
        import numba
        numba.set_num_threads(threads)
    t1 = time.perf_counter()
    sim = load_simulation(path)
    t2 = time.perf_counter()
    sim.prepare()
    t3 = time.perf_counter()
    sim.advance(1)
    t4 = time.perf_counter()
    print(json.dumps({"first_step_epoch": time.time(), "import_s": t1 - t0, "load_s": t2 - t1,
                      "prepare_s": t3 - t2, "first_step_s": t4 - t3,
                      "peak_rss_mb": _rss_mb()}), flush=True)


def worker_throughput(path: str, threads: int, steps: int, repeats: int) -> None:
    """Time ``sim.run([])`` with the kernels already compiled; best of ``repeats``."""
    import numba
    from nairnmpm_py.input import load_simulation
    numba.set_num_threads(threads)
    warm = load_simulation(path)           # load the kernels (compiled by a "start" worker)
    warm.prepare()
    warm.advance(2)
    runs, cpu, others = [], [], []
    for _ in range(repeats):
        sim = load_simulation(path)
        if steps > 0:
            sim.max_time = steps * sim.dt
        sim.prepare()                      # reads numba.get_num_threads() for its chunks
        assert sim.nch == threads, (sim.nch, threads)
        busy = _busy_cpu_s()
        c = time.process_time()
        t = time.perf_counter()
        sim.run([])
        runs.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
        # CPU time other processes took meanwhile, as a share of the machine
        if busy is not None:
            other = max(0.0, _busy_cpu_s() - busy - cpu[-1])
            others.append(other / (runs[-1] * (os.cpu_count() or 1)))
    best = min(range(repeats), key=runs.__getitem__)
    print(json.dumps({"particles": int(sim.particles.n), "steps": int(sim.step),
                      "wall_runs_s": runs, "cpu_runs_s": cpu, "others_cpu_share": others,
                      "wall_s": runs[best], "cpu_s": cpu[best], "nch": sim.nch,
                      "others_cpu_share_best": others[best] if others else None,
                      "peak_rss_mb": _rss_mb()}), flush=True)


# ---- driver ---------------------------------------------------------------------------
def _child(args: list[str], env: dict) -> tuple[dict, float]:
    """Run this file as a worker; return its JSON line and the epoch it was started."""
    start = time.time()
    proc = subprocess.run([sys.executable, str(Path(__file__).resolve()), *args], env=env,
                          capture_output=True, text=True)
    if proc.returncode != 0:
        sys.stderr.write(proc.stdout + proc.stderr)
        raise SystemExit(f"worker {' '.join(args)} failed (exit {proc.returncode})")
    line = [ln for ln in proc.stdout.splitlines() if ln.startswith("{")][-1]
    return json.loads(line), start


def _loadavg() -> list[float]:
    try:
        return list(os.getloadavg())
    except OSError:
        return []


def _machine() -> dict:
    info = {"python": sys.version.split()[0], "platform": platform.platform(),
            "cpus": os.cpu_count()}
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                info["cpu"] = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        import numba
        import numpy
        info["numba"] = numba.__version__
        info["numpy"] = numpy.__version__
    except ImportError:
        pass
    try:
        info["git_commit"] = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=HERE,
                                            capture_output=True, text=True).stdout.strip()
    except OSError:
        pass
    return info


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true",
                    help="short runs (beam 1,150 steps, block 200), one repeat; writes "
                         "throughput_quick.csv")
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2],
                    help="thread counts to time (default 1 2)")
    ap.add_argument("--out", default=str(HERE / "results"), help="results folder")
    ap.add_argument("--repeats", type=int, default=None,
                    help="timed runs per case and thread count, best kept (default 3, "
                         "1 with --quick)")
    ap.add_argument("--cases", nargs="+", choices=list(CASES), default=list(CASES))
    ap.add_argument("--worker", nargs="+", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)

    if args.worker:
        kind, rest = args.worker[0], args.worker[1:]
        if kind == "start":
            worker_start(rest[0], int(rest[1]) if len(rest) > 1 else 0)
        else:
            worker_throughput(rest[0], int(rest[1]), int(rest[2]), int(rest[3]))
        return 0

    repeats = args.repeats or (1 if args.quick else 3)
    paths = write_inputs()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    stem = "throughput_quick" if args.quick else "throughput"
    details = {"date": time.strftime("%Y-%m-%d %H:%M:%S %z"), "machine": _machine(),
               "quick": args.quick, "repeats": repeats, "threads": args.threads,
               "loadavg_begin": _loadavg(), "cases": {}}
    rows = []
    base_env = dict(os.environ)
    base_env["NUMBA_NUM_THREADS"] = str(max(max(args.threads), os.cpu_count() or 1))
    for name in args.cases:
        path = str(paths[name])
        steps = CASES[name][2] if args.quick else 0
        case = details["cases"][name] = {"input": os.path.relpath(path, Path.cwd())}
        with tempfile.TemporaryDirectory(prefix="nairnmpm_bench_") as tmp:
            env = dict(base_env)
            env["NUMBA_CACHE_DIR"] = os.path.join(tmp, "numba")
            env["NAIRNMPM_PY_CACHE"] = os.path.join(tmp, "kernels")
            os.makedirs(env["NUMBA_CACHE_DIR"])
            os.makedirs(env["NAIRNMPM_PY_CACHE"])
            starts = {}
            for label in ("cold", "warm"):
                print(f"[{name}] {label} start ...", file=sys.stderr, flush=True)
                info, t_spawn = _child(["--worker", "start", path], env)
                info["process_to_first_step_s"] = info.pop("first_step_epoch") - t_spawn
                info["loadavg"] = _loadavg()
                starts[label] = info
            case["start"] = starts
            compile_cold = starts["cold"]["prepare_s"] + starts["cold"]["first_step_s"]
            warm_start = starts["warm"]["process_to_first_step_s"]
            results = {}
            for n in args.threads:
                print(f"[{name}] {n} thread(s), {repeats} run(s) ...", file=sys.stderr, flush=True)
                # compile (or load) this thread count's kernels in a process of its own
                # first, so that the timed process's peak
                # memory is that of a warm run
                _child(["--worker", "start", path, str(n)], env)
                info, _ = _child(["--worker", "throughput", path, str(n), str(steps),
                                  str(repeats)], env)
                share = info.get("others_cpu_share_best")
                if share is not None and share > 0.05:
                    print(f"  warning: other processes used {100 * share:.0f}% of the machine "
                          "during the best run; its time may be slow", file=sys.stderr, flush=True)
                results[n] = info
            case["throughput"] = {str(k): v for k, v in results.items()}
        base = results.get(1)
        for n in args.threads:
            r = results[n]
            rate = r["particles"] * r["steps"] / r["wall_s"]
            rows.append({
                "case": name, "particles": r["particles"], "steps": r["steps"], "threads": n,
                "wall_s": round(r["wall_s"], 3),
                "particle_updates_per_s": round(rate),
                "speedup_vs_1thread": round(base["wall_s"] / r["wall_s"], 3) if base else "",
                "compile_cold_s": round(compile_cold, 2),
                "warm_start_s": round(warm_start, 2),
                "peak_rss_mb": round(r["peak_rss_mb"], 1)})
            print("  " + ", ".join(f"{k}={v}" for k, v in rows[-1].items()), file=sys.stderr)
    details["loadavg_end"] = _loadavg()
    fields = ["case", "particles", "steps", "threads", "wall_s", "particle_updates_per_s",
              "speedup_vs_1thread", "compile_cold_s", "warm_start_s", "peak_rss_mb"]
    with open(out / f"{stem}.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        w.writerows(rows)
    (out / f"{stem}_details.json").write_text(json.dumps(details, indent=1) + "\n")
    # the table, for the terminal
    widths = [max(len(h), *(len(str(r[h])) for r in rows)) for h in fields]
    print("  ".join(h.rjust(w) for h, w in zip(fields, widths)))
    for r in rows:
        print("  ".join(str(r[h]).rjust(w) for h, w in zip(fields, widths)))
    print(f"wrote {out / (stem + '.csv')} and {out / (stem + '_details.json')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
