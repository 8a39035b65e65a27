"""A traction law from outside: the example package in plugins/ is installed with
pip, found through its entry point only, and gets the framework's R-curve theory."""
import importlib
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad

from nairnmpm_py import plugins
from nairnmpm_py.analysis.rcurve import R_of_delta
from nairnmpm_py.cli import main

PACKAGE = Path(__file__).resolve().parents[1] / "plugins" / "nairnmpm-tail-softening"


@pytest.fixture(scope="module")
def installed():
    done = subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-deps",
                           str(PACKAGE)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    importlib.invalidate_caches()
    plugins.registry.cache_clear()
    yield
    plugins.registry.cache_clear()


def test_listed_with_its_package(installed, capsys):
    info = plugins.resolve("traction_laws", "TailSoftening")
    assert info is not None and info.package.startswith("nairnmpm-tail-softening")
    assert main(["plugins"]) == 0
    assert "TailSoftening" in capsys.readouterr().out


def test_framework_theory_applies_to_the_outside_law(installed):
    law = plugins.resolve("traction_laws", "TailSoftening").cls.from_params(sigmaI=0.5, JIc=100.0)
    assert law.delta_c() == pytest.approx(4 * 100.0 / (1000 * 0.5))   # J = sigma dc/(n+1)
    area = quad(lambda d: law.envelope_array(np.array([d]), law.param_vector())[0],
                0, law.delta_c())[0] * 1000.0
    assert area == pytest.approx(100.0, rel=1e-8)
    R = R_of_delta(law, np.array([0.0, law.delta_c()]), 50.0)
    assert R[0] == pytest.approx(50.0) and R[-1] == pytest.approx(150.0, rel=1e-6)


def test_usable_as_a_material_type(installed, tmp_path, capsys):
    text = (Path(__file__).parent / "data" / "tail_softening_material.xml").read_text()
    path = tmp_path / "scene.xml"
    path.write_text(text)
    assert main(["check", str(path)]) == 0
    assert "TailSoftening traction law" in capsys.readouterr().out
