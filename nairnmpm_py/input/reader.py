"""NairnMPM XML -> validated input model (all problems reported with their line)."""
from __future__ import annotations

import math

from pathlib import Path

from pydantic import ValidationError

from .. import plugins
from ..core.conditions import EXPRESSION_NAMES, expression_source
from ..errors import PluginError
from .models import (AxisModel, BodyModel, ConditionModel, CrackModel, CrackPointModel,
                     CracksHeaderModel, GlobalArchiveModel, GridModel, InputModel,
                     MaterialModel, MPMHeaderModel, ShapeModel)
from .xmlread import Reader, parse_file

# time units NairnMPM reads on header times, as factors to ms (absent = seconds)
TIME_UNITS_TO_MS = {None: 1000.0, "s": 1000.0, "sec": 1000.0, "ms": 1.0, "msec": 1.0,
                    "us": 1e-3, "microsec": 1e-3}
GIMP_TYPES = {"": "uGIMP", "ugimp": "uGIMP", "gimp": "uGIMP", "1": "uGIMP",
              "classic": "linear", "dirac": "linear", "0": "linear"}
GLOBAL_TYPES = {"Kinetic Energy", "Strain Energy", "Work Energy", "Work", "velx", "vely",
                "dispx", "dispy"}
# elements that only shape NairnMPM's own output files: accepted (see README)
OUTPUT_ONLY = {"MPMArchiveOrder", "CrackArchiveOrder", "ArchiveRoot"}


def read_input(path: str | Path) -> InputModel:
    """Parse and validate an input file; raises InputError listing every problem."""
    root, text, sha = parse_file(path)
    r = Reader(path)
    if root.tag != "JANFEAInput":
        r.problem(root, f"root element is <{root.tag}>, expected <JANFEAInput>")
        r.check()
    r.attrs(root, {"version": int})
    parts = {"title": "", "analysis": 10, "analysis_given": False, "mpm": None, "grid": None,
             "bodies": [], "materials": [], "conditions": [], "cracks": []}
    mesh_seen = False
    material_elements = 0
    for el in r.children(root):
        tag = el.tag
        if tag == "Header":
            _header(r, el, parts)
        elif tag == "MPMHeader":
            parts["mpm"] = _mpm_header(r, el)
        elif tag == "Mesh":
            mesh_seen = True
            r.attrs(el, {"output": str})
            for c in r.children(el):
                if c.tag == "Grid":
                    parts["grid"] = _grid(r, c)
                else:
                    r.unknown(c, "Mesh")
        elif tag == "MaterialPoints":
            r.attrs(el, {})
            for c in r.children(el):
                if c.tag in ("Body", "Hole"):
                    body = _body(r, c)
                    if body is not None:
                        parts["bodies"].append(body)
                else:
                    r.unknown(c, "MaterialPoints")
        elif tag == "Material":
            material_elements += 1
            m = _material(r, el)
            if m is not None:
                parts["materials"].append(m)
        elif tag in ("GridBCs", "ParticleBCs"):
            r.attrs(el, {})
            _conditions(r, el, parts["conditions"])
        elif tag == "CrackList":
            crack = _crack_list(r, el)
            if crack is not None:
                parts["cracks"].append(crack)
        else:
            r.unknown(el, "JANFEAInput")
    if not parts.pop("analysis_given"):
        # NairnMPM refuses such a file too, with this message
        r.problem(root, "No FEA or MPM analysis type was provided: add <Header><Analysis>10"
                        "</Analysis></Header> (10 plane strain, 11 plane stress)")
    if parts["mpm"] is None:
        r.problem(root, "missing <MPMHeader>")
    if not mesh_seen or parts["grid"] is None:
        r.problem(root, "missing <Mesh><Grid .../></Mesh>")
    if not any(not b.hole for b in parts["bodies"]):
        r.problem(root, "no <MaterialPoints><Body> defines any particles")
    if not material_elements:
        r.problem(root, "no <Material> defined")
    r.check()
    return InputModel(path=str(path), text=text, sha256=sha, **parts)


