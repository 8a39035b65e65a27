"""Style-6 boundary conditions: an expression of t (ms since the start time) gives the
same run as the equivalent built-in style, and bad expressions are input errors."""
import numpy as np
import pytest

from nairnmpm_py.cli import main
from nairnmpm_py.core.conditions import evaluate_expression

from mpm_helpers import Recorder, build, line_of, write

SCENE = """<?xml version="1.0"?>
<JANFEAInput version="3">
  <Header><Analysis>11</Analysis></Header>
  <MPMHeader><MaxTime units="ms">0.1</MaxTime><GlobalArchiveTime units="ms">0.01</GlobalArchiveTime><GIMP/></MPMHeader>
  <Mesh><Grid xmin="-2" xmax="24" ymin="-2" ymax="4"><Horiz cellsize="1"/><Vert cellsize="1"/></Grid></Mesh>
  <MaterialPoints><Body mat="1" thick="1"><Rect xmin="0" xmax="20" ymin="0" ymax="2"/></Body></MaterialPoints>
  <Material Type="1" Name="bar"><rho>1</rho><E>1000</E><nu>0.3</nu></Material>
  <GridBCs><BCLine x1="0" y1="min" x2="0" y2="max"><DisBC dir="1" GRIDBC/></BCLine></GridBCs>
  <ParticleBCs><BCLine x1="19.75" y1="0" x2="19.75" y2="2"><net/><LoadBC dir="1" LOADBC/></BCLine></ParticleBCs>
</JANFEAInput>
"""


def _run(tmp_path, grid_bc, load_bc, name):
    sim = build(tmp_path, SCENE.replace("GRIDBC", grid_bc).replace("LOADBC", load_bc), name)
    rec = Recorder()
    sim.run([rec])
    return rec, sim


def test_function_styles_match_built_in_styles(tmp_path):
    ref, ref_sim = _run(tmp_path, 'style="1" vel="-50"', 'style="2" load="30" time="0.02"', "a.xml")
    fn, fn_sim = _run(tmp_path, 'style="6" function="-50"',
                      'style="6" function="30*t" time="0.02"', "b.xml")
    for col in ("kinetic_energy_J", "strain_energy_J", "external_work_J"):
        assert np.allclose(fn.column(col), ref.column(col), rtol=1e-10, atol=1e-15), col
    assert ref.column("kinetic_energy_J")[-1] > 0
    load_col = [c for c in ref.rows[0] if c.startswith("load_N_") and c.endswith("_x")][-1]
    assert np.allclose(fn.column(load_col), ref.column(load_col))
    assert np.allclose(fn_sim.particles.pos, ref_sim.particles.pos, rtol=0, atol=1e-12)
    # the expressions are a module of their own, called through its address: the scene
    # with them runs the very step kernels of the scene without (nothing recompiled)
    assert fn_sim.kernels is ref_sim.kernels


def test_expression_language():
    assert evaluate_expression("2*t^2 + sin(pi*t/2)", 1.0) == pytest.approx(3.0)
    assert evaluate_expression("abs(-t)+sqrt(4)", 3.0) == pytest.approx(5.0)
    assert evaluate_expression("x*y + cos(q)", 0.0, x=2.0, y=3.0, q=0.0) == pytest.approx(7.0)
    with pytest.raises(ValueError):
        evaluate_expression("z*t", 1.0)
    with pytest.raises(ValueError):
        evaluate_expression("__import__('os')", 1.0)


@pytest.mark.parametrize("attrs, message", [
    ('style="6" function="t*("', "function"),
    ('style="6" function="open(t)"', "open"),
    ('style="6"', "style 6 and the function attribute go together"),
])
def test_bad_function_is_an_input_error(tmp_path, capsys, attrs, message):
    text = SCENE.replace("GRIDBC", 'style="1" vel="0"').replace("LOADBC", attrs)
    path = write(tmp_path, text)
    out = tmp_path / "out"
    assert main(["run", str(path), "-o", str(out), "-q"]) == 2
    err = capsys.readouterr().err
    assert f"{path}:{line_of(text, '<LoadBC')}:" in err and message in err
    assert not out.exists()


def test_particle_loads_can_turn_with_their_particles(tmp_path):
    """NairnMPM's way to make a force follow its particle: two style-6 loads using the
    particle rotation q (the DCB moment loading of the paper)."""
    turned = SCENE.replace("GRIDBC", 'style="1" vel="0"').replace(
        '<LoadBC dir="1" LOADBC/>',
        '<LoadBC dir="1" style="6" function="10*cos(q)"/><LoadBC dir="2" style="6" function="10*sin(q)"/>')
    sim = build(tmp_path, turned, "turned.xml")
    angle = 0.3
    c, s = np.cos(angle), np.sin(angle)
    sim.particles.F[0], sim.particles.F[1] = c, -s
    sim.particles.F[2], sim.particles.F[3] = s, c
    sim.max_time = sim.dt  # one step: the rotation has not changed yet
    rec = Recorder()
    sim.run([rec])
    fx = [v for k, v in rec.rows[-1].items() if k.startswith("load_N_") and k.endswith("_x")][-1]
    fy = [v for k, v in rec.rows[-1].items() if k.startswith("load_N_") and k.endswith("_y")][-1]
    assert fx == pytest.approx(10 * c, rel=1e-6) and fy == pytest.approx(10 * s, rel=1e-6)


def test_grid_conditions_have_no_rotation(tmp_path, capsys):
    text = SCENE.replace("GRIDBC", 'style="6" function="cos(q)"').replace("LOADBC", 'load="1"')
    path = write(tmp_path, text)
    assert main(["check", str(path)]) == 2
    assert "unknown name 'q'" in capsys.readouterr().err
