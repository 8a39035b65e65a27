"""The README's fenced code blocks work as written.

Every fenced block of README.md is extracted and checked by its language:

* ``python``: run as a script in a fresh interpreter (``sys.executable``) whose working
  directory is a temporary folder holding a copy of the repository's ``inputs/``; it must
  exit 0.  A block whose first line names its file (``# mypkg/soft.py``) is written there.
* ``xml``: must parse with lxml; a full input file (root ``JANFEAInput``) must pass
  ``nairnmpm check`` (``nairnmpm_py.cli.main(["check", ...])``) and, when it is tiny, run.
* ``sh``/``bash``/``console``: each command (a line split at ``&&``) starting with
  ``nairnmpm `` runs through ``sh`` in a temporary folder with ``inputs/`` copied, in
  order, and must exit 0; every other command must be listed in ``EXCLUDED_COMMANDS``
  with the reason it is not run, so a new kind of command fails here until it is
  classified.
* ``toml``: must parse, and its entry-point groups must be the package's plugin groups.
* ``text``: a ``--profile`` table as the command prints it; every row must name a task
  of the step list, a periodic task or one of the table's own rows.

Tests are parametrized by block, named after the README line of the opening fence.
"""
from __future__ import annotations

import ast
import inspect
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
TIMEOUT_S = 600          # per subprocess; the first run may compile the Numba kernels

# Shell commands of the README's fenced blocks that are not run, by prefix, and why.
# Everything else in a shell block must start with "nairnmpm " (and is run).
EXCLUDED_COMMANDS = {
    # README line 4 and 5 (the install lines): they build the environment this test
    # already runs in, and line 5 runs the test suite, which would recurse into this file.
    "python3 -m venv": "creates a virtual environment (install step; the tests already run in one)",
    ". .venv/bin/activate": "activates the virtual environment made by the install step",
    "pip install": "installs the package (and may reach a package index); the tests already run on an install",
    "pytest": "runs the whole test suite, which includes this file: it would recurse",
}
# Long-running commands would be excluded here as well (sweeps of the paper-resolution
# DCB family, benchmarks); the README's fenced blocks hold none today: those live in
# its tables, which are prose, not fenced blocks.

SHELL_LANGS = {"sh", "bash", "console", "shell"}
HANDLED_LANGS = {"python", "xml", "toml", "text"} | SHELL_LANGS
TINY_UPDATES = 2e6       # particles x steps below which an XML input block is also run


@dataclass(frozen=True)
class Block:
    lang: str
    line: int            # README line of the opening fence (1-based)
    text: str

    @property
    def id(self) -> str:
        return f"L{self.line}-{self.lang or 'plain'}"


def readme_blocks() -> list[Block]:
    blocks, lang, start, body = [], None, 0, []
    for n, line in enumerate(README.read_text().splitlines(), start=1):
        fence = re.match(r"^\s*```\s*([\w+-]*)", line)
        if lang is None:
            if fence:
                lang, start, body = fence.group(1).lower(), n, []
        elif fence and not fence.group(1):
            blocks.append(Block(lang, start, "\n".join(body) + "\n"))
            lang = None
        else:
            body.append(line)
    assert lang is None, f"README.md:{start}: code fence never closed"
    return blocks


BLOCKS = readme_blocks()


def _of(*langs: str) -> list:
    return [pytest.param(b, id=b.id) for b in BLOCKS if b.lang in langs]


def _workdir(tmp_path: Path) -> Path:
    """A folder holding a copy of inputs/ (without results folders a local run left)."""
    shutil.copytree(ROOT / "inputs", tmp_path / "inputs",
                    ignore=shutil.ignore_patterns("*_results"))
    return tmp_path


def _env() -> dict:
    """The test's environment, with the interpreter's scripts (``nairnmpm``) first on PATH."""
    env = dict(os.environ)
    env["PATH"] = str(Path(sys.executable).parent) + os.pathsep + env.get("PATH", "")
    return env


def _fail_text(proc: subprocess.CompletedProcess) -> str:
    return f"exit {proc.returncode}\n--- stdout\n{proc.stdout[-3000:]}\n--- stderr\n{proc.stderr[-3000:]}"


