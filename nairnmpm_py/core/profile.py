"""Where a run's time goes: the per-task profile of ``nairnmpm run --profile``.

The profiled driver (``advance_profiled``, composed from the same task list as the
plain one) adds each step task's clock cycles into an array; the run loop times the
periodic work (propagation checks, global and full archives) with the wall clock.
Cycles become seconds by the ratio of cycles to wall time over the whole run, and
what neither covers (returning to Python between driver calls, progress reports) is
a row of its own, so the shares add up to the whole run after compiling.
"""
from __future__ import annotations

import time

import numpy as np

from .cycles import cycles
from .tasks import PERIODIC, profile_rows

BETWEEN_CALLS = "between driver calls (Python)"


class StepProfile:
    def __init__(self, with_cracks: bool):
        self.names = profile_rows(with_cracks)
        self.cycles = np.zeros(len(self.names), dtype=np.uint64)
        self.periodic = {p.name: 0.0 for p in PERIODIC if with_cracks or not p.cracks}
        self.wall0 = self.cycles0 = None
        self.wall = 0.0
        self.cycle_span = 0

    def start(self) -> None:
        self.wall0 = time.perf_counter()
        self.cycles0 = int(cycles())

    def stop(self) -> None:
        self.cycle_span = int(cycles()) - self.cycles0
        self.wall = time.perf_counter() - self.wall0

    def timed(self, name: str, fn, *args):
        """Run fn(*args), adding its wall time to the periodic task ``name``."""
        t0 = time.perf_counter()
        try:
            return fn(*args)
        finally:
            self.periodic[name] += time.perf_counter() - t0

    def rows(self, steps: int) -> list[dict]:
        """[{task, ms_per_step, share}] over every step task, the periodic tasks and
        the time between driver calls; the shares add up to 1."""
        per_cycle = self.wall / self.cycle_span if self.cycle_span > 0 else 0.0
        seconds = {name: float(c) * per_cycle for name, c in zip(self.names, self.cycles)}
        seconds.update(self.periodic)
        seconds[BETWEEN_CALLS] = max(self.wall - sum(seconds.values()), 0.0)
        total = sum(seconds.values()) or 1.0
        n = max(steps, 1)
        return [{"task": name, "ms_per_step": 1e3 * s / n, "share": s / total}
                for name, s in seconds.items()]


def format_table(rows: list[dict]) -> str:
    """The profile as a text table, largest share first (like NairnMPM's end-of-run
    task timings)."""
    width = max(len(r["task"]) for r in rows)
    lines = [f"{'task':<{width}}  ms/step   share", "-" * (width + 18)]
    for r in sorted(rows, key=lambda r: -r["share"]):
        lines.append(f"{r['task']:<{width}}  {r['ms_per_step']:7.4f}  {100 * r['share']:5.1f} %")
    total = sum(r["ms_per_step"] for r in rows)
    lines.append(f"{'whole step':<{width}}  {total:7.4f}  100.0 %")
    return "\n".join(lines)