# ---- Header ---------------------------------------------------------------------
def _header(r: Reader, el, parts) -> None:
    r.attrs(el, {})
    for c in r.children(el):
        if c.tag == "Description":
            parts["title"] = (c.text or "").strip()
        elif c.tag == "Analysis":
            parts["analysis_given"] = True
            v = r.text(c, int)
            if v is not None and v not in (10, 11):
                r.problem(c, f"<Analysis>{v}</Analysis>: only 10 (plane strain MPM) and 11 "
                             "(plane stress MPM) are supported")
            elif v is not None:
                parts["analysis"] = v
        else:
            r.unknown(c, "Header")


# ---- MPMHeader ------------------------------------------------------------------
def _time(r: Reader, el, value: float | None, units: str | None) -> float | None:
    if value is None:
        return None
    key = units.strip() if isinstance(units, str) else None
    if key not in TIME_UNITS_TO_MS:
        r.problem(el, f"<{el.tag}> units=\"{units}\" is not a known time unit "
                      "(use s, ms, msec, us or microsec)")
        return None
    ms = value * TIME_UNITS_TO_MS[key]
    if not math.isfinite(ms):
        r.problem(el, f"<{el.tag}> {value:g} {key or 's'} is too large a time")
        return None
    return ms


def _positive_time(r: Reader, el, value: float | None, units: str | None,
                   attribute: str) -> float | None:
    """A time that must be > 0 (the run's end); None, with a problem, when it is not."""
    ms = _time(r, el, value, units)
    if ms is not None and not ms > 0.0:
        what = f"<{el.tag} {attribute}=...>" if attribute else f"<{el.tag}>"
        r.problem(el, f"{what} must be > 0 (got {value:g})")
        return None
    return ms