def _named_file(block: Block) -> str | None:
    """``mypkg/soft.py`` when the block's first line is a comment naming its file."""
    m = re.match(r"#\s*([\w./-]+\.(?:py|toml))\s*$", block.text.splitlines()[0])
    return m.group(1) if m else None


# ---------------------------------------------------------------------------- all

def test_readme_has_the_expected_kinds_of_blocks():
    langs = [b.lang for b in BLOCKS]
    assert {"python", "xml", "sh"} <= set(langs), langs
    unknown = [f"README.md:{b.line} ({b.lang or 'no language'})" for b in BLOCKS
               if b.lang not in HANDLED_LANGS]
    assert not unknown, f"blocks this test does not know how to check: {unknown}"


# ------------------------------------------------------------------------- python

@pytest.mark.parametrize("block", _of("python"))
def test_python_block_runs_twice(block, tmp_path):
    """Runs as written, and again in the same folder (re-running an example must work)."""
    work = _workdir(tmp_path)
    script = work / (_named_file(block) or f"readme_block_{block.line}.py")
    script.parent.mkdir(parents=True, exist_ok=True)
    script.write_text(block.text)
    for attempt in ("first", "second"):
        proc = subprocess.run([sys.executable, str(script)], cwd=work, env=_env(),
                              capture_output=True, text=True, timeout=TIMEOUT_S)
        assert proc.returncode == 0, (f"README.md:{block.line}: python block failed on its "
                                      f"{attempt} run: {_fail_text(proc)}")


def test_plugin_block_update_has_the_engine_signature():
    """The material plugin example's stub update takes what the engine passes."""
    from nairnmpm_py.materials.isotropic import update
    block = next(b for b in BLOCKS if b.lang == "python" and "update_function" in b.text)
    stub = next(n for n in ast.walk(ast.parse(block.text))
                if isinstance(n, ast.FunctionDef) and n.name == "update")
    real = list(inspect.signature(getattr(update, "py_func", update)).parameters)
    assert [a.arg for a in stub.args.args] == real


# ---------------------------------------------------------------------------- xml

@pytest.mark.parametrize("block", _of("xml"))
def test_xml_block_parses_checks_and_runs(block, tmp_path, capsys):
    from lxml import etree
    root = etree.fromstring(block.text.encode())   # raises on malformed XML
    assert isinstance(root.tag, str) and root.tag
    if root.tag != "JANFEAInput":
        return  # a fragment: parsing is its whole check
    from nairnmpm_py.cli import main
    from nairnmpm_py.input import load_simulation
    path = tmp_path / f"readme_block_{block.line}.xml"
    path.write_text(block.text)
    code = main(["check", str(path)])
    out, err = capsys.readouterr()
    assert code == 0, f"README.md:{block.line}: nairnmpm check failed:\n{err}"
    assert "particles:" in out and "time step:" in out
    sim = load_simulation(path)
    if sim.particles.n * sim.n_steps > TINY_UPDATES:
        return  # checked, too large to run here
    out_dir = tmp_path / "results"
    assert main(["run", str(path), "-o", str(out_dir), "-q"]) == 0
    run = json.loads((out_dir / "run.json").read_text())
    assert run["exit_status"] == "done"


def test_the_readme_input_block_is_a_full_input():
    """So the test above really checks and runs it (it is called a 10-line input)."""
    from lxml import etree
    xml = [b for b in BLOCKS if b.lang == "xml"]
    assert xml and all(etree.fromstring(b.text.encode()).tag == "JANFEAInput" for b in xml)


# -------------------------------------------------------------------------- shell

def _commands(block: Block) -> list[tuple[int, str]]:
    """(README line, command) for each command of a shell block, split at ``&&``."""
    cmds = []
    for i, line in enumerate(block.text.splitlines()):
        line = re.sub(r"^\s*\$\s+", "", line)          # console prompts
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        for part in line.split("&&"):
            cmds.append((block.line + 1 + i, part.strip()))
    return cmds


