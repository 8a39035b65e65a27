"""The ``nairnmpm`` command: a thin layer over the package's functions.

Exit codes: 0 done, 2 bad input, 3 the simulation went unstable, 130 interrupted
(after a checkpoint: ``nairnmpm resume DIR`` goes on).
"""
from __future__ import annotations

import argparse
import shutil
import signal
import sys
from pathlib import Path

from . import __version__

EXIT_OK, EXIT_INPUT, EXIT_UNSTABLE, EXIT_INTERRUPTED = 0, 2, 3, 130


def default_results_dir(input_path: Path) -> Path:
    """Results go next to the input, named after it: ``bar.xml`` -> ``bar_results``."""
    return input_path.with_name(input_path.stem + "_results")


def _print_problems(exc) -> None:
    for p in exc.problems:
        print(p, file=sys.stderr)


def _crack_summary(sim) -> str:
    scene = getattr(sim, "cracks", None)
    if scene is None:
        return "cracks:     none"
    cs = scene.cracks
    parts = []
    for c in range(cs.n_cracks):
        s, n = cs.first[c], cs.count[c]
        with_law = int((cs.law[s:s + n] >= 0).sum())
        tips = [t for t in scene.tips if t.crack == c]
        where = " and ".join(t.end for t in tips) + " tip" if tips else "no tip"
        grows = [f"{t.end} tip grows by {t.criterion.name}"
                 + (f" with law '{sim.material_names[t.new_law]}'" if t.new_law >= 0 else "")
                 for t in tips if t.criterion is not None]
        parts.append(f"crack {c + 1}: {n} particles, {with_law} with traction laws, J at "
                     f"{where}" + ("; " + ", ".join(grows) if grows else ""))
    return "cracks:     " + "; ".join(parts) + f" (J contour {scene.jcontour_size} cells)"


def _summary(sim) -> str:
    from .core.simulation import METHOD_NAMES, SHAPE_NAMES
    p, g = sim.particles, sim.grid
    lines = [
        f"title:      {sim.title.splitlines()[0] if sim.title else '(none)'}",
        f"analysis:   {'plane stress' if sim.plane_stress else 'plane strain'}, "
        f"{METHOD_NAMES[sim.method]}{'+' if sim.post_extrapolate and sim.method != 0 else ''}"
        f", {SHAPE_NAMES[sim.shape]} shape functions",
        f"particles:  {p.n}",
        f"grid:       {g.nx} x {g.ny} cells of {g.dx:g} x {g.dy:g} mm "
        f"({g.xmin:g} to {g.xmax:g}, {g.ymin:g} to {g.ymax:g} mm), thickness {g.thickness:g} mm",
        "materials:  " + "; ".join(
            f"{n} ({m.name}, {int((p.mat == i).sum())} particles, wave speed {m.wave_speed():.4g} m/s)"
            if hasattr(m, "wave_speed") else f"{n} ({m.name} traction law)"
            for i, (n, m) in enumerate(zip(sim.material_names, sim.materials))),
        _crack_summary(sim),
        f"time step:  {sim.dt:.6g} ms (CFL limit {sim.cfl_time_step():.6g} ms at factor {sim.cfl:g})",
        f"max time:   {sim.max_time:g} ms, about {sim.n_steps} steps",
        f"conditions: {len(sim.conditions.records)} ("
        + ", ".join(r.name for r in sim.conditions.records) + ")",
    ]
    return "\n".join(lines)


def cmd_check(args) -> int:
    from .errors import InputError
    from .input import load_simulation
    try:
        sim = load_simulation(args.file)
    except InputError as exc:
        _print_problems(exc)
        return EXIT_INPUT
    print(_summary(sim))
    return EXIT_OK