def _mpm_header(r: Reader, el) -> MPMHeaderModel | None:
    r.attrs(el, {})
    h: dict = {"line": el.sourceline, "global_archives": []}
    for c in r.children(el):
        tag = c.tag
        if tag == "MPMMethod":
            v = r.text(c, int)
            if v is not None and v not in (0, 2, 3):
                r.problem(c, f"<MPMMethod>{v}</MPMMethod>: use 0 (USF), 2 (USAVG) or 3 (USL)")
            elif v is not None:
                h["method"] = v
        elif tag == "SkipPostExtrapolation":
            r.attrs(c, {})
            h["post_extrapolate"] = False
        elif tag == "GIMP":
            a = r.attrs(c, {"type": str})
            kind = GIMP_TYPES.get(a.get("type", "").lower()) if "type" in a else "uGIMP"
            if kind is None:
                r.problem(c, f"<GIMP type=\"{a['type']}\">: supported types are uGIMP and Classic")
            else:
                h["shape"] = kind
        elif tag == "Timing":
            a = r.attrs(c, {"step": float, "max": float, "CFL": float, "units": str})
            end = _positive_time(r, c, a.get("max"), a.get("units"), "max")
            if end is not None:
                h["max_time_ms"] = end
                h["max_time_line"] = c.sourceline
            if "step" in a:
                h["time_step_ms"] = _time(r, c, a["step"], a.get("units"))
            if "CFL" in a:
                h["cfl"] = a["CFL"]
        elif tag in ("MaxTime", "TimeStep", "ArchiveTime", "GlobalArchiveTime",
                     "FirstArchiveTime"):
            a = r.attrs(c, {"units": str, "maxProps": int})
            if tag == "MaxTime":
                v = _positive_time(r, c, r.text(c, float), a.get("units"), "")
            else:
                v = _time(r, c, r.text(c, float), a.get("units"))
            key = {"MaxTime": "max_time_ms", "TimeStep": "time_step_ms",
                   "ArchiveTime": "archive_time_ms", "GlobalArchiveTime": "global_archive_time_ms",
                   "FirstArchiveTime": "archive_start_ms"}[tag]
            if v is not None:
                h[key] = v
                if tag == "MaxTime":
                    h["max_time_line"] = c.sourceline
        elif tag == "ArchiveGroup":
            a = r.attrs(c, {"time": float, "start": float, "units": str, "maxProps": int},
                        required=("time",))
            if "time" in a:
                h["archive_time_ms"] = _time(r, c, a["time"], a.get("units"))
            if "start" in a:
                h["archive_start_ms"] = _time(r, c, a["start"], a.get("units"))
        elif tag == "TimeFactor":
            v = r.text(c, float)
            if v is not None:
                h["cfl"] = v
        elif tag == "GlobalArchive":
            a = r.attrs(c, {"type": str, "mat": int, "material": int, "matname": str},
                        required=("type",))
            if "type" in a and a["type"] not in GLOBAL_TYPES:
                r.problem(c, f"<GlobalArchive type=\"{a['type']}\">: supported types are "
                             + ", ".join(sorted(GLOBAL_TYPES)))
            elif "type" in a:
                mat = a.get("mat", a.get("material"))
                h["global_archives"].append(GlobalArchiveModel(
                    type=a["type"], mat=mat, matname=a.get("matname"), line=c.sourceline))
        elif tag in OUTPUT_ONLY:
            r.attrs(c, {"unique": int})
            if tag == "ArchiveRoot":
                h["archive_root"] = (c.text or "").strip()
        elif tag == "Damping":
            r.attrs(c, {})
            v = r.text(c, float)
            if v is not None:
                h["damping_per_s"] = v
        elif tag == "PDamping":
            r.attrs(c, {})
            v = r.text(c, float)
            if v is not None:
                h["pdamping_per_s"] = v
        elif tag == "MatlPtsPerElement":
            v = r.text(c, int)
            if v is not None:
                if _points_per_side(v) is None:
                    r.problem(c, f"<MatlPtsPerElement>{v}: must be a perfect square from 1 to 25")
                else:
                    h["points_per_cell"] = v
        elif tag == "LeaveLimit":
            v = r.text(c, int)
            if v is not None and v < 0:
                r.problem(c, "<LeaveLimit> below 0 (delete particles) is not supported; use "
                             "0 (1% of the particles) or a count")
            elif v is not None:
                h["leave_limit"] = v
        elif tag == "Cracks":
            h["cracks"] = _cracks_header(r, c)
        else:
            r.unknown(c, "MPMHeader")
    try:
        return MPMHeaderModel(**{k: v for k, v in h.items() if v is not None})
    except ValidationError as exc:
        for e in exc.errors():
            r.problem(el, f"<MPMHeader> {'.'.join(map(str, e['loc']))}: {e['msg']}")
        return None


def _points_per_side(n: int) -> int | None:
    side = int(round(n ** 0.5))
    return side if side * side == n and 1 <= n <= 25 else None


# ---- Mesh -------------------------------------------------------------------------
def _grid(r: Reader, el) -> GridModel | None:
    a = r.attrs(el, {"xmin": float, "xmax": float, "ymin": float, "ymax": float,
                     "thickness": float}, required=("xmin", "xmax", "ymin", "ymax"))
    axes = {}
    for c in r.children(el):
        if c.tag in ("Horiz", "Vert"):
            n_name = "nx" if c.tag == "Horiz" else "ny"
            b = r.attrs(c, {"cellsize": float, n_name: int, "symmin": float, "symmax": float})
            if "cellsize" not in b and n_name not in b:
                r.problem(c, f"<{c.tag}> needs cellsize or {n_name}")
            if b.get("cellsize", 1.0) <= 0 or b.get(n_name, 1) <= 0:
                r.problem(c, f"<{c.tag}> cell size and count must be positive")
            axes[c.tag] = AxisModel(cellsize=b.get("cellsize"), n=b.get(n_name),
                                    symmin=b.get("symmin"), symmax=b.get("symmax"),
                                    line=c.sourceline)
        else:
            r.unknown(c, "Grid")
    bounds = ("xmin", "xmax", "ymin", "ymax")
    if any(k not in a for k in bounds) or "Horiz" not in axes or "Vert" not in axes:
        if all(k in a for k in bounds):
            r.problem(el, "<Grid> needs <Horiz> and <Vert> children")
        return None
    if a["xmin"] == a["xmax"] or a["ymin"] == a["ymax"]:
        r.problem(el, "<Grid> has zero width or height")
        return None
    if a.get("thickness", 1.0) <= 0:
        r.problem(el, "<Grid> thickness must be > 0")
    xmin, xmax = sorted((a["xmin"], a["xmax"]))
    ymin, ymax = sorted((a["ymin"], a["ymax"]))
    return GridModel(xmin=xmin, xmax=xmax, ymin=ymin, ymax=ymax,
                     thickness=a.get("thickness", 1.0), horiz=axes["Horiz"],
                     vert=axes["Vert"], line=el.sourceline)


