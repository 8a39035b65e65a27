"""The input language: NairnMPM XML -> validated models -> Simulation."""
from .build import build_simulation, load_simulation
from .reader import read_input

__all__ = ["read_input", "build_simulation", "load_simulation"]
