"""``nairnmpm sweep``: a template with entities, a table of values, members on a local
Dask cluster; a bad member is reported in summary.csv and does not stop the others."""
from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from nairnmpm_py.cli import main
from nairnmpm_py.errors import InputError
from nairnmpm_py.sweep import member_input, read_table, run_sweep

from mpm_helpers import write

# 48 particles (6 x 2 cells, 4 per cell), about a dozen steps; GIMP like test_cli's
# scene so the compiled kernels in the cache are the same ones
TEMPLATE = """<?xml version="1.0"?>
<!DOCTYPE JANFEAInput [
  <!ENTITY E "1000">
  <!ENTITY load "20">
]>
<JANFEAInput version="3">
  <Header><Description>small loaded bar, E = &E; MPa</Description><Analysis>11</Analysis></Header>
  <MPMHeader>
    <GIMP/>
    <MaxTime units="ms">0.01</MaxTime>
    <ArchiveTime units="ms">0.005</ArchiveTime>
    <GlobalArchiveTime units="ms">0.002</GlobalArchiveTime>
  </MPMHeader>
  <Mesh>
    <Grid xmin="-4" xmax="16" ymin="-4" ymax="8"><Horiz cellsize="2"/><Vert cellsize="2"/></Grid>
  </Mesh>
  <MaterialPoints>
    <Body matname="bar" thick="1"><Rect xmin="0" xmax="12" ymin="0" ymax="4"/></Body>
  </MaterialPoints>
  <Material Type="1" Name="bar"><rho>1</rho><E>&E;</E><nu>0.3</nu></Material>
  <GridBCs>
    <BCLine x1="0" y1="min" x2="0" y2="max"><DisBC dir="1" vel="0"/></BCLine>
  </GridBCs>
  <ParticleBCs>
    <LdRect xmin="11" xmax="12" ymin="0" ymax="4"><net/><LoadBC dir="1" style="2" load="&load;"/></LdRect>
  </ParticleBCs>
</JANFEAInput>
"""

TABLE = """name,E,load
soft,1000,20
stiff,2000,40
bad,-5,20
"""