# ---- MaterialPoints -------------------------------------------------------------
def _shape(r: Reader, el) -> ShapeModel | None:
    if el.tag in ("Rect", "Oval"):
        a = r.attrs(el, {"xmin": float, "xmax": float, "ymin": float, "ymax": float,
                         "units": str}, required=("xmin", "xmax", "ymin", "ymax"))
        if "units" in a and a["units"] != "mm":
            r.problem(el, f"<{el.tag}> units=\"{a['units']}\": only mm is supported")
        cut = [s for s in (_shape(r, c) for c in r.children(el)) if s is not None]
        if len([k for k in ("xmin", "xmax", "ymin", "ymax") if k in a]) < 4:
            return None
        xmin, xmax = sorted((a["xmin"], a["xmax"]))
        ymin, ymax = sorted((a["ymin"], a["ymax"]))
        return ShapeModel(kind=el.tag, xmin=xmin, xmax=xmax, ymin=ymin, ymax=ymax,
                          cutouts=cut, line=el.sourceline)
    if el.tag == "Polygon":
        r.attrs(el, {})
        pts = []
        for c in r.children(el):
            if c.tag == "pt":
                a = r.attrs(c, {"x": float, "y": float}, required=("x", "y"))
                if "x" in a and "y" in a:
                    pts.append((a["x"], a["y"]))
            else:
                r.unknown(c, "Polygon")
        if len(pts) < 3:
            r.problem(el, "<Polygon> needs at least 3 <pt> points")
            return None
        return ShapeModel(kind="Polygon", points=pts, line=el.sourceline)
    r.problem(el, f"unsupported shape <{el.tag}> (use Rect, Oval or Polygon)")
    return None


def _body(r: Reader, el) -> BodyModel | None:
    hole = el.tag == "Hole"
    spec = {} if hole else {"mat": int, "matname": str, "thick": float, "vx": float,
                            "vy": float, "angle": float}
    a = r.attrs(el, spec)
    if not hole and "mat" not in a and "matname" not in a:
        r.problem(el, "<Body> needs mat or matname")
    shapes, ppc = [], None
    for c in r.children(el):
        if c.tag == "MatlPtsPerElement" and not hole:
            ppc = r.text(c, int)
            if ppc is not None and _points_per_side(ppc) is None:
                r.problem(c, f"<MatlPtsPerElement>{ppc}: must be a perfect square from 1 to 25")
                ppc = None
        else:
            s = _shape(r, c)
            if s is not None:
                shapes.append(s)
    if a.get("thick", 1.0) <= 0:
        r.problem(el, "<Body> thick must be > 0")
    return BodyModel(hole=hole, mat=a.get("mat"), matname=a.get("matname"),
                     thick=a.get("thick"), vx=a.get("vx", 0.0), vy=a.get("vy", 0.0),
                     angle=a.get("angle", 0.0), points_per_cell=ppc, shapes=shapes,
                     line=el.sourceline)


# ---- Material -------------------------------------------------------------------
COMMON_MATERIAL_CHILDREN = {"PDamping", "color", "Propagate"}


