"""Bodies moving across grid cells: what is exact, and where cell-crossing noise shows.

1. A stress-free block translating at constant velocity (no conditions, no damping)
   is transported exactly by BOTH shape functions: the grid velocity is p_i / m_i = v
   at every node the block touches, so the velocity gradient is zero by partition of
   unity, no stress arises and nothing can make noise.  Measured: max |stress| 1e-13
   MPa for linear, 6e-9 MPa for uGIMP (see below), so the linear case cannot be "x100
   noisier" here -- there is nothing to amplify.  The test asserts this exactness.

2. Cell-crossing noise needs stress while particles cross cell boundaries: with
   linear shape functions the particle's gradient jumps when it enters a new cell, so
   the internal forces of a stressed body jump too.  The scene: a free-free bar
   vibrating in its first mode (sigma ~ sin(pi x / L), 1 MPa peak) and the same bar
   also translating at 10 m/s across 10 cells.  Noise = largest departure of the
   particle stresses from the smooth mode shape, fitted at each archive time.  The
   test asserts that linear shape functions show it (clearly larger than when the
   bar stays put and than with uGIMP), and prints the numbers.
"""
from __future__ import annotations

import numpy as np
import pytest

from mpm_helpers import Recorder, build, scene_xml

SHAPES = {"linear": "", "uGIMP": "<GIMP/>"}

BLOCK = scene_xml(
    header="""{shape}
    <MaxTime units="ms">2</MaxTime>
    <GlobalArchiveTime units="ms">0.02</GlobalArchiveTime>""",
    grid='<Grid xmin="-4" xmax="60" ymin="-4" ymax="14"><Horiz cellsize="2"/><Vert cellsize="2"/></Grid>',
    bodies='<Body mat="1" thick="1" vx="{vx}" vy="{vy}"><Rect xmin="0" xmax="20" ymin="0" ymax="10"/></Body>',
    rest='<Material Type="1" Name="block"><rho>1</rho><E>1000</E><nu>0.3</nu></Material>')


@pytest.mark.parametrize("shape", list(SHAPES))
def test_stress_free_translation_is_exact(tmp_path, shape):
    vx, vy = 10000.0, 2000.0           # mm/s: 20 mm (10 cells) by 4 mm in 2 ms
    sim = build(tmp_path, BLOCK.format(shape=SHAPES[shape], vx=vx, vy=vy))
    rec = Recorder(lambda s: float(np.abs(s.particles.stress).max()))
    assert sim.run(outputs=[rec])["exit_status"] == "done"
    p = sim.particles
    max_stress = max(rec.probes)
    ke = rec.column("kinetic_energy_J")
    moved = p.pos - p.pos0
    print(f"{shape}: translated {moved[0].mean():.4f} x {moved[1].mean():.4f} mm, "
          f"max |stress| {max_stress:.2e} MPa, kinetic energy change "
          f"{abs(ke[-1] - ke[0]) / ke[0]:.1e}")
    # ~zero: round-off (1e-13 MPa), plus ~6e-9 MPa with uGIMP from nodes at the very
    # edge of a particle's support whose mass falls under the engine's mass tolerance
    # (their velocity is zeroed, their tiny gradient still counts)
    assert max_stress < 1e-6                                    # MPa
    assert np.max(np.abs(ke - ke[0])) < 1e-10 * ke[0]
    assert np.allclose(moved[0], vx * 1e-3 * sim.time, rtol=1e-9)
    assert np.allclose(moved[1], vy * 1e-3 * sim.time, rtol=1e-9)
    assert np.allclose(p.vel[0], vx * 1e-3) and np.allclose(p.vel[1], vy * 1e-3)


BAR_L = 40.0
BAR = scene_xml(
    header="""{shape}
    <MaxTime units="ms">2</MaxTime>
    <GlobalArchiveTime units="ms">0.005</GlobalArchiveTime>""",
    grid='<Grid xmin="-4" xmax="80" ymin="-4" ymax="8"><Horiz cellsize="2"/><Vert cellsize="2"/></Grid>',
    bodies='<Body mat="1" thick="1"><Rect xmin="0" xmax="40" ymin="0" ymax="4"/></Body>',
    rest='<Material Type="1" Name="bar"><rho>1</rho><E>1000</E><nu>0</nu></Material>')


def vibrating_bar_noise(folder, shape: str, speed: float) -> dict:
    """Largest departure (MPa) of sigma_xx from the fitted first free-free mode."""
    sim = build(folder, BAR.format(shape=SHAPES[shape]), f"bar_{shape}_{speed:g}.xml")
    p = sim.particles
    # free-free first mode: v = v1 cos(pi x / L) (1 m/s: 1 MPa stress peak), plus drift
    p.vel[0] = speed + 1.0 * np.cos(np.pi * p.pos[0] / BAR_L)

    def residual(s):
        q = s.particles
        mode = np.sin(np.pi * q.pos0[0] / BAR_L)
        amp = np.dot(mode, q.stress[0]) / np.dot(mode, mode)
        return float(np.abs(q.stress[0] - amp * mode).max()), float(np.abs(q.stress[0]).max())

    rec = Recorder(residual)
    assert sim.run(outputs=[rec])["exit_status"] == "done"
    probes = np.array(rec.probes)
    return {"noise": float(probes[:, 0].max()), "peak": float(probes[:, 1].max()),
            "cells_crossed": float(np.mean(p.pos[0] - p.pos0[0]) / sim.grid.dx)}


@pytest.fixture(scope="module")
def noise(tmp_path_factory):
    folder = tmp_path_factory.mktemp("noise")
    return {(shape, v): vibrating_bar_noise(folder, shape, v)
            for shape in SHAPES for v in (0.0, 10.0)}


def test_cell_crossing_noise_shows_with_linear_shape_functions(noise):
    for (shape, v), r in noise.items():
        print(f"{shape:6s} drift {v:4g} m/s ({r['cells_crossed']:.1f} cells): peak |sigma_xx| "
              f"{r['peak']:.3f} MPa (exact 1), departure from the mode shape {r['noise']:.4f} MPa")
    lin_moving = noise[("linear", 10.0)]["noise"]
    lin_still = noise[("linear", 0.0)]["noise"]
    gimp_moving = noise[("uGIMP", 10.0)]["noise"]
    ratio = lin_moving / gimp_moving
    print(f"cell-crossing noise: linear / uGIMP = {ratio:.1f}, linear moving / still = "
          f"{lin_moving / lin_still:.1f}")
    assert noise[("linear", 10.0)]["cells_crossed"] > 9
    # the noise exists: crossing cells with linear shape functions adds a large
    # non-modal stress (measured ~0.69 MPa on a 1 MPa mode) ...
    assert lin_moving > 0.2
    assert lin_moving > 5 * lin_still
    # ... that uGIMP largely avoids (measured ratio ~5; the peak stress overshoots
    # the exact 1 MPa by ~50% with linear, ~3% with uGIMP)
    assert ratio > 3
    assert noise[("linear", 10.0)]["peak"] > 1.2
    assert noise[("uGIMP", 10.0)]["peak"] < 1.1
