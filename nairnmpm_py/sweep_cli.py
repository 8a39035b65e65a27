"""``nairnmpm sweep TEMPLATE.xml TABLE.csv [-o DIR] [--scheduler ADDRESS] [--workers N] [--force]``

A thin command layer over ``nairnmpm_py.sweep.run_sweep``.  Exit codes: 0 every member
done, 3 one or more failed (summary.csv is still written), 2 bad input (template,
table or folder; nothing runs).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

EXIT_OK, EXIT_INPUT, EXIT_FAILED = 0, 2, 3


def default_sweep_dir(template: Path) -> Path:
    """``bar.xml`` -> ``bar_sweep`` next to it."""
    return template.with_name(template.stem + "_sweep")


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "sweep", help="run a family of inputs from a template and a table of entity values",
        description="Runs one member per table row: the template with its <!ENTITY> values "
                    "replaced by the row's.  Results go to DIR/<name>/ and DIR/summary.csv.")
    p.add_argument("template", help="template input (.xml) declaring the swept entities")
    p.add_argument("table", help="CSV: header names entities (optional 'name' column), one row per member")
    p.add_argument("-o", "--output", help="sweep folder (default: next to TEMPLATE, TEMPLATE_sweep)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="Dask scheduler address (e.g. tcp://host:8786); default: a local cluster")
    p.add_argument("--workers", type=int, default=None, metavar="N",
                   help="worker processes of the local cluster (default 2)")
    p.add_argument("--force", action="store_true", help="replace an existing sweep folder")
    p.set_defaults(func=run)
    return p


def run(args) -> int:
    from .errors import InputError
    from .sweep import run_sweep
    template = Path(args.template)
    out = Path(args.output) if args.output else default_sweep_dir(template)
    if args.workers is not None and args.workers < 1:
        print(f"--workers: must be at least 1 (got {args.workers})", file=sys.stderr)
        return EXIT_INPUT

    def report(res: dict) -> None:
        line = f"{res['name']}: {res['exit_status']}"
        if res.get("exit_status") == "done":
            line += f" ({res.get('steps', 0)} steps, {res.get('wall_seconds', 0.0):.2f} s)"
        elif res.get("message"):
            line += f": {res['message']}"
        print(line, file=sys.stderr)
    try:
        results = run_sweep(template, args.table, out, scheduler=args.scheduler,
                            workers=args.workers, force=args.force, on_result=report)
    except InputError as exc:
        for p in exc.problems:
            print(p, file=sys.stderr)
        return EXIT_INPUT
    except (OSError, TimeoutError, ValueError) as exc:     # e.g. no scheduler at ADDRESS
        where = f"scheduler {args.scheduler}" if args.scheduler else "local cluster"
        print(f"{where}: {type(exc).__name__}: {exc}", file=sys.stderr)
        return EXIT_INPUT
    failed = [r for r in results if r["exit_status"] != "done"]
    print(f"{len(results) - len(failed)} of {len(results)} members done; summary in "
          f"{out / 'summary.csv'}", file=sys.stderr)
    return EXIT_FAILED if failed else EXIT_OK