def _material(r: Reader, el) -> MaterialModel | None:
    a = r.attrs(el, {"Type": str, "Name": str}, required=("Type", "Name"))
    if "Type" not in a:
        return None
    # NairnMPM numbers materials and traction laws in one list of <Material>s
    info, group = None, None
    try:
        for group in ("materials", "traction_laws"):
            info = plugins.resolve(group, a["Type"])
            if info is not None:
                break
    except PluginError as exc:
        r.problem(el, str(exc))
        return None
    if info is None:
        known = ", ".join(f"{p.name} ({p.nairn_type})" if p.nairn_type is not None else p.name
                          for g in ("materials", "traction_laws") for p in plugins.registry(g))
        r.problem(el, f"<Material Type=\"{a['Type']}\">: no material or traction-law plugin of "
                      f"that type or name (installed: {known})")
        return None
    values, lines, pdamp, propagate = {}, {}, None, None
    fields = info.cls.Params.model_fields
    for c in r.children(el):
        if c.tag == "PDamping":
            pdamp = r.text(c, float)
        elif c.tag == "Propagate":
            p = r.attrs(c, {"criterion": int, "direction": int, "traction": int})
            propagate = (p.get("criterion", 0), p.get("direction", 0), p.get("traction", 0),
                         c.sourceline)
        elif c.tag == "color":
            r.attrs(c, {"red": float, "green": float, "blue": float, "alpha": float})
        elif c.tag in fields:
            r.attrs(c, {})
            ann = fields[c.tag].annotation
            conv = int if ann is int else (str if ann is str else float)
            v = r.text(c, conv)
            if v is not None:
                values[c.tag] = v
                lines[c.tag] = c.sourceline
        else:
            allowed = ", ".join(list(fields) + sorted(COMMON_MATERIAL_CHILDREN))
            r.problem(c, f"unsupported property <{c.tag}> for material type {info.name} "
                         f"(allowed: {allowed})")
    try:
        params = info.cls.Params(**values)
    except ValidationError as exc:
        for e in exc.errors():
            field = e["loc"][0] if e["loc"] else None
            where = lines.get(field)
            msg = e["msg"].removeprefix("Value error, ")
            if e["type"] == "missing":
                msg = f"material '{a.get('Name')}' ({info.name}) needs <{field}>"
            else:
                msg = f"material '{a.get('Name')}' <{field}>: {msg}" if field else msg
            r.problem(_Line(where) if where else el, msg)
        return None
    return MaterialModel(type=info.nairn_type, plugin=info.name, group=group, name=a.get("Name", ""),
                         params=params.model_dump(), pdamping_per_s=pdamp, propagate=propagate,
                         line=el.sourceline)


class _Line:
    """Stands in for an element when only its line is known."""

    def __init__(self, line):
        self.sourceline = line


# ---- boundary conditions ----------------------------------------------------------
SHAPE_ATTRS = {
    "BCLine": {"x1": str, "y1": str, "x2": str, "y2": str, "tolerance": str},
    "BCPt": {"x": str, "y": str},
    "LdRect": {"xmin": str, "xmax": str, "ymin": str, "ymax": str},
}
SHAPE_REQUIRED = {"BCLine": ("x1", "y1", "x2", "y2"), "BCPt": ("x", "y"),
                  "LdRect": ("xmin", "xmax", "ymin", "ymax")}


