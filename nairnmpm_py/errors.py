"""Errors users see: bad input (exit 2) and unstable runs (exit 3)."""
from __future__ import annotations


class InputProblem:
    """One problem in an input file, printed as ``FILE:LINE: message``."""

    def __init__(self, path: str, line: int | None, message: str):
        self.path, self.line, self.message = path, line, message

    def __str__(self) -> str:
        where = f"{self.path}:{self.line}" if self.line else f"{self.path}"
        return f"{where}: {self.message}"


class InputError(Exception):
    """Bad input: one or more problems, each with file and line."""

    def __init__(self, problems: list[InputProblem] | InputProblem):
        if isinstance(problems, InputProblem):
            problems = [problems]
        self.problems = problems
        super().__init__("\n".join(str(p) for p in problems))


class SimulationUnstable(Exception):
    """The simulation blew up (NaN, runaway velocity, particle off the grid)."""

    def __init__(self, message: str, step: int, time_ms: float):
        self.step, self.time_ms = step, time_ms
        super().__init__(f"simulation stopped at step {step}, t = {time_ms:.6g} ms: {message}")


class PluginError(Exception):
    """A plugin could not be loaded or clashes with another."""
