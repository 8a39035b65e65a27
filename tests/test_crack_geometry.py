"""Crack polylines: COD sign convention and the checks bad inputs get."""
import numpy as np

from nairnmpm_py.cracks.geometry import CrackSet, polyline_problems


def test_cod_is_positive_when_the_above_surface_moves_left_of_travel():
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    cs = CrackSet.from_polylines([pts], [np.full(3, -1)], [(-1, 1)])
    cs.above[1, 1] += 0.1       # y of particle 1: above = left of first -> last = +y
    cs.below[1, 1] -= 0.05
    cs.above[0, 2] += 0.02      # pure sliding along the crack
    dn, dt = cs.cod()
    assert np.allclose(dn, [0.0, 0.15, 0.0])
    assert np.allclose(dt, [0.0, 0.0, 0.02])


def test_polyline_checks():
    ok = np.array([[1.0, 1.0], [5.0, 1.0], [9.0, 2.0]])
    assert polyline_problems(ok, (0, 10), (0, 10), 1.0) == []
    outside = np.array([[1.0, 1.0], [11.0, 1.0]])
    assert "outside the grid" in polyline_problems(outside, (0, 10), (0, 10), 1.0)[0]
    zero = np.array([[1.0, 1.0], [1.0, 1.0], [2.0, 1.0]])
    assert "zero length" in polyline_problems(zero, (0, 10), (0, 10), 1.0)[0]
    zigzag = np.array([[1.0, 1.0], [5.0, 5.0], [5.0, 1.0], [1.0, 5.0]])
    assert "crosses itself" in polyline_problems(zigzag, (0, 10), (0, 10), 1.0)[0]