def _conditions(r: Reader, el, out: list) -> None:
    grid = el.tag == "GridBCs"
    for shape_el in r.children(el):
        if shape_el.tag not in SHAPE_ATTRS:
            r.unknown(shape_el, el.tag)
            continue
        coords = r.attrs(shape_el, SHAPE_ATTRS[shape_el.tag], required=SHAPE_REQUIRED[shape_el.tag])
        net = False
        for c in r.children(shape_el):
            if grid and c.tag == "DisBC":
                a = r.attrs(c, {"dir": int, "vel": float, "style": int, "time": float,
                                "ftime": float, "function": str}, required=("dir",))
                _append_condition(r, c, a, a.get("vel", 0.0), None, net, shape_el, coords, out)
            elif not grid and c.tag == "net":
                r.attrs(c, {})
                net = True
            elif not grid and c.tag == "perParticle":
                r.attrs(c, {})
                net = False
            elif not grid and c.tag == "LoadBC":
                a = r.attrs(c, {"dir": int, "load": float, "value": float, "style": int,
                                "time": float, "ftime": float, "function": str},
                            required=("dir",))
                _append_condition(r, c, a, a.get("load", a.get("value", 0.0)), None, net,
                                  shape_el, coords, out)
            elif not grid and c.tag == "TractionBC":
                a = r.attrs(c, {"dir": int, "face": int, "stress": float, "style": int,
                                "time": float, "ftime": float, "function": str},
                            required=("dir", "face"))
                if "face" in a and a["face"] not in (1, 2, 3, 4):
                    r.problem(c, "<TractionBC> face must be 1 (bottom), 2 (right), 3 (top) or 4 (left)")
                    continue
                _append_condition(r, c, a, a.get("stress", 0.0), a.get("face"), net,
                                  shape_el, coords, out)
            else:
                r.unknown(c, shape_el.tag)


def _append_condition(r, c, a, value, face, net, shape_el, coords, out) -> None:
    if "dir" not in a:
        return
    allowed_dirs = (1, 2, 11, 12) if c.tag == "TractionBC" else (1, 2)
    if a["dir"] not in allowed_dirs:
        r.problem(c, f"<{c.tag}> dir=\"{a['dir']}\": supported are " + ", ".join(map(str, allowed_dirs)))
        return
    style = a.get("style", 1)
    if style not in (1, 2, 3, 4, 6):
        r.problem(c, f"<{c.tag}> style=\"{style}\": supported are 1 constant, 2 linear, 3 sine, "
                     "4 cosine, 6 function")
        return
    function = a.get("function")
    if (style == 6) != (function is not None):
        r.problem(c, f"<{c.tag}> style 6 and the function attribute go together")
        return
    if function is not None:
        # a grid node has a position but no rotation
        names = EXPRESSION_NAMES - {"q"} if c.tag == "DisBC" else EXPRESSION_NAMES
        try:
            expression_source(function, names)
        except (SyntaxError, ValueError) as exc:
            msg = exc.msg if isinstance(exc, SyntaxError) else str(exc)
            r.problem(c, f"<{c.tag}> function=\"{function}\": {msg}")
            return
    if style in (3, 4):
        t0, ftime = 0.0, a.get("ftime", 0.0)
    else:
        t0, ftime = a.get("time", a.get("ftime", 0.0)), 0.0
    if len(coords) < len(SHAPE_REQUIRED[shape_el.tag]):
        return
    out.append(ConditionModel(element=c.tag, direction=a["dir"], style=style, value=value,
                              time=t0, ftime=ftime, function=function, face=face, net=net,
                              shape=shape_el.tag,
                              coords=coords, shape_line=shape_el.sourceline, line=c.sourceline))