def _excluded(cmd: str) -> str | None:
    return next((why for pre, why in EXCLUDED_COMMANDS.items() if cmd.startswith(pre)), None)


@pytest.mark.parametrize("block", _of(*SHELL_LANGS))
def test_shell_block_nairnmpm_commands_run(block, tmp_path):
    work = _workdir(tmp_path)
    cmds = _commands(block)
    assert cmds, f"README.md:{block.line}: empty shell block"
    for line, cmd in cmds:
        if not cmd.startswith("nairnmpm "):
            assert _excluded(cmd), (f"README.md:{line}: `{cmd}` is neither a nairnmpm command "
                                    "nor in EXCLUDED_COMMANDS: run it here or exclude it")
            continue
        proc = subprocess.run(["sh", "-c", cmd], cwd=work, env=_env(),
                              capture_output=True, text=True, timeout=TIMEOUT_S)
        assert proc.returncode == 0, f"README.md:{line}: `{cmd}` failed: {_fail_text(proc)}"
        args = shlex.split(cmd)[1:]
        if args[0] == "run" and "-o" not in args and "--output" not in args:
            xml = Path(next(a for a in args[1:] if a.endswith(".xml")))
            results = work / xml.with_name(xml.stem + "_results")
            assert (results / "run.json").exists(), f"README.md:{line}: no {results}/run.json"
        if args[0] == "plot" and "-o" not in args:
            pngs = list((work / args[1] / "plots").glob("*.png"))
            assert pngs, f"README.md:{line}: `{cmd}` drew no PNG into {args[1]}/plots"


def test_excluded_commands_are_all_in_the_readme():
    """No stale exclusions: each one matches a command of a fenced shell block."""
    cmds = [c for b in BLOCKS if b.lang in SHELL_LANGS for _, c in _commands(b)]
    stale = [p for p in EXCLUDED_COMMANDS if not any(c.startswith(p) for c in cmds)]
    assert not stale, stale


# --------------------------------------------------------------------------- toml

@pytest.mark.parametrize("block", _of("toml"))
def test_toml_block_names_plugin_groups(block):
    from nairnmpm_py.plugins import GROUPS
    try:
        import tomllib                       # Python >= 3.11
    except ImportError:                      # Python 3.10: the entry-point tables by hand
        tomllib = None
    if tomllib is not None:
        groups = tomllib.loads(block.text).get("project", {}).get("entry-points", {})
    else:
        groups, table = {}, None
        for line in block.text.splitlines():
            head = re.match(r'\[project\.entry-points\."([^"]+)"\]', line.strip())
            pair = re.match(r'(\w+)\s*=\s*"([^"]*)"', line.strip())
            if head:
                table = groups.setdefault(head.group(1), {})
            elif pair and table is not None:
                table[pair.group(1)] = pair.group(2)
    assert groups, f"README.md:{block.line}: no entry points in the toml block"
    for group, entries in groups.items():
        assert group in GROUPS.values(), f"README.md:{block.line}: unknown plugin group {group}"
        for name, target in entries.items():
            assert re.fullmatch(r"[\w.]+:\w+", target), f"README.md:{block.line}: {name} = {target}"


# --------------------------------------------------------------------------- text

@pytest.mark.parametrize("block", _of("text"))
def test_text_block_is_a_profile_table_of_real_tasks(block):
    from nairnmpm_py.core.profile import BETWEEN_CALLS
    from nairnmpm_py.core.tasks import PERIODIC, profile_rows
    known = set(profile_rows(True)) | {p.name for p in PERIODIC} | {BETWEEN_CALLS, "whole step"}
    lines = block.text.strip().splitlines()
    assert lines[0].split() == ["task", "ms/step", "share"] and set(lines[1]) == {"-"}
    names = []
    for line in lines[2:]:
        m = re.match(r"(.+?)\s+(\d+\.\d+)\s+(\d+\.\d) %$", line)
        assert m, f"README.md:{block.line}: not a profile row: {line!r}"
        names.append(m.group(1))
    assert not set(names) - known, f"README.md:{block.line}: unknown rows {set(names) - known}"
    assert names[-1] == "whole step"
