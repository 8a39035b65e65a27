"""Built-in traction laws (registered through the ``nairnmpm_py.traction_laws`` entry
points, like any outside plugin) and the framework they share (``base``)."""
