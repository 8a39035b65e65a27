"""Runs that go wrong end with exit code 3, a message saying where and when, and a
results folder that stays readable (global.csv, run.json, archive.h5)."""
from __future__ import annotations

import json
import re

import h5py
import pytest

from nairnmpm_py.analysis.results import open_results
from nairnmpm_py.cli import main

from mpm_helpers import scene_xml, write

BAR = scene_xml(
    header="""{timing}
    <GlobalArchiveTime units="ms">0.004</GlobalArchiveTime>
    <ArchiveTime units="ms">0.02</ArchiveTime>""",
    grid='<Grid xmin="-4" xmax="108" ymin="-4" ymax="6"><Horiz cellsize="2"/><Vert cellsize="2"/></Grid>',
    bodies='<Body mat="1" thick="1" vx="1000"><Rect xmin="0" xmax="100" ymin="0" ymax="2"/></Body>',
    rest="""<Material Type="1" Name="bar"><rho>1</rho><E>1000</E><nu>0</nu></Material>
  <GridBCs>
    <BCLine x1="0" y1="min" x2="0" y2="max"><DisBC dir="1" vel="0"/></BCLine>
  </GridBCs>""")

TIMINGS = {
    "Timing-CFL-3": '<Timing CFL="3" max="2" units="ms"/>',
    "TimeFactor-3": '<MaxTime units="ms">2</MaxTime><TimeFactor>3</TimeFactor>',
}


def check_readable_after_stop(out, status="unstable"):
    run = json.loads((out / "run.json").read_text())
    assert run["exit_status"] == status
    assert "message" in run and run["steps_taken"] < run["steps_planned"]
    res = open_results(out)
    assert len(res.global_["time_ms"]) >= 1
    assert res.global_columns[:5] == ["time_ms", "step", "kinetic_energy_J",
                                      "strain_energy_J", "external_work_J"]
    with h5py.File(out / "archive.h5", "r") as h5:
        assert h5.attrs["exit_status"] == status
        assert len(h5["archives"]) >= 1
    return run


@pytest.mark.parametrize("timing", list(TIMINGS))
def test_time_step_above_cfl_limit_is_unstable(tmp_path, capsys, timing):
    path = write(tmp_path, BAR.format(timing=TIMINGS[timing]))
    out = tmp_path / "out"
    code = main(["run", str(path), "-o", str(out), "-q"])
    err = capsys.readouterr().err
    print(err)
    # a run that finishes with a time step 3x the CFL limit would be a failure
    assert code == 3, f"expected exit 3 (unstable), got {code}"
    m = re.search(r"step (\d+), t = ([0-9.eE+-]+) ms", err)
    assert m, err
    assert str(path) in err and "particle" in err
    run = check_readable_after_stop(out)
    assert run["steps_taken"] == int(m.group(1))
    assert f"step {m.group(1)}" in run["message"]


def test_same_bar_at_the_cfl_limit_runs(tmp_path, capsys):
    """Control: the scene above is fine at the default CFL factor 0.5."""
    path = write(tmp_path, BAR.format(timing='<Timing max="2" units="ms"/>'))
    assert main(["run", str(path), "-o", str(tmp_path / "out"), "-q"]) == 0
    assert json.loads((tmp_path / "out" / "run.json").read_text())["exit_status"] == "done"


FLYER = """<?xml version="1.0"?>
<JANFEAInput version="3">
  <Header><Analysis>11</Analysis></Header>
  <MPMHeader>
    <MaxTime units="ms">2</MaxTime>
    <GlobalArchiveTime units="ms">0.05</GlobalArchiveTime>
    <LeaveLimit>1</LeaveLimit>
  </MPMHeader>
  <Mesh>
    <Grid xmin="0" xmax="40" ymin="0" ymax="10"><Horiz cellsize="2"/><Vert cellsize="2"/></Grid>
  </Mesh>
  <MaterialPoints>
    <Body mat="1" thick="1" vx="50000"><Rect xmin="4" xmax="10" ymin="4" ymax="6"/></Body>
  </MaterialPoints>
  <Material Type="1" Name="block"><rho>1</rho><E>1000</E><nu>0.3</nu></Material>
</JANFEAInput>
"""


def test_particle_leaving_the_grid(tmp_path, capsys):
    path = write(tmp_path, FLYER)
    out = tmp_path / "out"
    code = main(["run", str(path), "-o", str(out), "-q"])
    err = capsys.readouterr().err
    print(err)
    assert code == 3
    assert "left the grid" in err
    m = re.search(r"step (\d+), t = ([0-9.eE+-]+) ms", err)
    assert m, err
    # the block's front (x = 10 mm) reaches the edge (40 mm) at 50 m/s after 0.6 ms
    assert float(m.group(2)) == pytest.approx(0.6, abs=0.05)
    run = check_readable_after_stop(out)
    assert "left the grid" in run["message"]
