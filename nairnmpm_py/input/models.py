"""Validated models of an input file, in the file's units, with source lines kept.

Times here are already in ms (header times were converted from their ``units``);
velocities are mm/s and loads N as NairnMPM reads them: ``build`` converts to the
engine's units (mm, g, ms).
"""
from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field


class Model(BaseModel):
    model_config = ConfigDict(extra="forbid", arbitrary_types_allowed=True)
    line: int | None = None


class GlobalArchiveModel(Model):
    type: str
    mat: int | None = None       # 1-based material number
    matname: str | None = None


class CracksHeaderModel(Model):
    jcontour_type: int = 1
    jcontour_size: int = 2
    jcontour_sizes: list[int] = []   # ours: sizes (cells) for jcontours.csv
    friction: float = 0.0        # 0 = frictionless (the only kind so far)
    contact_position: float | None = None
    propagate: list[tuple[int, int, int, int | None]] = []   # criterion, direction, traction, line
    propagate_length: float = 0.5


class MPMHeaderModel(Model):
    method: Literal[0, 2, 3] = 2
    post_extrapolate: bool = True
    shape: Literal["linear", "uGIMP"] = "linear"
    max_time_ms: float = 1000.0          # NairnMPM's default maximum time is 1 s
    time_step_ms: float | None = None
    max_time_line: int | None = None
    cfl: float = Field(0.5, gt=0)
    archive_time_ms: float | None = None
    archive_start_ms: float = 0.0
    global_archive_time_ms: float | None = None
    global_archives: list[GlobalArchiveModel] = []
    archive_root: str | None = None
    damping_per_s: float = 0.0
    pdamping_per_s: float = 0.0
    points_per_cell: int = 4
    leave_limit: int = 0
    cracks: CracksHeaderModel | None = None


class AxisModel(Model):
    cellsize: float | None = None
    n: int | None = None
    symmin: float | None = None
    symmax: float | None = None


class GridModel(Model):
    xmin: float
    xmax: float
    ymin: float
    ymax: float
    thickness: float = 1.0
    horiz: AxisModel
    vert: AxisModel


class ShapeModel(Model):
    kind: Literal["Rect", "Oval", "Polygon"]
    xmin: float = 0.0
    xmax: float = 0.0
    ymin: float = 0.0
    ymax: float = 0.0
    points: list[tuple[float, float]] = []
    cutouts: list["ShapeModel"] = []


class BodyModel(Model):
    hole: bool = False
    mat: int | None = None
    matname: str | None = None
    thick: float | None = None
    vx: float = 0.0   # mm/s
    vy: float = 0.0
    angle: float = 0.0
    points_per_cell: int | None = None
    shapes: list[ShapeModel] = []


class MaterialModel(Model):
    type: int | None = None
    plugin: str
    group: Literal["materials", "traction_laws"] = "materials"
    name: str
    params: dict
    pdamping_per_s: float | None = None
    propagate: tuple[int, int, int, int | None] | None = None  # criterion, direction, traction, line


class ConditionModel(Model):
    """A DisBC, LoadBC or TractionBC with the shape that selects its members."""
    element: Literal["DisBC", "LoadBC", "TractionBC"]
    direction: int
    style: int = 1
    value: float = 0.0           # mm/s, N or MPa
    time: float = 0.0            # ms (start of styles 1 and 2)
    ftime: float = 0.0           # rad/ms (styles 3 and 4)
    function: str | None = None  # style 6: expression of t (ms since time)
    face: int | None = None
    net: bool = False
    shape: Literal["BCLine", "BCPt", "LdRect"]
    coords: dict                 # raw coordinate strings (min-, max+, *1 resolved later)
    shape_line: int | None = None


class CrackPointModel(Model):
    x: float
    y: float
    tip: int = -1                # >0 tip material (J, propagation), -1 plain end, -2 exterior
    law: int | None = None       # traction law: 1-based material number
    lawname: str | None = None


class CrackModel(Model):
    fixed: bool = False
    tprop: int | None = None
    tpropname: str | None = None
    points: list[CrackPointModel] = []


class InputModel(Model):
    path: str
    text: str = ""
    sha256: str = ""
    title: str = ""
    analysis: Literal[10, 11] = 10
    mpm: MPMHeaderModel
    grid: GridModel
    bodies: list[BodyModel]
    materials: list[MaterialModel]
    conditions: list[ConditionModel] = []
    cracks: list[CrackModel] = []