def read_summary(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_member_input_overrides_entities_and_rejects_unknown_names(tmp_path):
    xml = member_input(TEMPLATE, {"name": "x", "E": "2500"})
    assert '<!ENTITY E "2500">' in xml and '<!ENTITY load "20">' in xml
    with pytest.raises(InputError) as exc:
        member_input(TEMPLATE, {"Emod": "1"}, tmp_path / "t.xml")
    assert str(exc.value).startswith(f"{tmp_path / 't.xml'}:2: table column 'Emod'")
    rows = read_table(write(tmp_path, "E\n1\n2\n", "t.csv"))
    assert [r["name"] for r in rows] == ["run_001", "run_002"] and rows[1]["E"] == "2"


def test_sweep_runs_members_reports_the_bad_one_and_plots(tmp_path, capsys):
    template = write(tmp_path, TEMPLATE, "bar.xml")
    table = write(tmp_path, TABLE, "table.csv")
    out = tmp_path / "sweep"
    assert main(["sweep", str(template), str(table), "-o", str(out), "--workers", "2"]) == 3
    err = capsys.readouterr().err
    assert "bad: input error" in err and "2 of 3 members done" in err

    rows = {r["name"]: r for r in read_summary(out / "summary.csv")}
    assert list(rows) == ["soft", "stiff", "bad"]
    for name in ("soft", "stiff"):
        r = rows[name]
        assert r["exit_status"] == "done" and int(r["steps"]) > 5
        assert (out / name / "run.json").exists() and (out / name / "global.csv").exists()
        assert float(r["kinetic_energy_J"]) > 0 and float(r["strain_energy_J"]) > 0
    assert rows["stiff"]["E"] == "2000" and rows["stiff"]["load"] == "40"
    assert '<!ENTITY E "2000">' in (out / "stiff" / "input.xml").read_text()
    bad = rows["bad"]
    assert bad["exit_status"] == "input error"
    assert "input.xml" in bad["message"] and "E must be > 0" in bad["message"]
    assert (out / "bad" / "input.xml").exists() and not (out / "bad" / "run.json").exists()

    # the folder exists now: refused without --force
    assert main(["sweep", str(template), str(table), "-o", str(out)]) == 2
    assert "--force" in capsys.readouterr().err

    # nairnmpm plot overlays the members
    assert main(["plot", str(out)]) == 0
    files = capsys.readouterr().out.split()
    assert any(f.endswith("sweep_energies.png") for f in files)
    assert any("sweep_load_" in f for f in files)


def test_unknown_column_is_bad_input_naming_it(tmp_path, capsys):
    template = write(tmp_path, TEMPLATE, "bar.xml")
    table = write(tmp_path, "name,E,modulus\na,1000,3\n", "table.csv")
    out = tmp_path / "sweep"
    assert main(["sweep", str(template), str(table), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert f"{template}:2:" in err and "'modulus'" in err and "declared: E, load" in err
    assert not out.exists()                       # nothing runs, nothing is written


def test_run_sweep_function_returns_statuses_in_table_order(tmp_path):
    template = write(tmp_path, TEMPLATE, "bar.xml")
    rows = [{"name": "one", "E": "1500"}]
    res = run_sweep(template, rows, tmp_path / "s", workers=1)
    assert [r["name"] for r in res] == ["one"] and res[0]["exit_status"] == "done"
    assert res[0]["steps"] > 5 and (tmp_path / "s" / "summary.csv").exists()


def test_sweep_plots_overlay_crack_results(tmp_path):
    """Members with cracks.csv get J_tip / growth and R-curve overlays (R against
    growth and against the notch-root opening), and zone length against the moment
    where global.csv has a moment column."""
    from nairnmpm_py.analysis.sweep_plots import plot_sweep
    (tmp_path / "summary.csv").write_text("name,exit_status\na,done\nb,done\n")
    head = "time_ms,crack,tip,crack_growth_mm,J_tip_J_m2,R_J_m2,cod_notch0_mm,zone_length_mm,event\n"
    for name, jc in (("a", 100.0), ("b", 200.0)):
        d = tmp_path / name
        d.mkdir()
        (d / "global.csv").write_text("time_ms,step,kinetic_energy_J,moment_Nmm_bc1_bc2,"
                                      "moment_Nmm_bc3_bc4,opening_mm_bc1_bc2_bc3_bc4\n"
                                      "0,0,0,0,0,0\n1,10,1e-3,-5,5,0.1\n2,20,2e-3,-9,9,0.2\n")
        (d / "run.json").write_text(json.dumps({"r_curve_theory": [
            {"crack": 1, "tip": "end", "cod_mm": [0, 0.05], "R_J_m2": [jc, jc + 10]}]}))
        rows = [f"{t},1,\"end\",0,{jc * t / 2},,0,0,\"archive\"" for t in (0.0, 1.0)]
        rows += [f"{1 + k / 10},1,\"end\",{k * 0.5},{jc},{jc + 10 * k},{0.01 * k},{k},\"growth\""
                 for k in range(5)]
        (d / "cracks.csv").write_text(head + "\n".join(rows) + "\n")
    written = {p.name for p in plot_sweep(tmp_path)}
    assert {"sweep_cracks.png", "sweep_r_curve.png", "sweep_energies.png", "sweep_r_cod.png",
            "sweep_zone_moment.png", "sweep_load_bc1_bc2.png", "sweep_load_bc3_bc4.png"} <= written


def test_moments_plot_against_the_opening_of_their_groups():
    """A moment column pairs with the opening_mm_ column naming its group (Figs 8A, 9A);
    a load column with its own disp_mm_ column; anything else with nothing."""
    from nairnmpm_py.analysis.plots import load_displacement
    g = {"moment_Nmm_bc1_bc2": np.array([0.0, 1.0]), "moment_Nmm_bc3_bc4": np.array([0.0, -1.0]),
         "moment_Nmm_bc5_bc6": np.array([0.0, 2.0]), "opening_mm_bc1_bc2_bc3_bc4": np.array([0.0, 0.3]),
         "load_N_bc7_y": np.array([0.0, 4.0]), "disp_mm_bc7_y": np.array([0.0, 0.01])}
    for col in ("moment_Nmm_bc1_bc2", "moment_Nmm_bc3_bc4"):
        x, label, used = load_displacement(g, col)
        assert used == "opening_mm_bc1_bc2_bc3_bc4" and label == "load-line opening (mm)"
    assert load_displacement(g, "moment_Nmm_bc5_bc6")[0] is None
    assert load_displacement(g, "load_N_bc7_y")[2] == "disp_mm_bc7_y"


@pytest.mark.parametrize("table", ["dcb_family.csv", "dcb_family_paper.csv"])
def test_shipped_dcb_family_tables_make_valid_members(table, tmp_path):
    """Every member of the shipped family tables (1 mm cells, and the paper's 0.25 mm
    particles) is a valid input: the template's entities, a grid that holds the
    specimen, the loaded rows on particle centres."""
    from pathlib import Path

    from nairnmpm_py.input import load_simulation
    inputs = Path(__file__).resolve().parents[1] / "inputs"
    template = inputs / "dcb_bridging.xml"
    rows = read_table(inputs / table)
    assert len(rows) == 8
    for row in rows[:1] + rows[-1:]:
        path = write(tmp_path, member_input(template.read_text(), row, template), "member.xml")
        sim = load_simulation(path)
        spacing = float(row.get("cs", "1")) / 2
        assert sim.particles.n == round(150 * 12 / spacing ** 2)
        # four loaded rows, x and y: each the particles within 2 mm of the end
        members = [rec.n_members for rec in sim.conditions.records if rec.n_members]
        assert members == [round(2 / spacing)] * 8
