"""Reading NairnMPM XML with lxml: internal DTD entities, source lines, strict checks.

Every problem is collected as ``FILE:LINE: message`` so a user sees all of them at
once; an element or attribute we do not know is a problem, never silently skipped.
"""
from __future__ import annotations

import hashlib
import math
from pathlib import Path

from lxml import etree

from ..errors import InputError, InputProblem


class Reader:
    """Collects problems while the model is built from one file."""

    def __init__(self, path: str | Path):
        self.path = str(path)
        self.problems: list[InputProblem] = []

    def problem(self, el, message: str) -> None:
        line = getattr(el, "sourceline", None) if el is not None else None
        self.problems.append(InputProblem(self.path, line, message))

    def check(self) -> None:
        if self.problems:
            raise InputError(self.problems)

    # ---- elements ------------------------------------------------------------
    @staticmethod
    def children(el) -> list:
        return [c for c in el if isinstance(c.tag, str)]

    def unknown(self, el, where: str) -> None:
        self.problem(el, f"unsupported element <{el.tag}> in <{where}>")

    def attrs(self, el, spec: dict, required: tuple = ()) -> dict:
        """Attributes of ``el`` converted by ``spec`` (name -> converter)."""
        out = {}
        for name, raw in el.attrib.items():
            conv = spec.get(name)
            if conv is None:
                allowed = ", ".join(spec) if spec else "none"
                self.problem(el, f"unsupported attribute '{name}' on <{el.tag}> (allowed: {allowed})")
                continue
            try:
                out[name] = _finite(conv(raw.strip()))
            except (ValueError, TypeError):
                self.problem(el, f"<{el.tag}> attribute {name}=\"{raw}\" is not a valid {_kind(conv)}")
        for name in required:
            if name not in el.attrib:
                self.problem(el, f"<{el.tag}> needs the attribute '{name}'")
        return out

    def text(self, el, conv=str, required: bool = True):
        raw = (el.text or "").strip()
        if not raw:
            if required:
                self.problem(el, f"<{el.tag}> needs a value")
            return None
        try:
            return _finite(conv(raw))
        except (ValueError, TypeError):
            self.problem(el, f"<{el.tag}> value '{raw}' is not a valid {_kind(conv)}")
            return None

    def no_children(self, el) -> None:
        for c in self.children(el):
            self.unknown(c, el.tag)


def _finite(value):
    """NaN and infinity are no value of any input field (an infinite MaxTime or
    modulus would only fail later, and less clearly)."""
    if isinstance(value, float) and not math.isfinite(value):
        raise ValueError("not finite")
    return value


def _kind(conv) -> str:
    return {float: "number", int: "integer", str: "text"}.get(conv, getattr(conv, "__name__", "value"))


def parse_file(path: str | Path):
    """Parse XML, expanding internal entities; returns (root, text, sha256)."""
    path = Path(path)
    if not path.exists():
        raise InputError(InputProblem(str(path), None, "file not found"))
    data = path.read_bytes()
    parser = etree.XMLParser(resolve_entities=True, load_dtd=False, no_network=True,
                             remove_comments=True, remove_pis=True, huge_tree=True)
    try:
        root = etree.fromstring(data, parser)
    except etree.XMLSyntaxError as exc:
        line = exc.lineno if getattr(exc, "lineno", None) else None
        msg = exc.msg if hasattr(exc, "msg") else str(exc)
        msg = (msg.splitlines() or [""])[0].strip()    # one line (lxml may quote the text)
        if data.lstrip()[:1] != b"<":
            msg = "not an XML file (NairnMPM command scripts must be exported to XML first)"
        raise InputError(InputProblem(str(path), line, f"malformed XML: {msg}")) from None
    text = data.decode("utf-8", errors="replace")
    return root, text, hashlib.sha256(data).hexdigest()
