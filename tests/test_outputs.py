"""Built-in output plugins and the results reader / plots, driven by a fake sim."""
from __future__ import annotations

import json
import types
import xml.etree.ElementTree as ET

import h5py
import meshio
import numpy as np
import pytest

from nairnmpm_py.analysis.plots import column_label, plot_results
from nairnmpm_py.analysis.results import open_results
from nairnmpm_py.core.grid import Grid
from nairnmpm_py.core.particles import Particles
from nairnmpm_py.outputs.archive_h5 import ArchiveH5
from nairnmpm_py.outputs.global_csv import GlobalCsv
from nairnmpm_py.outputs.run_json import RunJson
from nairnmpm_py.outputs.vtu import VtuSeries

N = 6


def fake_sim():
    rng = np.random.default_rng(1)
    pos = rng.uniform(0.0, 10.0, (2, N))
    p = Particles.allocate(pos=pos, vel=np.zeros((2, N)), mass=np.full(N, 2.0),
                           vol0=np.full(N, 0.5), lp=np.full((2, N), 0.25),
                           mat=np.arange(N) % 2, n_hist=1, pdamp=np.zeros(N))
    return types.SimpleNamespace(
        title="fake", plane_stress=True, method=2, shape=1, dt=0.01, max_time=0.02,
        n_steps=2, time=0.0, step=0, particles=p, grid=Grid(0, 10, 0, 10, 5, 4),
        material_names=["steel", "glue"], compile_seconds=0.5,
        source={"path": "/x/in.xml", "sha256": "ab" * 32, "text": "<JANFEAInput/>"})


def row(sim):
    r = {"time_ms": sim.time, "step": sim.step, "kinetic_energy_J": 1e-3 * sim.step,
         "strain_energy_J": 2e-3 * sim.step, "external_work_J": 3e-3 * sim.step,
         "load_N_top": 5.0 * sim.step, "disp_mm_top": 0.1 * sim.step,
         "load_N_free": 0.0, "disp_mm_free": 0.0, "velx_mm_s_steel": 7.0 * sim.step}
    return r


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    folder = tmp_path_factory.mktemp("results")
    sim = fake_sim()
    plugins = [cls(folder) for cls in (RunJson, GlobalCsv, ArchiveH5, VtuSeries)]
    for o in plugins:
        o.begin(sim)
    assert json.loads((folder / "run.json").read_text())["exit_status"] == "running"
    p = sim.particles
    for k in range(2):
        if k:   # move the particles so the two archives differ
            sim.step, sim.time = 2, 0.02
            p.vel[0] = 1.5
            p.pos[0] += 0.1
            p.stress[0] = np.arange(N)
            p.w[:] = 0.25
        r = row(sim)
        for o in plugins:
            o.on_global(sim, r)
            o.on_archive(sim)
    # the CSV must be readable before end (a crash leaves it behind like this)
    assert (folder / "global.csv").read_text().count("\n") == 3
    for o in plugins:
        o.end(sim, {"exit_status": "done", "wall_seconds": 1.25, "steps": 2})
    return folder


def test_global_csv(folder):
    lines = (folder / "global.csv").read_text().splitlines()
    assert lines[0].split(",")[:5] == ["time_ms", "step", "kinetic_energy_J",
                                       "strain_energy_J", "external_work_J"]
    data = np.loadtxt(folder / "global.csv", delimiter=",", skiprows=1)
    assert data.shape == (2, 10)
    assert data[1, 1] == 2 and data[1, 5] == pytest.approx(10.0)


def test_archive_h5(folder):
    with h5py.File(folder / "archive.h5", "r") as h5:
        assert h5.attrs["exit_status"] == "done"
        assert bool(h5.attrs["plane_stress"])
        assert list(h5.attrs["material_names"]) == ["steel", "glue"]
        assert h5["input_xml"][()].decode() == "<JANFEAInput/>"
        assert sorted(h5["archives"]) == ["000000", "000002"]
        last = h5["archives/000002"]
        assert last.attrs["time_ms"] == pytest.approx(0.02)
        assert last["pos"].shape == (2, N) and last["F"].shape == (5, N)
        assert np.allclose(last["vel"][0], 1.5)
        assert np.allclose(last["pos"][0] - last["pos0"][0], 0.1)
        assert last["mat"].dtype == np.int32


def test_vtu_and_pvd(folder):
    mesh = meshio.read(folder / "vtu" / "particles_000002.vtu")
    assert mesh.points.shape == (N, 3)
    assert np.allclose(mesh.point_data["displacement"][:, 0], 0.1)
    assert np.allclose(mesh.point_data["sxx"], np.arange(N))
    assert mesh.point_data["stress"].shape == (N, 9)
    assert list(mesh.point_data["material"]) == [0, 1, 0, 1, 0, 1]
    root = ET.parse(folder / "particles.pvd").getroot()
    sets = root.findall("./Collection/DataSet")
    assert [d.get("file") for d in sets] == ["vtu/particles_000000.vtu", "vtu/particles_000002.vtu"]
    assert float(sets[1].get("timestep")) == pytest.approx(0.02)


def test_run_json(folder):
    run = json.loads((folder / "run.json").read_text())
    assert run["exit_status"] == "done"
    assert run["analysis"] == "plane stress"
    assert run["mpm_method"] == {"number": 2, "name": "USAVG"}
    assert run["particles"] == N and run["cells"] == 20
    assert run["steps_taken"] == 2 and run["wall_seconds"] == 1.25
    assert run["input"]["sha256"] == "ab" * 32
    assert run["units"]["length"] == "mm"


def test_open_results(folder):
    res = open_results(folder)
    assert res.run["exit_status"] == "done"
    assert res.global_columns[0] == "time_ms"
    assert np.allclose(res.global_["load_N_top"], [0.0, 10.0])
    assert res.cracks is None and res.jcontours is None
    assert np.allclose(res.archive_times(), [0.0, 0.02])
    last = res.archive(-1)
    assert last["step"] == 2 and np.allclose(last["vel"][0], 1.5)
    assert res.material_names() == ["steel", "glue"]


def test_plot_results(folder, tmp_path):
    # add crack and contour files so every plot kind is drawn
    (folder / "cracks.csv").write_text(
        "time_ms,crack,tip,crack_growth_mm,J_tip_J_m2,J_ff_J_m2,R_J_m2\n"
        "0,0,1,0,10,12,11\n0.01,0,1,0.5,20,25,24\n0.02,0,1,1.0,22,30,29\n")
    (folder / "jcontours.csv").write_text(
        "contour_mm,J_J_m2,J_tip_J_m2,J_ff_J_m2\n1,5,4,6\n2,5.5,4,6\n")
    try:
        files = plot_results(folder, tmp_path / "plots")
    finally:
        (folder / "cracks.csv").unlink()
        (folder / "jcontours.csv").unlink()
    names = sorted(f.name for f in files)
    assert names == sorted(["energies.png", "load_top.png", "global_velx_mm_s_steel.png",
                            "j_vs_time.png", "r_curve.png", "crack_growth.png",
                            "j_contours.png"])
    for f in files:
        assert f.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_column_labels():
    assert column_label("velx_mm_s_steel") == "x velocity steel (mm/s)"
    assert column_label("J_tip_J_m2") == "J tip (J/m^2)"
    assert column_label("load_N_top") == "load top (N)"
