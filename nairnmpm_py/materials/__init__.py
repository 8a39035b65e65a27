"""Built-in material plugins (registered through entry points like any other)."""
