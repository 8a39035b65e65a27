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

from mpm_helpers import Recorder, build, line_of, scene_xml

L, W, THICK = 100.0, 10.0, 1.0      # mm
E, NU = 1000.0, 0.3                 # MPa
F = 10.0                            # N
T_RAMP, T_END = 1.0, 2.0            # ms
AREA = W * THICK
SIGMA = F / AREA                    # 1 MPa

XML = scene_xml(
    analysis="{analysis}",
    header="""<GIMP/>
    <MaxTime units="ms">{t_end}</MaxTime>
    <GlobalArchiveTime units="ms">0.05</GlobalArchiveTime>
    <Damping>15708</Damping>""",
    grid="""<Grid xmin="-4" xmax="{gx}" ymin="-4" ymax="{gy}" thickness="{thick}">
      <Horiz cellsize="2"/><Vert cellsize="2"/>
    </Grid>""",
    bodies='<Body mat="1" thick="{thick}"><Rect xmin="0" xmax="{L}" ymin="0" ymax="{W}"/></Body>',
    rest="""<Material Type="1" Name="bar"><rho>1</rho><E>{E}</E><nu>{nu}</nu></Material>
  <GridBCs>
    <BCLine x1="0" y1="min" x2="0" y2="max"><DisBC dir="1" vel="0"/></BCLine>
  </GridBCs>
  <ParticleBCs>
    <LdRect xmin="99" xmax="{L}" ymin="0" ymax="{W}">
      <net/>
      <LoadBC dir="1" style="2" load="{rate}" time="0"/>
      <LoadBC dir="1" style="2" load="-{rate}" time="{t_ramp}"/>
    </LdRect>
  </ParticleBCs>""")


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


TRACTION = """    <LdRect xmin="99" xmax="{L}" ymin="0" ymax="{W}">
      <TractionBC dir="1" face="2" style="2" stress="{rate}" time="0"/>
      <TractionBC dir="1" face="2" style="2" stress="-{rate}" time="{t_ramp}"/>
    </LdRect>"""


CRACK = """  <CrackList>
    <Line xmin="40" ymin="5" xmax="60" ymax="5" resolution="20"/>
  </CrackList>
"""


@pytest.mark.parametrize("crack", [False, True], ids=["no crack", "crack along the bar"])
def test_traction_on_the_end_face_settles_at_the_same_stress(tmp_path, crack):
    """The same bar pulled by a TractionBC (sigma = 1 MPa on the right face of the last
    particle column) instead of the net LoadBC: the traction acts on the face, half at
    each of its corners with linear grid weights (as NairnMPM applies it), adds up to
    sigma times the face area, and the bar settles at sigma_xx = sigma.  With a crack
    along the bar (parallel to the load, so it changes nothing) the crack kernels
    apply the traction the same way."""
    start, end = XML.index("    <LdRect"), XML.index("  </ParticleBCs>")
    body = XML[:start] + TRACTION + "\n" + XML[end:]
    if crack:
        body = body.replace("  <Material ", CRACK + "  <Material ", 1)
    text = body.format(
        analysis=11, t_end=T_END, gx=L + 4, gy=W + 4, thick=THICK, L=L, W=W, E=E, nu=NU,
        rate=SIGMA / T_RAMP, t_ramp=T_RAMP)
    sim = build(tmp_path, text, "traction.xml")
    rec = Recorder()
    assert sim.run(outputs=[rec])["exit_status"] == "done"
    last = rec.rows[-1]
    applied = sum(v for k, v in last.items()
                  if k.startswith("load_N_") and k != f"load_N_bc{line_of(text, '<DisBC')}_x")
    assert applied == pytest.approx(F, rel=1e-3)
    s = sim.particles.stress
    x0 = sim.particles.pos0[0]
    mid = (x0 > 0.2 * L) & (x0 < 0.8 * L)
    err = np.abs(s[0, mid] / SIGMA - 1)
    if crack:
        # the crack's tips (x = 40, 60) disturb sigma_xx by up to 6 % within about
        # 15 mm with either kind of load (2 mm cells), so look farther away
        mid &= np.abs(x0 - 50.0) > 20.0
        err = np.abs(s[0, mid] / SIGMA - 1)
    print(f"traction: sigma_xx mean {s[0, mid].mean():.5f} MPa, max error {100 * err.max():.3f}%")
    assert err.max() < 0.01
    assert last[f"load_N_bc{line_of(text, '<DisBC')}_x"] == pytest.approx(-F, rel=0.01)
    # the loaded particles' own stress is the traction too (the face carries it)
    end = x0 > 99.0
    assert s[0, end].mean() == pytest.approx(SIGMA, rel=0.02)
