"""Bad inputs: exit code 2, one ``FILE:LINE: message`` line per problem on stderr
(with the line of the offending element), no traceback, and nothing written."""
from __future__ import annotations

import json
import re

import pytest

from nairnmpm_py.cli import main

from mpm_helpers import line_of, write

GOOD = """<?xml version="1.0"?>
<JANFEAInput version="3">
  <Header><Analysis>11</Analysis></Header>
  <MPMHeader>
    <MaxTime units="ms">0.05</MaxTime>
  </MPMHeader>
  <Mesh>
    <Grid xmin="-4" xmax="24" ymin="-4" ymax="8">
      <Horiz cellsize="2"/><Vert cellsize="2"/>
    </Grid>
  </Mesh>
  <MaterialPoints>
    <Body mat="1" thick="1">
      <Rect xmin="0" xmax="20" ymin="0" ymax="4"/>
    </Body>
  </MaterialPoints>
  <Material Type="1" Name="bar">
    <rho>1</rho>
    <E>1000</E>
    <nu>0.3</nu>
  </Material>
</JANFEAInput>
"""

# name: (text to replace, replacement, text on the offending line, message pattern)
CASES = {
    "malformed-tag-mismatch": ("<E>1000</E>", "<E>1000</e>", "<E>1000</e>",
                               r"malformed XML.*mismatch"),
    "malformed-undefined-entity": ("<E>1000</E>", "<E>&modulus;</E>", "&modulus;",
                                   r"malformed XML.*modulus"),
    "unknown-element": ('<MaxTime units="ms">0.05</MaxTime>',
                        '<MaxTime units="ms">0.05</MaxTime>\n    <Bogus/>', "<Bogus/>",
                        r"unsupported element <Bogus> in <MPMHeader>"),
    "unknown-attribute": ('<Body mat="1" thick="1">', '<Body mat="1" thick="1" colour="red">',
                          'colour="red"', r"unsupported attribute 'colour' on <Body>"),
    "missing-E": ("    <E>1000</E>\n", "", '<Material Type="1"', r"needs <E>"),
    "E-zero": ("<E>1000</E>", "<E>0</E>", "<E>0</E>", r"E must be > 0"),
    "E-negative": ("<E>1000</E>", "<E>-5</E>", "<E>-5</E>", r"E must be > 0"),
    "E-not-a-number": ("<E>1000</E>", "<E>stiff</E>", "<E>stiff</E>", r"not a valid number"),
    "nu-half": ("<nu>0.3</nu>", "<nu>0.5</nu>", "<nu>0.5</nu>", r"nu must satisfy"),
    "nu-above-half": ("<nu>0.3</nu>", "<nu>0.7</nu>", "<nu>0.7</nu>", r"nu must satisfy"),
    "body-outside-grid": ('<Rect xmin="0" xmax="20"', '<Rect xmin="0" xmax="30"',
                          '<Rect xmin="0" xmax="30"', r"outside the grid"),
    "undefined-mat": ('<Body mat="1"', '<Body mat="2"', '<Body mat="2"',
                      r'mat="2".*only 1 material'),
    "undefined-matname": ('<Body mat="1"', '<Body matname="steel"', '<Body matname="steel"',
                          r'matname="steel" names no <Material>'),
    "unknown-time-units": ('<MaxTime units="ms">', '<MaxTime units="fortnights">',
                           'units="fortnights"', r'units="fortnights" is not a known time unit'),
    "unknown-material-type": ('Type="1"', 'Type="99"', 'Type="99"', r"no material or traction-law plugin"),
    "body-of-traction-law": ('<Material Type="1" Name="bar">\n    <rho>1</rho>\n    <E>1000</E>\n    <nu>0.3</nu>',
                             '<Material Type="14" Name="bar">\n    <sigmaI>1</sigmaI>\n    <JIc>100</JIc>',
                             '<Body mat="1"', r"is a traction law \(Cubic\)"),
    "traction-law-three-parameters": ('<Material Type="1" Name="bar">\n    <rho>1</rho>\n    <E>1000</E>\n    <nu>0.3</nu>',
                                      '<Material Type="1" Name="bar">\n    <rho>1</rho>\n    <E>1000</E>\n    <nu>0.3</nu>\n  </Material>\n  <Material Type="14" Name="law">\n    <sigmaI>1</sigmaI>\n    <delIc>0.2</delIc>\n    <JIc>112.5</JIc>',
                                      '<Material Type="14"', r"give two of"),
    "crack-outside-grid": ("</MaterialPoints>", '</MaterialPoints>\n  <CrackList>\n    <Line xmin="2" ymin="2.1" xmax="30" ymax="2.1" resolution="4"/>\n  </CrackList>',
                           "<CrackList>", r"crack point 5 \(30, 2.1\) is outside the grid"),
    "crack-zero-length": ("</MaterialPoints>", '</MaterialPoints>\n  <CrackList>\n    <pt x="2" y="2.1"/>\n    <pt x="2" y="2.1"/>\n    <pt x="8" y="2.1"/>\n  </CrackList>',
                          "<CrackList>", r"crack segment 1 has zero length"),
    "crack-crosses-itself": ("</MaterialPoints>", '</MaterialPoints>\n  <CrackList>\n    <pt x="2" y="1"/>\n    <pt x="8" y="3"/>\n    <pt x="8" y="1"/>\n    <pt x="2" y="3"/>\n  </CrackList>',
                             "<CrackList>", r"crack crosses itself \(segments 1 and 3\)"),
    "crack-mat-not-a-traction-law": ("</MaterialPoints>", '</MaterialPoints>\n  <CrackList>\n    <Line xmin="-1" ymin="2.1" xmax="10" ymax="2.1" resolution="4" mat="1"/>\n  </CrackList>',
                                     '<Line xmin="-1"', r"crack mat: material 1 \('bar'\) is not a traction law"),
    "crack-tip-is-a-traction-law": ("  </Material>\n</JANFEAInput>", '  </Material>\n  <Material Type="14" Name="glue"><sigmaI>1</sigmaI><JIc>100</JIc></Material>\n  <CrackList>\n    <Line xmin="-1" ymin="2.1" xmax="10" ymax="2.1" resolution="4" end_tip="2"/>\n  </CrackList>\n</JANFEAInput>',
                                    '<Line xmin="-1"', r"crack tip material: material 2 \('glue'\) is not a solid material"),
    "crack-law-name-unknown": ("</MaterialPoints>", '</MaterialPoints>\n  <CrackList>\n    <Line xmin="-1" ymin="2.1" xmax="10" ymax="2.1" resolution="4" matname="glue"/>\n  </CrackList>',
                               '<Line xmin="-1"', r"crack mat: no material named 'glue'"),
    # NairnMPM refuses a file without an analysis type with this message
    "no-header": ("  <Header><Analysis>11</Analysis></Header>\n", "", "<JANFEAInput",
                  r"No FEA or MPM analysis type was provided"),
    "max-time-negative": ('<MaxTime units="ms">0.05</MaxTime>', '<MaxTime units="ms">-5</MaxTime>',
                          '<MaxTime units="ms">-5', r"<MaxTime> must be > 0 \(got -5\)"),
    "max-time-zero-timing": ('<MaxTime units="ms">0.05</MaxTime>', '<Timing max="0" units="ms"/>',
                             '<Timing max="0"', r"<Timing max=...> must be > 0"),
    # refused from an estimate before anything is allocated (the grid alone would need
    # petabytes)
    "absurd-resolution": ('<Horiz cellsize="2"/><Vert cellsize="2"/>',
                          '<Horiz cellsize="1e-6"/><Vert cellsize="1e-6"/>', "<Grid xmin",
                          r"particles: about .* GiB, more than this machine's .* GiB of memory"),
}

