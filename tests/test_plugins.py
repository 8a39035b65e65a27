"""Plugin registry: lookup by name and Type number, clear errors for broken or
clashing plugins."""
from types import SimpleNamespace

import pytest

from nairnmpm_py import plugins
from nairnmpm_py.errors import PluginError


def test_builtins_resolve_by_name_and_type():
    assert plugins.resolve("materials", 1).name == "Isotropic"
    assert plugins.resolve("materials", "28").name == "Neohookean"
    assert plugins.resolve("materials", "neohookean").nairn_type == 28
    assert plugins.resolve("materials", 9999) is None
    names = {p.name for p in plugins.registry("outputs")}
    assert {"global_csv", "archive_h5", "vtu", "run_json"} <= names


class _EP:
    def __init__(self, name, target, dist="somepkg"):
        self.name, self._target = name, target
        self.value = f"{dist}.mod:{name}"
        self.dist = SimpleNamespace(name=dist, version="1.0")

    def load(self):
        if isinstance(self._target, Exception):
            raise self._target
        return self._target


def _with_entry_points(monkeypatch, eps):
    monkeypatch.setattr(plugins, "entry_points", lambda group: eps)
    plugins.registry.cache_clear()


@pytest.fixture(autouse=True)
def _clear_cache():
    yield
    plugins.registry.cache_clear()


def test_broken_plugin_names_its_package(monkeypatch):
    _with_entry_points(monkeypatch, [_EP("Bad", ImportError("no module named x"), "brokenpkg")])
    with pytest.raises(PluginError, match="brokenpkg 1.0.*failed to load.*no module named x"):
        plugins.registry("materials")


def test_duplicate_type_number_names_both_packages(monkeypatch):
    a = type("A", (), {"name": "A", "nairn_type": 1})
    b = type("B", (), {"name": "B", "nairn_type": 1})
    _with_entry_points(monkeypatch, [_EP("A", a, "pkga"), _EP("B", b, "pkgb")])
    with pytest.raises(PluginError, match="duplicate NairnMPM Type 1.*pkga.*pkgb"):
        plugins.registry("materials")


def test_duplicate_name_names_both_packages(monkeypatch):
    a = type("A", (), {"name": "Same"})
    b = type("B", (), {"name": "same"})
    _with_entry_points(monkeypatch, [_EP("A", a, "pkga"), _EP("B", b, "pkgb")])
    with pytest.raises(PluginError, match="duplicate plugin name"):
        plugins.registry("materials")
