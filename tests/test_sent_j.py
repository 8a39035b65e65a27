"""J integrals of the seed paper's SENT specimen (Fig 3), on coarse versions of the
shipped inputs ``inputs/sent_fig3_{B,D}.xml``.

D (no tractions) against the handbook: J0 = K^2 (1 - nu^2)/E, K = sigma sqrt(pi a)
F(a/W), F = 0.265 (1 - a/W)^4 + (0.857 + 0.265 a/W)/(1 - a/W)^1.5 (Tada, Paris and
Irwin, 3rd ed.), J0 = 354.9 J/m^2.  Measured (uGIMP): 4 mm cells +5.1 to +5.5 %,
2 mm cells +2.5 to +2.7 %, 1 mm cells +0.5 to +1.7 % (``benchmarks/sent_j_accuracy.py``
charts the error against run time).

B (linear tractions sigma = k delta over the 10 mm of crack nearest the tip), 2 mm
cells: contours of half-size 1-4 cells cross the traction zone, 5-8 enclose it.  Seed
Eqs 11-13: J_tip = J(x) - W_B(x) inside, J_ff = J(x) outside, both independent of the
contour, and J_ff - J_tip = W_B(x_root).  Measured: J_tip 281.8-282.8 and J_ff
324.0-325.0 J/m^2 on sizes 2-8 (0.4 %, 0.3 %); J_ff (outside) - J_tip (inside) = 42.17
against W_B(x_root) = 42.15 J/m^2 from the COD at the root (0.05 %).  The root is the
edge of the last law particle's half segment: taken at that particle itself, W_B(x_root)
was 41.5 and the difference 2.2 %.
"""
from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from nairnmpm_py.input import load_simulation

INPUTS = Path(__file__).resolve().parents[1] / "inputs"
J0 = 354.88   # J/m^2


def test_handbook_value():
    a, W, s, E, nu = 20.0, 50.0, 10.0, 70000.0, 0.33
    al = a / W
    F = 0.265 * (1 - al) ** 4 + (0.857 + 0.265 * al) / (1 - al) ** 1.5
    K = s * math.sqrt(math.pi * a) * F
    assert K * K * (1 - nu * nu) / E * 1000 == pytest.approx(J0, abs=0.01)


def coarse(case: str, cell: int, tmp_path: Path) -> Path:
    """The shipped input with 4 mm cells (grid, crack line and tip kept mid-cell)."""
    text = (INPUTS / f"sent_fig3_{case}.xml").read_text()
    if cell == 4:
        text = text.replace('<!ENTITY cs "2">', '<!ENTITY cs "4">')
        text = text.replace('xmin="-5" xmax="55"', 'xmin="-6" xmax="54"')
        text = re.sub(r'y(min|max)="101"', r'y\1="102"', text)
    path = tmp_path / f"sent_{case}_{cell}.xml"
    path.write_text(text)
    return path


def final_contours(path: Path, sizes=(1, 2, 3, 4, 5, 6, 7, 8)) -> dict:
    sim = load_simulation(path)
    sim.run([])
    assert sim.particles.kinetic_energy() < 0.01 * sim.particles.strain_energy()
    return {r["contour_cells"]: r for r in sim.cracks.tip_results(sim, sizes=list(sizes))}


def test_traction_free_sent_converges_to_the_handbook(tmp_path):
    err = {}
    for cell, sizes in ((4, (2, 3, 4)), (2, (2, 3, 4, 5, 6, 7, 8))):
        rows = final_contours(coarse("D", cell, tmp_path), sizes)
        J = np.array([rows[s]["J_contour_J_m2"] for s in sizes])
        assert not any(rows[s]["error"] for s in sizes)
        # no tractions: J_tip = J_ff = J on every contour
        assert all(rows[s]["J_tip_J_m2"] == rows[s]["J_ff_J_m2"] == rows[s]["J_contour_J_m2"]
                   for s in sizes)
        assert np.ptp(J) / np.mean(J) < 0.005      # path independent (0.3 %, 0.2 %)
        err[cell] = np.mean(J) / J0 - 1.0
    assert 0 < err[4] < 0.06                       # +5.2 %
    assert 0 < err[2] < 0.03                       # +2.6 %
    assert err[2] < 0.6 * err[4]                   # first order in the cell size


