"""The Numba MPM engine: particle and grid arrays, shape functions, time step."""
