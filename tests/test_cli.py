"""The ``nairnmpm`` command: plugins, check, run and plot, through ``cli.main`` (and
once through the installed console script)."""
from __future__ import annotations

import re
import shutil
import subprocess
import sys

import pytest

from nairnmpm_py.cli import main

from mpm_helpers import write

SMALL = """<?xml version="1.0"?>
<JANFEAInput version="3">
  <Header><Description>small loaded bar</Description><Analysis>11</Analysis></Header>
  <MPMHeader>
    <GIMP/>
    <MaxTime units="ms">0.2</MaxTime>
    <ArchiveTime units="ms">0.1</ArchiveTime>
    <GlobalArchiveTime units="ms">0.01</GlobalArchiveTime>
    <GlobalArchive type="velx" matname="bar"/>
  </MPMHeader>
  <Mesh>
    <Grid xmin="-4" xmax="44" ymin="-4" ymax="8"><Horiz cellsize="2"/><Vert cellsize="2"/></Grid>
  </Mesh>
  <MaterialPoints>
    <Body matname="bar" thick="1"><Rect xmin="0" xmax="40" ymin="0" ymax="4"/></Body>
  </MaterialPoints>
  <Material Type="1" Name="bar"><rho>1</rho><E>1000</E><nu>0.3</nu></Material>
  <GridBCs>
    <BCLine x1="0" y1="min" x2="0" y2="max"><DisBC dir="1" vel="0"/></BCLine>
  </GridBCs>
  <ParticleBCs>
    <LdRect xmin="39" xmax="40" ymin="0" ymax="4"><net/><LoadBC dir="1" style="2" load="20"/></LdRect>
  </ParticleBCs>
</JANFEAInput>
"""


def plugin_rows(text: str) -> list[list[str]]:
    lines = [ln for ln in text.splitlines() if ln.strip()]
    assert lines[0].split()[:4] == ["group", "name", "type", "package"]
    return [ln.split() for ln in lines[1:]]


def test_plugins_lists_materials_with_type_numbers_and_outputs(capsys):
    assert main(["plugins"]) == 0
    rows = plugin_rows(capsys.readouterr().out)
    materials = {r[1]: r for r in rows if r[0] == "nairnmpm_py.materials"}
    assert materials["Isotropic"][2] == "1"
    assert materials["Neohookean"][2] == "28"
    assert all("nairnmpm_py" in " ".join(r[3:]) for r in materials.values())
    outputs = {r[1] for r in rows if r[0] == "nairnmpm_py.outputs"}
    assert {"run_json", "global_csv", "archive_h5", "vtu"} <= outputs


def test_check_prints_particles_cells_and_time_step(tmp_path, capsys):
    path = write(tmp_path, SMALL)
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert re.search(r"particles:\s+160\b", out)             # 20 x 2 cells, 4 per cell
    assert re.search(r"grid:\s+24 x 6 cells of 2 x 2 mm", out)
    m = re.search(r"time step:\s+([0-9.eE+-]+) ms", out)
    # CFL step: 0.5 * 2 mm / c, c = sqrt((lambda + 2G) / rho) for E = 1000, nu = 0.3
    c = (1000 * 0.7 / (1.3 * 0.4) / 1e-3) ** 0.5
    assert float(m.group(1)) == pytest.approx(0.5 * 2 / c, rel=1e-5)
    assert re.search(r"max time:\s+0.2 ms, about \d+ steps", out)
    assert "Isotropic" in out and "plane stress" in out and "uGIMP" in out
    assert not (tmp_path / "scene_results").exists()          # check writes nothing


def test_run_then_plot_makes_pngs(tmp_path, capsys):
    path = write(tmp_path, SMALL)
    out = tmp_path / "res"
    assert main(["run", str(path), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert "particles:" in err and "done:" in err               # not quiet: summary, end line
    for name in ("run.json", "global.csv", "archive.h5", "particles.pvd"):
        assert (out / name).exists(), name
    assert main(["plot", str(out)]) == 0
    printed = [ln for ln in capsys.readouterr().out.splitlines() if ln.strip()]
    pngs = sorted((out / "plots").glob("*.png"))
    assert pngs and sorted(str(p) for p in pngs) == sorted(printed)
    names = {p.name for p in pngs}
    assert "energies.png" in names
    assert any(n.startswith("load_bc") for n in names)           # the LoadBC's load-displacement
    assert "global_velx_mm_s_bar.png" in names
    for p in pngs:
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_plot_into_another_folder(tmp_path, capsys):
    path = write(tmp_path, SMALL)
    out = tmp_path / "res"
    assert main(["run", str(path), "-o", str(out), "-q"]) == 0
    assert main(["plot", str(out), "-o", str(tmp_path / "figs")]) == 0
    assert list((tmp_path / "figs").glob("*.png"))


def test_plot_refuses_a_folder_without_results(tmp_path, capsys):
    assert main(["plot", str(tmp_path)]) == 2
    assert "not a results folder" in capsys.readouterr().err


def test_console_script(tmp_path):
    exe = shutil.which("nairnmpm")
    cmd = [exe] if exe else [sys.executable, "-m", "nairnmpm_py.cli"]
    done = subprocess.run(cmd + ["plugins"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "Neohookean" in done.stdout and "28" in done.stdout
    bad = write(tmp_path, SMALL.replace("<E>1000</E>", "<E>-1</E>"))
    done = subprocess.run(cmd + ["check", str(bad)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 2
    assert f"{bad}:" in done.stderr and "Traceback" not in done.stderr
