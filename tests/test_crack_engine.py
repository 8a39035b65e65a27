"""Explicit cracks in the engine (CRAMP): separate velocity fields, traction laws with
history, crack contact, more than one crack.

The scene: a bar 40 mm x 4 mm (E = 1000 MPa, plane stress, 1 mm cells, uGIMP) held
in x at x = 0 and pulled in x at x = 40 mm by a grid velocity, cut across at x = 20.5
mm by a vertical crack whose ends lie outside the bar (exterior ends, tip code -2).
The particles are cut into two pieces joined only through the crack, so in a slow
pull the bar stress (reaction at x = 0 over the 4 mm^2 section) is what the crack
surfaces carry:

* no traction law: nothing (the two halves separate, the opening equals the pull);
* a triangular law (sigma_c = 1 MPa, delta_c = 0.1 mm, peak at 0.2259 delta_c): the
  law's envelope S(delta) at the crack opening while loading, the secant S(h)/h delta
  while the crack closes again from its largest opening h, and zero once delta_c is
  passed (every crack particle failed);
* pushed instead of pulled, the faces touch and frictionless contact carries the load.

Only crack particles inside the bar carry the law: a law particle hands all its force
to whatever material its surfaces find, so one just outside the bar would pull on the
bar's edge.
"""
from __future__ import annotations

import numpy as np
import pytest

from mpm_helpers import Recorder, build, scene_xml

AREA = 4.0          # mm^2, 4 mm x 1 mm
SIGMA_C = 1.0       # MPa
DELTA_C = 0.1       # mm


def crack_points(x: float, law: bool) -> str:
    """Crack particles every 0.25 mm from y = -0.875 to 4.875 mm; the law only on those
    inside the bar, each standing for 0.25 mm of it."""
    pts = []
    for k in range(24):
        y = -0.875 + 0.25 * k
        tip = ' tip="-2"' if k in (0, 23) else ""
        mat = ' matname="glue"' if law and 0.0 < y < 4.0 else ""
        pts.append(f'<pt x="{x:g}" y="{y:g}"{tip}{mat}/>')
    return "\n      ".join(pts)


def bar_xml(v: float, t_end: float, t_reverse: float = 99.0, law: bool = True,
            second_crack: bool = False) -> str:
    cracks = f"<CrackList>\n      {crack_points(20.5, law)}\n    </CrackList>"
    if second_crack:
        cracks += f"\n    <CrackList>\n      {crack_points(30.5, False)}\n    </CrackList>"
    return scene_xml(
        header=f"""<GIMP/>
    <MaxTime units="ms">{t_end}</MaxTime>
    <GlobalArchiveTime units="ms">0.02</GlobalArchiveTime>
    <Damping>5000</Damping>""",
        grid="""<Grid xmin="-2" xmax="42" ymin="-2" ymax="6" thickness="1">
      <Horiz cellsize="1"/><Vert cellsize="1"/>
    </Grid>""",
        bodies='<Body matname="bar" thick="1"><Rect xmin="0" xmax="40" ymin="0" ymax="4"/></Body>',
        rest=f"""{cracks}
  <Material Type="1" Name="bar"><rho>1</rho><E>1000</E><nu>0.3</nu></Material>
  <Material Type="12" Name="glue">
    <sigmaI>{SIGMA_C}</sigmaI><delIc>{DELTA_C}</delIc><sigmaII>1</sigmaII><delIIc>0.1</delIIc>
  </Material>
  <GridBCs>
    <BCLine x1="0" y1="min" x2="0" y2="max"><DisBC dir="1" vel="0"/></BCLine>
    <BCLine x1="40" y1="min" x2="40" y2="max">
      <DisBC dir="1" vel="{v}"/>
      <DisBC dir="1" vel="{-2 * v}" time="{t_reverse}"/>
    </BCLine>
  </GridBCs>""")


def run_bar(tmp_path, **kw):
    sim = build(tmp_path, bar_xml(**kw))

    def probe(s):
        cs = s.cracks.cracks
        inside = (cs.plane[1] > 0) & (cs.plane[1] < 4) & (cs.crack == 0)
        dn, _ = cs.cod()
        return (float(np.mean(dn[inside])), float(np.mean(s.cracks.hist[0][inside])),
                int(np.sum(s.cracks.state[inside] == 2)))

    rec = Recorder(probe)
    sim.run([rec])
    fixed = next(c for c in rec.rows[0] if c.startswith("load_N_") and c.endswith("_x"))
    sigma = -rec.column(fixed) / AREA       # bar stress from the reaction at x = 0
    dn, h, failed = (np.array(v) for v in zip(*rec.probes))
    return sim, rec, sigma, dn, h, failed


