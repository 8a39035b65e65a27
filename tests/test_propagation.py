"""Crack growth by the critical energy release rate (criterion 7).

The coarse SENT specimen of ``inputs/sent_fig3_D.xml`` (4 mm cells) with JIc = 300
J/m^2 on the specimen material and the load of the Fig 3 runs (J would reach about
370 J/m^2): the tip must not move while J_tip < JIc, must start growing at the first
check where J_tip >= JIc, and then (load control, unstable) keeps growing, half a cell
straight ahead per growth step.  With a Tprop law, new crack particles carry it and
the energy released is R = JIc + W_B(root) - W_B^(r)(root) (seed Eq 15).
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from nairnmpm_py.cli import main
from nairnmpm_py.input import load_simulation

from mpm_helpers import line_of

INPUTS = Path(__file__).resolve().parents[1] / "inputs"
JIC = 300.0


def sent_growing(tmp_path: Path, tprop: bool, extra: str = "", t_end: float = 0.46) -> Path:
    text = (INPUTS / "sent_fig3_D.xml").read_text()
    text = text.replace('<!ENTITY cs "2">', '<!ENTITY cs "4">')
    text = text.replace('xmin="-5" xmax="55"', 'xmin="-6" xmax="54"')
    text = re.sub(r'y(min|max)="101"', r'y\1="102"', text)
    text = text.replace('<JContourSizes>1 2 3 4 5 6 7 8</JContourSizes>',
                        f'<Propagate criterion="7" direction="0"/>{extra}')
    text = text.replace('<MaxTime units="ms">1.2</MaxTime>', f'<MaxTime units="ms">{t_end}</MaxTime>')
    text = text.replace('<ArchiveTime units="ms">0.2</ArchiveTime>', '<ArchiveTime units="ms">0.02</ArchiveTime>')
    text = text.replace('<nu>0.33</nu>\n  </Material>', f'<nu>0.33</nu>\n    <JIc>{JIC:g}</JIc>\n  </Material>', 1)
    if tprop:
        text = text.replace('<CrackList>', '<CrackList Tpropname="triangle">')
    path = tmp_path / "sent_growing.xml"
    path.write_text(text)
    return path


def run(path: Path):
    sim = load_simulation(path)
    sim.run([])
    return sim


def test_tip_grows_once_J_tip_reaches_JIc(tmp_path):
    sim = run(sent_growing(tmp_path, tprop=False))
    scene = sim.cracks
    log = scene.growth_log
    tip = scene.tips[0]
    assert tip.grown == len(log) >= 5
    j_first = log[0]["J_tip_J_m2"]
    # checked every step: growth starts as J_tip crosses JIc (J rises ~0.1 % per step)
    assert JIC <= j_first < 1.01 * JIC
    assert all(r["J_tip_J_m2"] >= JIC for r in log)
    # half a cell (2 mm) straight ahead per growth step (the crack particles also
    # move with the material, by up to 0.03 mm here)
    growth = np.array([r["crack_growth_mm"] for r in log])
    assert np.allclose(np.diff(growth), 2.0, atol=0.05)
    ys = np.array([r["tip_y_mm"] for r in log])
    assert np.ptp(ys) < 0.01
    # no traction law: R is J_tip,c (Eq 15 with W_B = 0)
    assert all(r["R_J_m2"] == pytest.approx(JIC) for r in log)
    cs = scene.cracks
    assert cs.count[0] == 85 + len(log)       # 84 segments in the input
    assert np.all(cs.law == -1)


def test_new_crack_particles_get_the_tprop_law(tmp_path):
    sim = run(sent_growing(tmp_path, tprop=True))
    scene = sim.cracks
    cs = scene.cracks
    log = scene.growth_log
    assert len(log) >= 3
    law = sim.material_names.index("triangle")
    grown = cs.law[cs.count[0] - len(log):cs.count[0]]
    assert np.all(grown == law)
    assert np.all(cs.law[:85] == -1)                  # the initial crack stays free
    assert np.all(scene.state[cs.count[0] - len(log):] >= 1)
    # R from Eq 15 on every growth row, with the zone's root values
    for r in log:
        assert r["R_J_m2"] == pytest.approx(JIC + r["W_B_root_J_m2"] - r["W_B_rec_root_J_m2"])
    # a bridging zone forms behind the tip: the later rows see traction work at the root
    assert log[-1]["zone_length_mm"] > 0 and log[-1]["W_B_root_J_m2"] > 0


def test_criterion_7_needs_JIc(tmp_path, capsys):
    path = sent_growing(tmp_path, tprop=False)
    text = path.read_text().replace(f"<JIc>{JIC:g}</JIc>", "")
    path.write_text(text)
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert f"{path}:{line_of(text, '<Propagate criterion')}:" in err
    assert "needs <JIc>" in err


def test_unknown_criterion_is_an_input_error(tmp_path, capsys):
    path = sent_growing(tmp_path, tprop=False)
    text = path.read_text().replace('criterion="7"', 'criterion="42"')
    path.write_text(text)
    assert main(["check", str(path)]) == 2
    assert "no propagation criterion of that number" in capsys.readouterr().err


def test_run_json_carries_the_R_curve_theory(tmp_path):
    """run.json's r_curve_theory: Eq 16 for the tip's new-particle law and J_tip,c,
    which ``nairnmpm plot`` draws dashed beside the simulated R (Fig 7)."""
    import json

    from nairnmpm_py.analysis.rcurve import R_triangular
    path = sent_growing(tmp_path, tprop=True, t_end=0.05)
    out = tmp_path / "out"
    assert main(["run", str(path), "-o", str(out), "-q"]) == 0
    (th,) = json.loads((out / "run.json").read_text())["r_curve_theory"]
    assert (th["crack"], th["tip"], th["J_tip_c_J_m2"]) == (1, "end", JIC)
    # "triangle": sigma 5 MPa, delta_c 0.04 mm, peak at the default 0.225926299 delta_c
    assert th["delta_c_mm"] == pytest.approx(0.04)
    assert th["J_B_J_m2"] == pytest.approx(0.5 * 5 * 0.04 * 1000)
    d, R = np.array(th["cod_mm"]), np.array(th["R_J_m2"])
    assert d[-1] == pytest.approx(1.2 * 0.04)
    np.testing.assert_allclose(R, R_triangular(d, JIC, 100.0, 0.04, 0.225926299 * 0.04), rtol=1e-9)


def test_J_after_a_growth_reads_the_assignment_of_the_grown_crack(tmp_path):
    """The step's crack-side assignment is for the crack before it grew: J must not read
    it stale.  After a growth the scene extrapolates again, and J's fields equal those
    of the standalone crossing test on the grown crack."""
    from nairnmpm_py.cracks.jintegral import StepAssignment, nodal_fields, step_nodal_fields
    sim = run(sent_growing(tmp_path, tprop=False, t_end=0.02))
    scene = sim.cracks
    window = scene._contour_window(sim, scene.tips, scene.jcontour_size)
    assert sim.grid_current
    assert scene._grow(sim, scene.tips[0])
    assert not sim.grid_current
    P, G, _, K, _ = sim.bundles()
    stale = step_nodal_fields(sim.grid, P, StepAssignment(K.vfld, K.cut, K.nslot, G.g, P.wij,
                                                          P.wc), sim.shape, window=window)
    fresh = scene.j_fields(sim, window)
    assert sim.grid_current
    crossing = nodal_fields(sim.grid, sim.particles, scene.cracks, sim.shape, window=window)
    assert np.allclose(fresh.mass, crossing.mass, rtol=1e-12, atol=0.0)
    assert np.array_equal(fresh.crack, crossing.crack)
    assert not np.allclose(stale.mass, crossing.mass, rtol=1e-12, atol=0.0)