PROBLEM_LINE = re.compile(r"^(?P<file>.+?):(?P<line>\d+): (?P<msg>.+)$")


def bad_file(tmp_path, case):
    old, new, _, _ = CASES[case]
    text = GOOD.replace(old, new, 1)
    assert text != GOOD
    return text, write(tmp_path, text, "bad.xml")


def problems(err: str) -> list[re.Match]:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert lines, "no message on stderr"
    assert "Traceback" not in err
    matched = [PROBLEM_LINE.match(ln) for ln in lines]
    assert all(matched), f"not FILE:LINE: message lines: {lines}"
    return matched


@pytest.mark.parametrize("case", list(CASES))
def test_bad_input_exits_2_with_file_and_line(tmp_path, capsys, case):
    text, path = bad_file(tmp_path, case)
    _, _, needle, pattern = CASES[case]
    expected_line = line_of(text, needle)
    out = tmp_path / "results"
    code = main(["run", str(path), "-o", str(out), "-q"])
    err = capsys.readouterr().err
    print(err)
    assert code == 2
    found = problems(err)
    assert all(m["file"] == str(path) for m in found)
    hits = [m for m in found if int(m["line"]) == expected_line and re.search(pattern, m["msg"])]
    assert hits, f"no problem on line {expected_line} matching {pattern!r}: {err}"
    # nothing created on disk: no results folder, nothing next to the input
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.xml"]
    # check reports the same, with the same exit code
    assert main(["check", str(path)]) == 2
    assert str(expected_line) in capsys.readouterr().err


