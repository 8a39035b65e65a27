"""Built-in crack-propagation criteria (registered through the
``nairnmpm_py.propagation`` entry points, like any outside plugin)."""