def test_traction_free_crack_cuts_the_bar(tmp_path):
    sim, rec, sigma, dn, h, failed = run_bar(tmp_path, v=50.0, t_end=0.6, law=False)
    assert np.max(np.abs(sigma)) < 1e-9            # nothing crosses the crack
    t = rec.column("time_ms")
    # the right half moves with the pulled end: the opening is the pull, 0.05 mm/ms
    late = t > 0.3
    assert np.allclose(dn[late], 0.05 * t[late], rtol=0.03)


def test_triangular_law_loads_follows_envelope_and_fails(tmp_path):
    sim, rec, sigma, dn, h, failed = run_bar(tmp_path, v=50.0, t_end=2.4)
    law = sim.materials[1]
    loading = (dn > 0.1 * law.peak_delta()) & (failed == 0)
    assert loading.sum() > 50
    expected = law.envelope(dn[loading])
    err = (sigma[loading] - expected) / SIGMA_C
    # measured: RMS 1.2 %, worst 3.7 % of sigma_c (dynamics of the pull)
    assert np.sqrt(np.mean(err ** 2)) < 0.02
    assert np.max(np.abs(err)) < 0.05
    assert np.max(sigma) == pytest.approx(SIGMA_C, rel=0.03)
    # past delta_c every law particle has failed and the bar carries nothing
    assert failed[-1] == 16
    assert np.all(np.abs(sigma[-5:]) < 0.02 * SIGMA_C)


def test_unloading_returns_linearly_to_the_origin(tmp_path):
    sim, rec, sigma, dn, h, failed = run_bar(tmp_path, v=50.0, t_end=2.8, t_reverse=1.6)
    law = sim.materials[1]
    t = rec.column("time_ms")
    # from 0.3 ms after the pull reverses (the reversal's stress waves have passed)
    unloading = t > 1.9
    h_max = h[unloading]
    assert np.ptp(h_max) < 1e-6 and h_max[0] > 2 * law.peak_delta()   # history kept
    assert dn[unloading][-1] < 0.3 * h_max[0]                          # it closed
    secant = law.envelope(h_max) / h_max * dn[unloading]
    err = (sigma[unloading] - secant) / SIGMA_C
    # the reaction still rings (+-5 % of sigma_c, alternating sample to sample) after
    # the reversal; averaged over 0.1 ms it is within 3 % of the secant, while the
    # envelope would be 24-70 % above it
    assert np.sqrt(np.mean(err ** 2)) < 0.025
    assert np.max(np.abs(np.convolve(err, np.ones(5) / 5, "valid"))) < 0.03
    assert np.all(law.envelope(dn[unloading]) > sigma[unloading] + 0.15 * SIGMA_C)
    assert failed.max() == 0


def test_contact_carries_compression_across_the_crack(tmp_path):
    # push instead of pull, no law: the faces must touch and carry the load
    sim, rec, sigma, dn, h, failed = run_bar(tmp_path, v=-20.0, t_end=1.0, law=False)
    t = rec.column("time_ms")
    pushed = 20.0e-3 * t                       # mm the end has moved
    late = t > 0.5
    # the whole bar shortens elastically: stress = E * strain, compressive
    strain = pushed[late] / 40.0
    assert np.allclose(-sigma[late], 1000.0 * strain, rtol=0.08)
    # the faces do not pass through each other: contact engages once the fields'
    # mean displacements overlap; the surfaces settle 2e-4 mm (0.02 % of a cell) into
    # each other and stay there
    assert np.min(dn) > -1e-3


def test_two_cracks_cut_the_bar_twice(tmp_path):
    sim, rec, sigma, dn, h, failed = run_bar(tmp_path, v=50.0, t_end=0.6, law=False,
                                             second_crack=True)
    assert sim.cracks.nf == 4
    assert np.max(np.abs(sigma)) < 1e-9
    cs = sim.cracks.cracks
    dn_all, _ = cs.cod()
    inside = (cs.plane[1] > 0) & (cs.plane[1] < 4)
    # the right piece (x > 30.5) moves away; the middle piece stays put
    assert np.mean(dn_all[inside & (cs.crack == 1)]) == pytest.approx(0.05 * 0.6, rel=0.05)
    assert abs(np.mean(dn_all[inside & (cs.crack == 0)])) < 0.002
