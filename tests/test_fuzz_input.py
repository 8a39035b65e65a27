"""Fuzzing the reader: random mutations of every shipped input and of NairnMPM's own
examples are refused with exit 2 and ``FILE:LINE`` lines, or accepted, and never end in
a traceback.

Mutations (hypothesis, derandomized so CI sees the same cases every time): delete,
duplicate or swap elements; delete attributes; put text, extreme or malformed numbers
in attributes and element text; truncate the file; reference an undefined entity.
Each case goes through ``nairnmpm check`` (read, validate, build the simulation).
``NAIRNMPM_FUZZ=long`` draws 2,000 new cases (``NAIRNMPM_FUZZ_EXAMPLES`` sets how many)
and also runs each accepted one (to exit 0, 2 or 3) into a fresh folder: minutes to
hours, for benchmarks, not CI.
"""
from __future__ import annotations

import copy
import os
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from lxml import etree

from nairnmpm_py.cli import main

ROOT = Path(__file__).resolve().parents[1]
SEEDS = sorted((ROOT / "inputs").glob("*.xml")) + sorted((ROOT / "tests" / "data").glob("*.fmcmd"))
LONG = os.environ.get("NAIRNMPM_FUZZ") == "long"
EXAMPLES = int(os.environ.get("NAIRNMPM_FUZZ_EXAMPLES", 2000 if LONG else 150))
VALUES = ["", "abc", "nan", "inf", "-inf", "1e308", "-1e308", "1e-308", "0", "-1", "-0",
          "3.5.2", "1e999", " 7 ", "0x10", "9" * 40, "-2147483649", "1,5", "&amp;"]
KINDS = ["delete", "duplicate", "swap", "drop_attribute", "attribute", "text", "truncate",
         "entity"]


def _tree(text: str):
    parser = etree.XMLParser(resolve_entities=False, remove_comments=False)
    return etree.fromstring(text.encode(), parser).getroottree()


@st.composite
def mutated(draw) -> tuple[str, str, str]:
    """(seed file name, what was done, mutated text)."""
    path = draw(st.sampled_from(SEEDS))
    text = path.read_text()
    kind = draw(st.sampled_from(KINDS))
    if kind == "truncate":
        at = draw(st.integers(0, len(text) - 1))
        return path.name, f"truncate at {at}", text[:at]
    if kind == "entity":
        at = text.index("<JANFEAInput")
        at = text.index(">", at) + 1 + draw(st.integers(0, 200))
        return path.name, f"entity at {at}", text[:at] + "&undefined_entity;" + text[at:]
    tree = _tree(text)
    elements = [e for e in tree.getroot().iter() if isinstance(e.tag, str)]
    el = draw(st.sampled_from(elements))
    what = f"{kind} <{el.tag}> (line {el.sourceline})"
    parent = el.getparent()
    if kind == "delete" and parent is not None:
        parent.remove(el)
    elif kind == "duplicate" and parent is not None:
        parent.insert(parent.index(el), copy.deepcopy(el))
    elif kind == "swap" and parent is not None and len(parent) > 1:
        other = parent[draw(st.integers(0, len(parent) - 1))]
        i, j = parent.index(el), parent.index(other)
        if i != j:
            a, b = (el, other) if i < j else (other, el)
            parent.remove(b)
            parent.insert(parent.index(a), b)
    elif kind in ("drop_attribute", "attribute") and el.attrib:
        name = draw(st.sampled_from(sorted(el.attrib)))
        if kind == "drop_attribute":
            del el.attrib[name]
        else:
            el.set(name, draw(st.sampled_from(VALUES)))
        what += f" {name}"
    elif kind == "text" and len(el) == 0:
        el.text = draw(st.sampled_from(VALUES))
    return path.name, what, etree.tostring(tree, encoding="unicode")


@settings(max_examples=EXAMPLES, derandomize=not LONG, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                 HealthCheck.function_scoped_fixture])
@given(case=mutated())
def test_every_mutation_is_refused_cleanly_or_accepted(case, capsys):
    seed, what, text = case
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"fuzz_{Path(seed).stem}.xml"
        path.write_text(text)
        code = main(["check", str(path)])
        err = capsys.readouterr().err
        assert code in (0, 2), f"{seed}, {what}: exit {code}"
        if code == 2:
            lines = [ln for ln in err.splitlines() if ln.strip()]
            assert lines and all(ln.startswith(str(path)) for ln in lines), (seed, what, err)
        if LONG and code == 0:
            out = Path(tmp) / "results"
            assert main(["run", str(path), "-o", str(out), "-q"]) in (0, 2, 3), (seed, what)


def test_the_fuzz_seeds_are_every_example_and_nairnmpms_own():
    assert len(SEEDS) >= 10 and {p.suffix for p in SEEDS} == {".xml", ".fmcmd"}
    for seed in SEEDS:
        assert _tree(seed.read_text()).getroot().tag == "JANFEAInput"


@pytest.mark.parametrize("seed", SEEDS[:1])
def test_an_existing_results_folder_is_never_written_without_force(seed, tmp_path, capsys):
    out = tmp_path / "results"
    out.mkdir()
    (out / "mine.txt").write_text("keep")
    assert main(["run", str(seed), "-o", str(out), "-q"]) == 2
    assert [p.name for p in out.iterdir()] == ["mine.txt"]
    assert "--force" in capsys.readouterr().err
