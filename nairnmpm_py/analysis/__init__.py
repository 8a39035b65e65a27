"""Analysis of results: open a results folder as arrays, plot it, and (elsewhere in
this package) the closed-form R-curve theory, traction-law inversion and area method.
"""