def cmd_run(args) -> int:
    from .errors import InputError
    from .input import load_simulation
    from .outputs.defaults import default_outputs
    path = Path(args.file)
    try:
        sim = load_simulation(path)
    except InputError as exc:
        _print_problems(exc)
        return EXIT_INPUT
    out = Path(args.output) if args.output else default_results_dir(path)
    if out.exists():
        if not args.force:
            print(f"{out}: results folder exists; use --force to replace it", file=sys.stderr)
            return EXIT_INPUT
        if out.is_dir() and ((out / "run.json").exists() or not any(out.iterdir())):
            shutil.rmtree(out)
        else:
            print(f"{out}: exists and is not a results folder; not replacing it", file=sys.stderr)
            return EXIT_INPUT
    try:
        out.mkdir(parents=True)
    except OSError as exc:
        print(f"{out}: cannot create the results folder: {exc.strerror or exc}", file=sys.stderr)
        return EXIT_INPUT
    return _execute(sim, path, out, default_outputs(out), args, resumed=False)


def cmd_resume(args) -> int:
    from .errors import InputError
    from .outputs.defaults import default_outputs
    from .resume import ResumeError, load_resumable
    folder = Path(args.dir)
    try:
        sim, ck = load_resumable(folder, args.max_time, args.force)
    except ResumeError as exc:
        print(exc, file=sys.stderr)
        return EXIT_INPUT
    except InputError as exc:
        _print_problems(exc)
        return EXIT_INPUT
    if sim.step >= sim.n_steps:
        print(f"{folder}: the run is done at {ck.time_ms:.6g} ms (MaxTime); give --max-time to "
              "go further", file=sys.stderr)
        return EXIT_INPUT
    outputs = default_outputs(folder)
    try:
        for o in outputs:
            o.resume(sim, ck.step, ck.time_ms)
    except OSError as exc:
        print(f"{exc.filename or folder}: cannot continue the results: {exc.strerror or exc}",
              file=sys.stderr)
        return EXIT_INPUT
    if not args.quiet:
        print(f"resuming {folder} at step {ck.step} ({ck.time_ms:.6g} ms) to "
              f"{sim.max_time:g} ms", file=sys.stderr)
    return _execute(sim, Path(sim.source.get("path") or folder), folder, outputs, args,
                    resumed=True)


def _stop_on_signal(sim):
    """SIGINT / SIGTERM: the first asks the run to stop at its next return to Python
    (a fraction of a second) after writing a checkpoint; a second stops it at once."""
    def handler(signum, frame):
        if sim.stop_requested:
            raise KeyboardInterrupt
        sim.request_stop()
    return handler


def _execute(sim, path: Path, out: Path, outputs: list, args, resumed: bool) -> int:
    """Run (or go on with) ``sim`` into ``out`` with a progress bar, checkpoints and
    signal handling; the exit code."""
    from .core.checkpoint import Checkpoints
    from .errors import SimulationUnstable
    show = not args.quiet and sys.stderr.isatty()
    bar = None
    if show:
        from tqdm import tqdm
        bar = tqdm(total=sim.n_steps, initial=sim.step, unit="step", dynamic_ncols=True,
                   file=sys.stderr,
                   bar_format="{l_bar}{bar}| {n_fmt}/{total_fmt} steps [{elapsed}<{remaining}, "
                              "{rate_fmt}]{postfix}")

    def progress(fraction, time_ms, step, rate):
        if bar is not None:
            bar.n = step
            bar.set_postfix_str(f"t = {time_ms:.4g} ms", refresh=False)
            bar.refresh()
    if not args.quiet and not resumed:
        print(_summary(sim), file=sys.stderr)
    checkpoints = Checkpoints(out, args.checkpoint_every)
    # Ctrl-C and a job scheduler's SIGTERM: a checkpoint, every output closed, exit 130
    handler = _stop_on_signal(sim)
    previous = {sig: signal.signal(sig, handler) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        status = sim.run(outputs, progress=progress, profile=args.profile,
                         checkpoints=checkpoints, resumed=resumed)
    except SimulationUnstable as exc:
        if bar is not None:
            bar.close()
        print(f"{path}: {exc}; results so far are in {out}", file=sys.stderr)
        return EXIT_UNSTABLE
    except KeyboardInterrupt:
        if bar is not None:
            bar.close()
        where = (f"; continue with: nairnmpm resume {out}" if checkpoints.written else "")
        print(f"\ninterrupted at step {sim.step}; results so far are in {out}{where}",
              file=sys.stderr)
        return EXIT_INTERRUPTED
    except OSError as exc:      # a full disk, a folder made unwritable during the run
        if bar is not None:
            bar.close()
        print(f"{exc.filename or out}: cannot write the results: {exc.strerror or exc}; "
              f"what was written before is in {out}", file=sys.stderr)
        return EXIT_INPUT
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)
    if bar is not None:
        bar.close()
    if not args.quiet:
        print(f"done: {sim.step} steps in {status['wall_seconds']:.2f} s; results in {out}",
              file=sys.stderr)
    if status.get("profile"):
        from .core.profile import format_table
        print(format_table(status["profile"]))
    return EXIT_OK


