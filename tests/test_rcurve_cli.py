"""``nairnmpm rcurve``: the subcommand's functions, driven through its own parser."""
import argparse
import csv

import numpy as np
import pytest

from nairnmpm_py.analysis import rcurve as rc
from nairnmpm_py.analysis import rcurve_cli


def parse(*argv):
    ap = argparse.ArgumentParser(prog="nairnmpm")
    rcurve_cli.add_parser(ap.add_subparsers(dest="command", required=True))
    return ap.parse_args(["rcurve", *argv])


def main(*argv):
    args = parse(*argv)
    return args.func(args)


def read(path):
    with open(path) as fh:
        rows = list(csv.DictReader(fh))
    return {k: np.array([float(r[k]) if r[k] else np.nan for r in rows]) for k in rows[0]}


def test_parser_defaults_to_run():
    args = parse("fig5")
    assert args.func is rcurve_cli.run and args.rcurve_command == "fig5"


def test_theory_writes_table_and_plot(tmp_path, capsys):
    out, png = tmp_path / "R.csv", tmp_path / "R.png"
    assert main("theory", "--law", "Cubic", "--param", "sigmaI=1.0", "--param", "JIc=100",
                "--jtip", "100", "--out", str(out), "--plot", str(png)) == 0
    assert "J_B = 100 J/m^2" in capsys.readouterr().out
    t = read(out)
    assert t["delta_mm"][-1] == pytest.approx(16 / 9 * 0.1)
    assert t["R_J_m2"][0] == pytest.approx(100) and t["R_J_m2"][-1] == pytest.approx(200)
    np.testing.assert_allclose(t["R_J_m2"], t["R_closed_form_J_m2"], rtol=1e-6)
    np.testing.assert_allclose(t["R_eff_J_m2"], t["R_eff_closed_form_J_m2"], rtol=1e-6)
    np.testing.assert_allclose(t["R_J_m2"], 100 + t["W_B_J_m2"] - t["W_B_rec_J_m2"], rtol=1e-9)
    assert png.stat().st_size > 1000


def test_theory_prints_by_type_number(capsys):
    assert main("theory", "--law", "12", "--param", "sigmaI=0.5", "--param", "delIc=0.4",
                "--jtip", "50", "--points", "11") == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("# Triangular (NairnMPM Type 12)")
    assert lines[1].startswith("delta_mm,")
    assert len(lines) == 2 + 11


@pytest.mark.parametrize("argv,message", [
    (("--law", "Cubic", "--param", "sigmaI=1", "--param", "JIc=100", "--param", "delIc=0.2"),
     "give two of sigmaI, delIc, JIc"),
    (("--law", "Nope", "--param", "sigmaI=1"), "no traction law of that name"),
    (("--law", "Cubic", "--param", "sigmaI"), "expected NAME=VALUE"),
    (("--law", "Cubic", "--param", "sigmaI=x", "--param", "JIc=1"), "is not a number"),
    (("--law", "Cubic", "--param", "sigma=1", "--param", "JIc=1"), "not a parameter of this law"),
    (("--law", "Cubic", "--param", "sigmaI=1", "--param", "JIc=100", "--mode", "II"),
     "no mode II tractions"),
])
def test_theory_bad_input_exits_2(argv, message, capsys):
    assert main("theory", *argv, "--jtip", "100") == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


def test_fig5(tmp_path):
    png, table = tmp_path / "fig5.png", tmp_path / "fig5.csv"
    assert main("fig5", "--out", str(png), "--csv", str(table)) == 0
    assert png.stat().st_size > 1000
    t = read(table)
    x = t["delta_over_delta_c"]
    np.testing.assert_allclose(t["R_over_Jtip_cubic"], 1 + x**3 * (4 - 3 * x), rtol=1e-6)
    np.testing.assert_allclose(t["R_eff_over_Jtip_cubic"], 1 + x**2 * (6 - 8 * x + 3 * x**2),
                               rtol=1e-6)
    assert np.all(t["R_over_Jtip_triangular"][x <= 0.2259] == pytest.approx(1.0))


def test_invert_recovers_the_cubic_law(tmp_path):
    R_csv = tmp_path / "R.csv"
    assert main("theory", "--law", "Cubic", "--param", "sigmaI=1.0", "--param", "JIc=100",
                "--jtip", "100", "--points", "801", "--out", str(R_csv)) == 0
    t = read(R_csv)
    with open(tmp_path / "R_only.csv", "w") as fh:  # only the columns an experiment gives
        fh.write("delta_mm,R_J_m2\n")
        for d, R in zip(t["delta_mm"], t["R_J_m2"]):
            fh.write(f"{d:.12g},{R:.12g}\n")
    out = tmp_path / "sigma.csv"
    assert main("invert", "--csv", str(tmp_path / "R_only.csv"), "--out", str(out),
                "--plot", str(tmp_path / "sigma.png")) == 0
    s = read(out)
    inner = (t["delta_over_delta_c"] >= 0.05) & (t["delta_over_delta_c"] <= 0.95)
    assert np.abs(s["sigma_MPa"] - t["sigma_MPa"])[inner].max() < 0.01  # sigma_c = 1 MPa


def test_invert_missing_column(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("delta,R\n0,1\n")
    assert main("invert", "--csv", str(bad)) == 2
    assert "missing column(s) delta_mm, R_J_m2" in capsys.readouterr().err


def _dcb_csv(path, B=20.0, R=500.0):
    K, a0 = 8.0 / (2500.0 * B * 216.0), 50.0
    Fc = np.sqrt(2 * B * R / 1000 / (3 * K * a0**2))
    a_grow = np.linspace(a0, 100.0, 60)[1:]
    F = np.concatenate([np.linspace(0, Fc, 20), np.sqrt(2 * B * R / 1000 / (3 * K * a_grow**2))])
    a = np.concatenate([np.full(20, a0), a_grow])
    with open(path, "w") as fh:
        fh.write("d_mm,F_N,a_mm\n")
        for row in zip(K * a**3 * F, F, a):
            fh.write(",".join(f"{v:.12g}" for v in row) + "\n")


def test_area_method_command(tmp_path, capsys):
    data = tmp_path / "dcb.csv"
    _dcb_csv(data)
    assert main("area", "--csv", str(data), "--thickness", "20") == 0
    out = capsys.readouterr().out
    assert "dcb_area.csv" in out and "dcb_area.png" in out
    t = read(tmp_path / "dcb_area.csv")
    np.testing.assert_allclose(t["R_spline_J_m2"], 500.0, rtol=0.02)
    disc = t["R_discrete_J_m2"][~np.isnan(t["R_discrete_J_m2"])]
    assert len(disc) == 59
    np.testing.assert_allclose(disc, 500.0, rtol=0.02)
    np.testing.assert_allclose(t["U_J_m"], rc.area_method_U(t["d_mm"], t["F_N"], 20.0), atol=1e-6)
    assert (tmp_path / "dcb_area.png").stat().st_size > 1000


def test_area_method_bad_input(tmp_path, capsys):
    data = tmp_path / "dcb.csv"
    _dcb_csv(data)
    assert main("area", "--csv", str(data), "--thickness", "0") == 2
    assert main("area", "--csv", str(tmp_path / "missing.csv"), "--thickness", "1") == 2
    assert main("area", "--csv", str(data), "--thickness", "1", "--smoothing", "lots") == 2
    err = capsys.readouterr().err
    assert "--thickness must be > 0" in err and "missing.csv" in err and "expected 'gcv'" in err