# ---- cracks -----------------------------------------------------------------------
def _cracks_header(r: Reader, el) -> CracksHeaderModel:
    r.attrs(el, {})
    h: dict = {"line": el.sourceline, "propagate": []}
    for c in r.children(el):
        if c.tag == "JContour":
            a = r.attrs(c, {"type": int, "size": int, "terms": int, "gridenergy": int})
            if a.get("type", 1) != 1:
                r.problem(c, "<JContour> type: only 1 (square contour around the tip) is supported")
            if a.get("size", 2) < 1:
                r.problem(c, "<JContour> size must be at least 1 cell")
            if a.get("terms", 1) != 1 or a.get("gridenergy", 0) != 0:
                r.problem(c, "<JContour> terms=2 and gridenergy=1 are not supported")
            h["jcontour_type"] = a.get("type", 1)
            h["jcontour_size"] = a.get("size", 2)
        elif c.tag == "JContourSizes":
            # ours: J on each of these contour half-sizes (cells) into jcontours.csv
            r.attrs(c, {})
            text = (c.text or "").replace(",", " ").split()
            try:
                sizes = [int(v) for v in text]
            except ValueError:
                sizes = []
            if not sizes or min(sizes) < 1:
                r.problem(c, "<JContourSizes> needs whole numbers of cells >= 1, e.g. 2 3 4 6 8")
            else:
                h["jcontour_sizes"] = sizes
        elif c.tag == "Friction":
            r.attrs(c, {})
            v = r.text(c, float)
            if v is not None and v != 0:
                r.problem(c, f"<Friction>{v:g}: only 0 (frictionless crack contact) is supported")
            elif v is not None:
                h["friction"] = v
        elif c.tag == "ContactPosition":
            r.attrs(c, {})
            v = r.text(c, float)
            if v is not None:
                h["contact_position"] = v
        elif c.tag == "Propagate":
            a = r.attrs(c, {"criterion": int, "direction": int, "traction": int})
            h["propagate"].append((a.get("criterion", 0), a.get("direction", 0),
                                   a.get("traction", 0), c.sourceline))
        elif c.tag == "PropagateLength":
            r.attrs(c, {})
            v = r.text(c, float)
            if v is not None:
                if v <= 0:
                    r.problem(c, "<PropagateLength> must be > 0 (cells)")
                else:
                    h["propagate_length"] = v
        else:
            r.unknown(c, "Cracks")
    return CracksHeaderModel(**h)


def _crack_list(r: Reader, el) -> CrackModel | None:
    a = r.attrs(el, {"type": str, "Tprop": int, "Tpropname": str, "friction": float})
    if "friction" in a and a["friction"] != 0:
        r.problem(el, "<CrackList> friction: only 0 (frictionless) is supported")
    points: list[CrackPointModel] = []
    for c in r.children(el):
        if c.tag == "Line":
            b = r.attrs(c, {"xmin": float, "ymin": float, "xmax": float, "ymax": float,
                            "resolution": int, "start_tip": int, "end_tip": int, "mat": int,
                            "matname": str}, required=("xmin", "ymin", "xmax", "ymax"))
            if len([k for k in ("xmin", "ymin", "xmax", "ymax") if k in b]) < 4:
                continue
            n = max(1, b.get("resolution", 1))
            start = _tip_code(b.get("start_tip", -1))
            end = _tip_code(b.get("end_tip", -1))
            for i in range(n + 1):
                f = i / n
                x = b["xmin"] + f * (b["xmax"] - b["xmin"])
                y = b["ymin"] + f * (b["ymax"] - b["ymin"])
                tip = start if i == 0 else (end if i == n else -1)
                if i == 0 and points and abs(points[-1].x - x) < 1e-12 and abs(points[-1].y - y) < 1e-12:
                    # a line continuing the previous one shares its first point
                    points[-1] = points[-1].model_copy(update={"law": b.get("mat"), "lawname": b.get("matname")})
                    continue
                points.append(CrackPointModel(x=x, y=y, tip=tip, law=b.get("mat"),
                                              lawname=b.get("matname"), line=c.sourceline))
        elif c.tag == "pt":
            b = r.attrs(c, {"x": float, "y": float, "tip": int, "mat": int, "matname": str},
                        required=("x", "y"))
            if "x" in b and "y" in b:
                points.append(CrackPointModel(x=b["x"], y=b["y"], tip=_tip_code(b.get("tip", -1)),
                                              law=b.get("mat"), lawname=b.get("matname"),
                                              line=c.sourceline))
        else:
            r.unknown(c, "CrackList")
    if len(points) < 2:
        r.problem(el, "<CrackList> needs at least two points (a <Line> or two <pt>)")
        return None
    return CrackModel(fixed=a.get("type") == "fixed", tprop=a.get("Tprop"),
                      tpropname=a.get("Tpropname"), points=points, line=el.sourceline)


def _tip_code(v: int) -> int:
    """NairnMPM's tip codes: >0 tip material, -2 exterior end, anything else -1."""
    return v if v > 0 or v == -2 else -1
