"""Explicit cracks: geometry, multi-field nodes, contact, J integral, propagation."""
