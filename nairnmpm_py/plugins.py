"""Plugin registry over Python entry points.

Built-in and outside plugins register the same way, under the groups below, so the
core never imports a concrete material, law or output by name.  A plugin class may
carry ``nairn_type`` (NairnMPM's ``Type`` number) and ``name``.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from importlib.metadata import entry_points

from .errors import PluginError

GROUPS = {
    "materials": "nairnmpm_py.materials",
    "traction_laws": "nairnmpm_py.traction_laws",
    "propagation": "nairnmpm_py.propagation",
    "outputs": "nairnmpm_py.outputs",
}


@dataclass(frozen=True)
class PluginInfo:
    group: str
    name: str
    nairn_type: int | None
    package: str
    cls: type


def _package_of(ep) -> str:
    dist = getattr(ep, "dist", None)
    return f"{dist.name} {dist.version}" if dist is not None else ep.value.split(":")[0]


@lru_cache(maxsize=None)
def registry(group: str) -> tuple[PluginInfo, ...]:
    """Load every plugin of one group (short name, e.g. ``"materials"``)."""
    if group not in GROUPS:
        raise PluginError(f"unknown plugin group '{group}' (known: {', '.join(GROUPS)})")
    found: dict[str, PluginInfo] = {}
    by_type: dict[int, PluginInfo] = {}
    for ep in entry_points(group=GROUPS[group]):
        package = _package_of(ep)
        try:
            cls = ep.load()
        except Exception as exc:  # a broken plugin must name itself
            raise PluginError(
                f"plugin '{ep.name}' in group {GROUPS[group]} from package {package} "
                f"failed to load: {type(exc).__name__}: {exc}") from exc
        name = getattr(cls, "name", ep.name)
        info = PluginInfo(group, name, getattr(cls, "nairn_type", None), package, cls)
        key = name.lower()
        if key in found and found[key].cls is not cls:
            raise PluginError(
                f"duplicate plugin name '{name}' in group {GROUPS[group]}: from "
                f"{found[key].package} and from {package}")
        if info.nairn_type is not None:
            other = by_type.get(info.nairn_type)
            if other is not None and other.cls is not cls:
                raise PluginError(
                    f"duplicate NairnMPM Type {info.nairn_type} in group {GROUPS[group]}: "
                    f"'{other.name}' from {other.package} and '{name}' from {package}")
            by_type[info.nairn_type] = info
        found[key] = info
    return tuple(sorted(found.values(), key=lambda p: (p.nairn_type is None, p.nairn_type or 0, p.name)))


def resolve(group: str, key: str | int) -> PluginInfo | None:
    """Find a plugin by name (case-insensitive) or by NairnMPM Type number."""
    plugins = registry(group)
    if isinstance(key, int) or (isinstance(key, str) and key.strip().lstrip("-").isdigit()):
        number = int(key)
        for p in plugins:
            if p.nairn_type == number:
                return p
        return None
    for p in plugins:
        if p.name.lower() == str(key).strip().lower():
            return p
    return None


def all_plugins() -> list[PluginInfo]:
    return [p for g in GROUPS for p in registry(g)]
