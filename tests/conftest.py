"""Shared test setup.

The simulation tests use tiny scenes (a few hundred particles).  For those, Numba's
parallel kernels only add thread start-up and barrier costs, and on a machine whose
cores are busy with something else (a benchmark, another test run) every parallel
region waits for a time slice: a 2000-step bar took 170 s with 2 threads against
0.2 s with 1.  So the tests run the kernels on one thread unless
NAIRNMPM_TEST_THREADS says otherwise (e.g. NAIRNMPM_TEST_THREADS=2 pytest; the whole
suite passes either way).

The suite runs on both cores (pytest-xdist, whole files per worker, see
pyproject.toml).  The file with the longest run goes first, so the other worker
runs the rest alongside it rather than after it.
"""
from __future__ import annotations

import os

import numba
import pytest


@pytest.fixture(autouse=True, scope="session")
def _numba_threads():
    wanted = int(os.environ.get("NAIRNMPM_TEST_THREADS", "1"))
    old = numba.get_num_threads()
    numba.set_num_threads(max(1, min(wanted, numba.config.NUMBA_NUM_THREADS)))
    yield
    numba.set_num_threads(old)


# about 7 minutes on one core with empty caches (a DCB run through its growth)
LONGEST_FIRST = ("test_dcb_growth.py",)


def pytest_collection_modifyitems(config, items):
    items.sort(key=lambda item: item.path.name not in LONGEST_FIRST)   # stable sort
