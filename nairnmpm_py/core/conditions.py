"""Boundary conditions as flat tables the kernels can read.

Each condition element of the input is one *record* (style, value, start time,
frequency) with a name for the results columns; its members are grid nodes
(velocity conditions) or particles (loads).  Internal units: mm/ms, N, ms.
"""
from __future__ import annotations

import ast
import math
from dataclasses import dataclass, field

import numpy as np

GRID_VELOCITY = "velocity"
PARTICLE_LOAD = "load"


@dataclass
class ConditionRecord:
    name: str
    kind: str        # GRID_VELOCITY or PARTICLE_LOAD
    direction: int   # 0 = x, 1 = y
    style: int
    value: float     # for style 6: the factor on the expression (unit conversion)
    t0: float = 0.0
    ftime: float = 0.0
    n_members: int = 0
    function: str | None = None   # style 6: expression of t (ms since t0)
    shape_line: int = 0   # input line of the BCLine/BCPt/LdRect that selected the members


# what a style-6 expression may use (NairnMPM's expression language): t in ms since
# the condition's start; x, y the node or particle position (mm); q the particle's
# rotation (radians, counter-clockwise), so a load can turn with its particle
EXPRESSION_FUNCTIONS = {"sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh",
                        "exp", "log", "log10", "sqrt", "abs", "floor", "ceil"}
EXPRESSION_NAMES = {"t", "x", "y", "q", "pi", "e"}


def expression_source(text: str, names: set[str] = EXPRESSION_NAMES) -> str:
    """Python source (math.* calls) of a NairnMPM expression; ValueError if it uses
    anything but ``names`` and the listed functions.  ``^`` is a power, as in NairnMPM."""
    tree = ast.parse(text.replace("^", "**"), mode="eval")
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and node.id not in names | EXPRESSION_FUNCTIONS:
            raise ValueError(f"unknown name '{node.id}' (allowed: {', '.join(sorted(names))} "
                             f"and {', '.join(sorted(EXPRESSION_FUNCTIONS))})")
        if isinstance(node, ast.Call) and not (isinstance(node.func, ast.Name)
                                                and node.func.id in EXPRESSION_FUNCTIONS):
            raise ValueError("only the listed functions may be called")
        if not isinstance(node, (ast.Expression, ast.BinOp, ast.UnaryOp, ast.Call, ast.Name,
                                 ast.Constant, ast.Load, ast.operator, ast.unaryop)):
            raise ValueError(f"'{type(node).__name__}' is not allowed in an expression")

    class ToMath(ast.NodeTransformer):
        def visit_Name(self, node):
            if node.id in EXPRESSION_FUNCTIONS or node.id in ("pi", "e"):
                name = "fabs" if node.id == "abs" else node.id
                return ast.copy_location(ast.Attribute(ast.Name("math", ast.Load()), name,
                                                       ast.Load()), node)
            return node
    return ast.unparse(ast.fix_missing_locations(ToMath().visit(tree)))


def evaluate_expression(text: str, t: float, x: float = 0.0, y: float = 0.0,
                        q: float = 0.0) -> float:
    return float(eval(expression_source(text), {"math": math, "__builtins__": {}},
                      {"t": t, "x": x, "y": y, "q": q}))


@dataclass
class Conditions:
    records: list[ConditionRecord] = field(default_factory=list)
    grid_nodes: list = field(default_factory=list)
    grid_dirs: list = field(default_factory=list)
    grid_recs: list = field(default_factory=list)
    part_ids: list = field(default_factory=list)
    part_dirs: list = field(default_factory=list)
    part_scales: list = field(default_factory=list)
    part_faces: list = field(default_factory=list)   # 0 = the particle, 1-4 its face
    part_recs: list = field(default_factory=list)

    def add_grid_velocity(self, record: ConditionRecord, nodes: np.ndarray) -> None:
        r = len(self.records)
        record.n_members = len(nodes)
        self.records.append(record)
        self.grid_nodes += [int(k) for k in nodes]
        self.grid_dirs += [record.direction] * len(nodes)
        self.grid_recs += [r] * len(nodes)

    def add_particle_load(self, record: ConditionRecord, particles: np.ndarray,
                          scales: np.ndarray, face: int = 0) -> None:
        """``face`` 0: the load goes to the nodes with the particle's own weights
        (LoadBC); 1-4 (bottom, right, top, left): it acts on that face of the particle
        (TractionBC), half at each of the face's two corners, with linear grid weights
        there, as NairnMPM applies tractions."""
        r = len(self.records)
        record.n_members = len(particles)
        self.records.append(record)
        self.part_ids += [int(p) for p in particles]
        self.part_dirs += [record.direction] * len(particles)
        self.part_scales += [float(s) for s in scales]
        self.part_faces += [int(face)] * len(particles)
        self.part_recs += [r] * len(particles)

    def renumber_particles(self, new_index_of_old: np.ndarray) -> None:
        self.part_ids = [int(new_index_of_old[p]) for p in self.part_ids]

    def arrays(self) -> dict:
        """Everything the kernels need, as contiguous numpy arrays."""
        def ints(v):
            return np.array(v, dtype=np.int64)
        recs = self.records
        return dict(
            gbc_node=ints(self.grid_nodes), gbc_dir=ints(self.grid_dirs),
            gbc_rec=ints(self.grid_recs),
            pbc_part=ints(self.part_ids), pbc_dir=ints(self.part_dirs),
            pbc_scale=np.array(self.part_scales, dtype=float), pbc_face=ints(self.part_faces),
            pbc_rec=ints(self.part_recs),
            rec_style=ints([r.style for r in recs]),
            rec_value=np.array([r.value for r in recs], dtype=float),
            rec_t0=np.array([r.t0 for r in recs], dtype=float),
            rec_ftime=np.array([r.ftime for r in recs], dtype=float),
        )
