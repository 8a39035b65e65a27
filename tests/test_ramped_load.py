"""A clamped bar under a slowly ramped, then held, end load settles at sigma = F/A.

The bar (100 x 10 mm, thickness 1 mm, E = 1000 MPa, nu = 0.3) is held in x on the
node line x = 0 (free to contract sideways) and pulled by a net LoadBC on its last
particle column: two style-2 ramps add up to F = 10 N reached at 1 ms and held to
2 ms; grid damping near the first-mode frequency removes the vibration.  Then
  sigma_xx = F/A everywhere (within 1%), sigma_yy = 0,
  plane stress (Analysis 11): eps_xx = sigma/E, sigma_zz = 0;
  plane strain (Analysis 10) with free faces (sigma_yy = 0):
      eps_xx = sigma (1 - nu^2)/E, sigma_zz = nu sigma;
  the end displacement eps_xx * x of the loaded particles within 2%,
  the reaction at x = 0 equal to -F.
"""
from __future__ import annotations

import numpy as np
import pytest

from mpm_helpers import Recorder, build, line_of

L, W, THICK = 100.0, 10.0, 1.0      # mm
E, NU = 1000.0, 0.3                 # MPa
F = 10.0                            # N
T_RAMP, T_END = 1.0, 2.0            # ms
AREA = W * THICK
SIGMA = F / AREA                    # 1 MPa

XML = """<?xml version="1.0"?>
<JANFEAInput version="3">
  <Header><Analysis>{analysis}</Analysis></Header>
  <MPMHeader>
    <GIMP/>
    <MaxTime units="ms">{t_end}</MaxTime>
    <GlobalArchiveTime units="ms">0.05</GlobalArchiveTime>
    <Damping>15708</Damping>
  </MPMHeader>
  <Mesh>
    <Grid xmin="-4" xmax="{gx}" ymin="-4" ymax="{gy}" thickness="{thick}">
      <Horiz cellsize="2"/><Vert cellsize="2"/>
    </Grid>
  </Mesh>
  <MaterialPoints>
    <Body mat="1" thick="{thick}"><Rect xmin="0" xmax="{L}" ymin="0" ymax="{W}"/></Body>
  </MaterialPoints>
  <Material Type="1" Name="bar"><rho>1</rho><E>{E}</E><nu>{nu}</nu></Material>
  <GridBCs>
    <BCLine x1="0" y1="min" x2="0" y2="max"><DisBC dir="1" vel="0"/></BCLine>
  </GridBCs>
  <ParticleBCs>
    <LdRect xmin="99" xmax="{L}" ymin="0" ymax="{W}">
      <net/>
      <LoadBC dir="1" style="2" load="{rate}" time="0"/>
      <LoadBC dir="1" style="2" load="-{rate}" time="{t_ramp}"/>
    </LdRect>
  </ParticleBCs>
</JANFEAInput>
"""


def run(tmp_path, analysis: int) -> dict:
    text = XML.format(analysis=analysis, t_end=T_END, gx=L + 4, gy=W + 4, thick=THICK, L=L,
                      W=W, E=E, nu=NU, rate=F / T_RAMP, t_ramp=T_RAMP)
    sim = build(tmp_path, text, f"ramp_{analysis}.xml")
    rec = Recorder()
    status = sim.run(outputs=[rec])
    assert status["exit_status"] == "done"
    p = sim.particles
    x0 = p.pos0[0]
    loaded = x0 >= 99.0
    # column names follow the source line of each condition element
    fixed = f"bc{line_of(text, '<DisBC')}_x"
    ramp_up = f"bc{line_of(text, '<LoadBC')}_x"
    ramp_down = f"bc{line_of(text, '<LoadBC', 2)}_x"
    last = rec.rows[-1]
    return {"sim": sim, "rows": rec.rows, "x_loaded": float(np.mean(x0[loaded])),
            "mid": (x0 > 0.2 * L) & (x0 < 0.8 * L), "last": last,
            "reaction": last[f"load_N_{fixed}"],
            "applied": last[f"load_N_{ramp_up}"] + last[f"load_N_{ramp_down}"],
            "end_disp": last[f"disp_mm_{ramp_up}"]}


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    folder = tmp_path_factory.mktemp("ramp")
    return {a: run(folder, a) for a in (10, 11)}


@pytest.mark.parametrize("analysis", [10, 11])
def test_settles_at_sigma_F_over_A(results, analysis):
    r = results[analysis]
    s = r["sim"].particles.stress
    mid = r["mid"]
    err = np.abs(s[0, mid] / SIGMA - 1)
    print(f"Analysis {analysis}: sigma_xx mean {s[0, mid].mean():.5f} MPa (F/A = {SIGMA:g}), "
          f"max error {100 * err.max():.3f}%, |sigma_yy| max {np.abs(s[1, mid]).max():.2e}, "
          f"sigma_zz {s[3, mid].mean():.4f}, KE {r['last']['kinetic_energy_J']:.2e} J")
    assert err.max() < 0.01
    assert np.abs(s[1, mid]).max() < 0.01 * SIGMA
    assert np.abs(s[2, mid]).max() < 0.01 * SIGMA
    expected_szz = 0.0 if analysis == 11 else NU * SIGMA
    assert np.allclose(s[3, mid], expected_szz, atol=0.01 * SIGMA)
    # settled: what is left of the kinetic energy is tiny next to the strain energy
    assert r["last"]["kinetic_energy_J"] < 1e-2 * r["last"]["strain_energy_J"]


@pytest.mark.parametrize("analysis", [10, 11])
def test_load_and_reaction_balance(results, analysis):
    r = results[analysis]
    # the two ramps hold F (evaluated at the start of the last step: within dt * rate)
    assert r["applied"] == pytest.approx(F, rel=1e-3)
    assert r["reaction"] == pytest.approx(-F, rel=0.01)


@pytest.mark.parametrize("analysis", [10, 11])
def test_end_displacement_from_elasticity(results, analysis):
    r = results[analysis]
    strain = SIGMA / E * ((1 - NU ** 2) if analysis == 10 else 1.0)
    expected = strain * r["x_loaded"]
    print(f"Analysis {analysis}: end displacement {r['end_disp']:.6f} mm, expected "
          f"{expected:.6f} mm ({100 * (r['end_disp'] / expected - 1):+.3f}%)")
    assert r["end_disp"] == pytest.approx(expected, rel=0.02)


def test_plane_strain_is_stiffer_by_one_minus_nu_squared(results):
    ratio = results[10]["end_disp"] / results[11]["end_disp"]
    assert ratio == pytest.approx(1 - NU ** 2, rel=0.02)
    assert ratio < 0.95   # clearly different, not equal within noise