@pytest.mark.parametrize("case", ["missing-E", "E-zero", "nu-half"])
def test_invalid_material_is_reported_once(tmp_path, capsys, case):
    _, path = bad_file(tmp_path, case)
    assert main(["check", str(path)]) == 2
    found = problems(capsys.readouterr().err)
    assert len(found) == 1, [m.group(0) for m in found]


def test_not_an_xml_file(tmp_path, capsys):
    path = write(tmp_path, "Title 'a NairnMPM command script'\nMaterial 1\n", "script.fmcmd")
    assert main(["run", str(path), "-o", str(tmp_path / "out"), "-q"]) == 2
    err = capsys.readouterr().err
    found = problems(err)
    assert "not an XML file" in found[0]["msg"]
    assert not (tmp_path / "out").exists()


def test_run_refuses_to_overwrite_results_without_force(tmp_path, capsys):
    path = write(tmp_path, GOOD, "good.xml")
    out = tmp_path / "results"
    assert main(["run", str(path), "-o", str(out), "-q"]) == 0
    before = (out / "run.json").read_text()
    stamp = (out / "run.json").stat().st_mtime_ns
    capsys.readouterr()
    assert main(["run", str(path), "-o", str(out), "-q"]) == 2
    err = capsys.readouterr().err
    assert str(out) in err and "--force" in err
    assert (out / "run.json").read_text() == before
    assert (out / "run.json").stat().st_mtime_ns == stamp
    # with --force it is replaced
    assert main(["run", str(path), "-o", str(out), "-q", "--force"]) == 0
    assert json.loads((out / "run.json").read_text())["exit_status"] == "done"


def test_default_results_folder_is_not_overwritten_either(tmp_path, capsys):
    path = write(tmp_path, GOOD, "good.xml")
    assert main(["run", str(path), "-q"]) == 0
    out = tmp_path / "good_results"
    assert (out / "global.csv").exists()
    assert main(["run", str(path), "-q"]) == 2
    assert "--force" in capsys.readouterr().err


def test_an_unwritable_results_folder_is_refused_with_exit_2(tmp_path, capsys):
    path = write(tmp_path, GOOD, "good.xml")
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder")
    out = blocker / "results"      # under a file: no one can create it, root included
    assert main(["run", str(path), "-o", str(out), "-q"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(out) in err and "cannot create" in err
    assert blocker.read_text() == "not a folder"


def test_a_full_disk_during_the_run_stops_it_with_exit_2_and_keeps_what_was_written(
        tmp_path, capsys, monkeypatch):
    import errno
    from nairnmpm_py.outputs.global_csv import GlobalCsv
    # a global row every 0.005 ms: ten in the run
    text = GOOD.replace('<MaxTime units="ms">0.05</MaxTime>', '<MaxTime units="ms">0.05</MaxTime>'
                        '\n    <GlobalArchiveTime units="ms">0.005</GlobalArchiveTime>')
    path = write(tmp_path, text, "good.xml")
    out = tmp_path / "results"
    real = GlobalCsv.on_global
    calls = []

    def fills_up(self, sim, row):
        calls.append(sim.step)
        if len(calls) > 3:       # the disk fills after three rows
            raise OSError(errno.ENOSPC, "No space left on device",
                          str(self.folder / self.filename))
        real(self, sim, row)
    monkeypatch.setattr(GlobalCsv, "on_global", fills_up)
    assert main(["run", str(path), "-o", str(out), "-q"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "No space left on device" in err and "global.csv" in err
    run = json.loads((out / "run.json").read_text())
    assert run["exit_status"] == "write_failed"
    assert 0 < run["steps_taken"] < run["steps_planned"]      # it stopped there
    rows = (out / "global.csv").read_text().splitlines()
    assert len(rows) == 1 + 3                  # the header and the rows written before
    import h5py
    with h5py.File(out / "archive.h5", "r") as h5:   # closed cleanly
        assert h5.attrs["exit_status"] == "write_failed"
        assert len(h5["archives"]) >= 1