def cmd_plugins(args) -> int:
    from . import plugins
    from .errors import PluginError
    rows = []
    status = EXIT_OK
    for short, group in plugins.GROUPS.items():
        try:
            for p in plugins.registry(short):
                rows.append((group, p.name, "" if p.nairn_type is None else str(p.nairn_type), p.package))
        except PluginError as exc:
            print(f"error: {exc}", file=sys.stderr)
            status = EXIT_INPUT
    head = ("group", "name", "type", "package")
    widths = [max(len(r[i]) for r in rows + [head]) for i in range(4)]
    for r in [head] + rows:
        print("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip())
    return status


def cmd_plot(args) -> int:
    from .analysis.plots import plot_results
    folder = Path(args.dir)
    if (folder / "summary.csv").exists():        # a sweep folder: overlay its members
        from .analysis.sweep_plots import plot_sweep
        for f in plot_sweep(folder, Path(args.output) if args.output else None):
            print(f)
        return EXIT_OK
    if not (folder / "run.json").exists() and not (folder / "global.csv").exists():
        print(f"{folder}: not a results folder (no run.json or global.csv)", file=sys.stderr)
        return EXIT_INPUT
    files = plot_results(folder, Path(args.output) if args.output else None)
    for f in files:
        print(f)
    return EXIT_OK


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="nairnmpm", description="MPM fracture simulations from "
                                 "NairnMPM-style XML input files.")
    ap.add_argument("--version", action="version", version=f"nairnmpm_py {__version__}")
    sub = ap.add_subparsers(dest="command", required=True)
    p = sub.add_parser("run", help="run a simulation")
    p.add_argument("file", help="input file (.xml, or NairnMPM's XML .fmcmd)")
    p.add_argument("-o", "--output", help="results folder (default: next to FILE, FILE_results)")
    p.add_argument("--force", action="store_true", help="replace an existing results folder")
    p.add_argument("-q", "--quiet", action="store_true", help="no summary or progress bar")
    p.add_argument("--profile", action="store_true",
                   help="time each task of the step; table at the end and in run.json")
    p.add_argument("--checkpoint-every", type=float, metavar="MINUTES",
                   help="also write a checkpoint every MINUTES of wall time (one is "
                        "written after each archive and when the run is interrupted)")
    p.set_defaults(func=cmd_run)
    p = sub.add_parser("resume", help="continue a run from its last checkpoint")
    p.add_argument("dir", help="the run's results folder")
    p.add_argument("--max-time", type=float, metavar="MS",
                   help="run to this time (ms) instead of the input's MaxTime")
    p.add_argument("--force", action="store_true",
                   help="resume even though the input file changed since the run started")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.add_argument("--profile", action="store_true",
                   help="per-task timing table of this part (run.json and printed)")
    p.add_argument("--checkpoint-every", type=float, metavar="MINUTES",
                   help="also write a checkpoint every MINUTES of wall time")
    p.set_defaults(func=cmd_resume)
    p = sub.add_parser("check", help="parse and validate only; print a summary")
    p.add_argument("file")
    p.set_defaults(func=cmd_check)
    p = sub.add_parser("plugins", help="list registered plugins")
    p.set_defaults(func=cmd_plugins)
    p = sub.add_parser("plot", help="PNG plots of a results folder")
    p.add_argument("dir")
    p.add_argument("-o", "--output", help="folder for the PNGs (default DIR/plots)")
    p.set_defaults(func=cmd_plot)
    from .analysis import rcurve_cli
    rcurve_cli.add_parser(sub)
    from . import sweep_cli
    sweep_cli.add_parser(sub)
    return ap


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