def test_bridged_sent_two_path_independent_integrals(tmp_path):
    rows = final_contours(coarse("B", 2, tmp_path))
    sizes = range(2, 9)
    assert not any(rows[s]["error"] for s in sizes)
    j_x = np.array([rows[s]["J_contour_J_m2"] for s in sizes])
    j_tip = np.array([rows[s]["J_tip_J_m2"] for s in sizes])
    j_ff = np.array([rows[s]["J_ff_J_m2"] for s in sizes])
    w_root = rows[2]["W_B_root_J_m2"]
    # the law particles run from x = 10 to the tip at 20; the one at 10 carries half a
    # segment (0.125 mm) beyond it, so the loaded zone is 10.125 mm long
    assert rows[2]["zone_length_mm"] == pytest.approx(10.125, abs=0.01)
    assert np.ptp(j_tip) / np.mean(j_tip) < 0.01
    assert np.ptp(j_ff) / np.mean(j_ff) < 0.01
    inside = [s for s in sizes if rows[s]["W_B_crossing_J_m2"] > 0]
    outside = [s for s in sizes if rows[s]["W_B_crossing_J_m2"] == 0]
    assert inside == [2, 3, 4] and outside == [5, 6, 7, 8]
    # J(x) rises through the zone, then is the same on every enclosing contour
    jx_in = [rows[s]["J_contour_J_m2"] for s in inside]
    assert all(b > a for a, b in zip(jx_in, jx_in[1:]))
    jx_out = np.array([rows[s]["J_contour_J_m2"] for s in outside])
    assert np.ptp(jx_out) / np.mean(jx_out) < 0.005
    assert min(jx_out) > max(jx_in)
    # Eq 11 from independent contours: J_ff (enclosing) - J_tip (crossing the zone)
    jtip_inside = np.mean([rows[s]["J_tip_J_m2"] for s in inside])
    assert np.mean(jx_out) - jtip_inside == pytest.approx(w_root, rel=0.02)
    # W_B(x_root) from the COD at the root: sigma = k delta, W = k delta^2 / 2
    k = 200.0   # MPa/mm
    assert w_root == pytest.approx(0.5 * k * rows[2]["cod_root_mm"] ** 2 * 1000, rel=1e-6)
    assert j_x[0] < j_x[-1]


def test_triangular_zone_sent_C(tmp_path):
    """Fig 3C: a triangular law over the 7.5 mm nearest the tip (its root particle at
    x = 12.5 carries half a segment more), 2 mm cells.  Measured: J_tip and J_ff vary
    0.7 % and 0.6 % over contours of 4-16 mm; J(x) outside the zone 329.6-330.3;
    J_ff - J_tip = 61.3 against W_B(x_root) = 60.2 J/m^2 (1.9 %; 0.4 % with 1 mm cells,
    benchmarks/sent_fig3.py --cell 1)."""
    rows = final_contours(coarse("C", 2, tmp_path))
    sizes = range(2, 9)
    assert not any(rows[s]["error"] for s in sizes)
    assert rows[2]["zone_length_mm"] == pytest.approx(7.625, abs=0.01)
    j_tip = np.array([rows[s]["J_tip_J_m2"] for s in sizes])
    j_ff = np.array([rows[s]["J_ff_J_m2"] for s in sizes])
    assert np.ptp(j_tip) / np.mean(j_tip) < 0.02      # the 2 %
    assert np.ptp(j_ff) / np.mean(j_ff) < 0.02
    inside = [s for s in sizes if rows[s]["W_B_crossing_J_m2"] > 0]
    outside = [s for s in sizes if rows[s]["W_B_crossing_J_m2"] == 0]
    assert inside == [2, 3] and outside == [4, 5, 6, 7, 8]
    jx_out = np.array([rows[s]["J_contour_J_m2"] for s in outside])
    assert np.ptp(jx_out) / np.mean(jx_out) < 0.005
    np.testing.assert_allclose(jx_out, [rows[s]["J_ff_J_m2"] for s in outside], rtol=1e-12)
    # J(x) rises non-linearly inside the zone (the law is not linear)
    assert rows[2]["J_contour_J_m2"] < rows[3]["J_contour_J_m2"] < jx_out.min()
    jtip_inside = np.mean([rows[s]["J_tip_J_m2"] for s in inside])
    assert np.mean(jx_out) - jtip_inside == pytest.approx(rows[2]["W_B_root_J_m2"], rel=0.02)


def test_tractions_over_the_whole_crack_sent_A(tmp_path):
    """Fig 3A: linear tractions over the whole crack inside the specimen, so every
    contour crosses the zone: J_tip is the same on all of them while J(x) keeps
    growing (measured over 4-16 mm: J_tip 186.3-187.0, J(x) 198.7 to 228.8 J/m^2)."""
    rows = final_contours(coarse("A", 2, tmp_path))
    sizes = range(2, 9)
    assert not any(rows[s]["error"] for s in sizes)
    assert all(rows[s]["W_B_crossing_J_m2"] > 0 for s in sizes)
    j_tip = np.array([rows[s]["J_tip_J_m2"] for s in sizes])
    j_x = np.array([rows[s]["J_contour_J_m2"] for s in sizes])
    assert np.ptp(j_tip) / np.mean(j_tip) < 0.01
    assert np.all(np.diff(j_x) > 0) and j_x[-1] > 1.1 * j_x[0]
