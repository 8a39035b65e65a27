"""Moments of the particle loads, for global.csv's ``moment_Nmm_<name>`` columns.

A moment is reported for every *group* of two or more load shapes (``BCLine``,
``BCPt``, ``LdRect`` holding ``LoadBC``/``TractionBC``) that act on one piece of the
body: two shapes belong together unless the straight line between their particles'
centroids crosses a crack.  On the seed paper's DCB this gives one group per arm (the
two loaded rows of each arm) and its column is the moment that arm carries; on an
uncracked beam with two end forces it is the couple they make.

Each load condition's total force (``load_N_`` column) is taken to act at the current
centroid of its particles, and the moment (N mm, counter-clockwise positive) is taken
about the centroid of the group's shapes.  For a couple (zero net force) the reference
point does not matter.  This is exact when the particles of one condition carry equal
loads (constant, ``<net/>`` or any load of time alone); a style-6 load that depends on
the particle (x, y, q) differs between particles only by the spread of those values.

When there are exactly two groups, global.csv also gets ``opening_mm_<group>_<group>``:
how far the groups' centres have moved apart (the load-line opening of a DCB's arms).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.conditions import PARTICLE_LOAD


@dataclass
class LoadCouple:
    name: str               # column suffix: bc<line>_bc<line>... (the shapes' input lines)
    records: np.ndarray     # condition record indices
    members: list           # per record: its particle indices


def load_couples(conditions, positions: np.ndarray, cracks=None) -> list[LoadCouple]:
    """Groups of particle-load shapes on one piece of the body (see the module)."""
    part_ids = np.asarray(conditions.part_ids, dtype=np.int64)
    part_recs = np.asarray(conditions.part_recs, dtype=np.int64)
    shapes: dict[int, list[int]] = {}
    for r, rec in enumerate(conditions.records):
        if rec.kind == PARTICLE_LOAD and rec.n_members:
            shapes.setdefault(rec.shape_line, []).append(r)
    lines = list(shapes)
    centre = {ln: positions[:, part_ids[np.isin(part_recs, shapes[ln])]].mean(axis=1)
              for ln in lines}
    parent = list(range(len(lines)))

    def root(i):
        while parent[i] != i:
            i = parent[i]
        return i

    for i in range(len(lines)):
        for j in range(i + 1, len(lines)):
            if not _cut_by_crack(centre[lines[i]], centre[lines[j]], cracks):
                parent[root(j)] = root(i)
    groups: dict[int, list[int]] = {}
    for i, ln in enumerate(lines):
        groups.setdefault(root(i), []).append(ln)
    out = []
    for members in groups.values():
        if len(members) < 2:
            continue
        recs = np.array([r for ln in members for r in shapes[ln]], dtype=np.int64)
        out.append(LoadCouple("_".join(f"bc{ln}" for ln in members), recs,
                              [part_ids[part_recs == r] for r in recs]))
    return out


def couple_moment(couple: LoadCouple, records, rec_force: np.ndarray,
                  positions: np.ndarray) -> float:
    """Moment (N mm, counter-clockwise) of a group's loads about its centroid."""
    at = np.array([positions[:, m].mean(axis=1) for m in couple.members])
    c = at.mean(axis=0)   # the group's centre, as group_centre
    moment = 0.0
    for k, r in enumerate(couple.records):
        f = float(rec_force[r])
        if records[r].direction == 0:
            moment -= (at[k, 1] - c[1]) * f
        else:
            moment += (at[k, 0] - c[0]) * f
    return moment


def group_centre(couple: LoadCouple, positions: np.ndarray) -> np.ndarray:
    """The point a group's moment is taken about: the mean of its conditions' particle
    centroids."""
    return np.mean([positions[:, m].mean(axis=1) for m in couple.members], axis=0)


def couples_opening(a: LoadCouple, b: LoadCouple, positions: np.ndarray,
                    initial: np.ndarray) -> float:
    """How far (mm) two groups have moved apart: the change in the distance between
    their centres.  On a moment-loaded DCB (one group per arm) it is the load-line
    opening the seed paper plots the moment against (Figs 8A, 9A)."""
    now = group_centre(a, positions) - group_centre(b, positions)
    then = group_centre(a, initial) - group_centre(b, initial)
    return float(np.hypot(now[0], now[1]) - np.hypot(then[0], then[1]))


def _cut_by_crack(a: np.ndarray, b: np.ndarray, cracks) -> bool:
    if cracks is None:
        return False
    from ..cracks.crossing import line_crosses_crack
    from ..cracks.geometry import EXTERIOR_END
    cs = cracks.cracks
    px, py = np.ascontiguousarray(cs.plane[0]), np.ascontiguousarray(cs.plane[1])
    for c in range(cs.n_cracks):
        if line_crosses_crack(a[0], a[1], b[0], b[1], px, py, int(cs.first[c]),
                              int(cs.count[c]), bool(cs.tips[c, 0] == EXTERIOR_END),
                              bool(cs.tips[c, 1] == EXTERIOR_END)) != 0:
            return True
    return False
