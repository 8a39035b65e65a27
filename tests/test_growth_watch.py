"""The step's watch on growing tips (``cracks.growth_watch``) changes nothing but speed.

The growing SENT of ``test_propagation`` with a bridging law on its new crack
particles, run with the watch and with Python's full check at every step: the same
growth rows to the last bit, the same particles and crack surfaces, and far fewer full
checks.  The watch's bound (J_tip <= J(x)) needs W_B >= 0; a law that could make W_B
negative turns the watch off.
"""
from __future__ import annotations

import numpy as np

from nairnmpm_py.input import load_simulation

from test_propagation import sent_growing


def _run(path, watch: bool):
    sim = load_simulation(path)
    sim.cracks.watch_tips = watch
    sim.run([])
    return sim


def test_watched_run_equals_the_full_check_at_every_step(tmp_path):
    path = sent_growing(tmp_path, tprop=True)
    watched, full = _run(path, True), _run(path, False)
    assert watched.step == full.step
    log_w, log_f = watched.cracks.growth_log, full.cracks.growth_log
    assert len(log_f) >= 3
    assert [r["time_ms"] for r in log_w] == [r["time_ms"] for r in log_f]
    for a, b in zip(log_w, log_f):
        for key in ("J_tip_J_m2", "J_ff_J_m2", "R_J_m2", "W_B_root_J_m2", "tip_x_mm",
                    "KI_MPa_sqrt_m"):
            assert a[key] == b[key], key
    for name in ("pos", "vel", "stress"):
        assert np.array_equal(getattr(watched.particles, name), getattr(full.particles, name))
    for name in ("plane", "above", "below"):
        assert np.array_equal(getattr(watched.cracks.cracks, name),
                              getattr(full.cracks.cracks, name))
    assert np.array_equal(watched.cracks.edge_hist, full.cracks.edge_hist)
    # the full check ran at every step without the watch, and far less often with it
    assert full.cracks.full_checks == full.step // full.cracks.check_steps
    assert watched.cracks.full_checks < 0.5 * full.cracks.full_checks


class _Law:
    """A law's envelope as the safety test reads it: S = s0 (d / dc)^p up to dc."""

    def __init__(self, power: float):
        self.p, self.dc, self.s0 = power, 0.01, 10.0

    def mode(self, m):
        return type("Env", (), {"breakpoints": ()})()

    def delta_c(self, m=1):
        return self.dc

    def area(self, m=1):
        return 1000.0 * self.s0 * self.dc / (self.p + 1)

    def envelope(self, h, m=1):
        return self.s0 * (np.asarray(h) / self.dc) ** self.p

    def dissipated(self, h, m=1):
        h = np.asarray(h)
        work = 1000.0 * self.s0 * h ** (self.p + 1) / ((self.p + 1) * self.dc ** self.p)
        return work - 500.0 * self.envelope(h) * h


def test_watch_only_with_laws_that_never_give_back_more_than_they_took(tmp_path):
    sim = load_simulation(sent_growing(tmp_path, tprop=True, t_end=0.01))
    scene = sim.cracks
    sim.prepare()
    sim.watch_growth = True
    assert scene.watch_table(sim).shape == (1, 4)
    assert scene.watch_table(sim)[0, 2] == 0.3          # JIc 300 J/m^2 in N/mm
    for power, ok in ((1.0, True), (0.5, True), (2.0, False)):
        scene.laws = {0: _Law(power)}
        scene._unload_ok = None
        assert scene._laws_unload_safely() is ok
        assert (scene.watch_table(sim).shape[0] == 1) is ok
