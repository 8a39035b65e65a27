"""Built-in output plugins: run.json, global.csv, archive.h5 and VTU/PVD series.

Each is registered under the ``nairnmpm_py.outputs`` entry-point group, exactly as an
out-of-tree output plugin would be, and writes into the run's results folder.
"""
