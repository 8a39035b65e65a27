"""nairnmpm_py: Material Point Method fracture simulations with a Numba core.

Read a NairnMPM-style XML input with :func:`nairnmpm_py.input.read_input`, build a
:class:`nairnmpm_py.core.simulation.Simulation` from it and call ``run``.
"""
__version__ = "0.1.0"
