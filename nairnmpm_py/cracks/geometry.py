"""Explicit cracks as massless crack particles: polylines, checked for sense.

Every crack is an ordered polyline of crack particles (first -> last); "above" is the
left side walking first -> last, and its unit normal is (-t_y, t_x).  Each particle
has a plane position and two surface positions (above, below) that start equal and
later move with the velocity fields on their side; COD = above - below.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

PLAIN_END = -1
EXTERIOR_END = -2


@dataclass
class CrackSet:
    plane: np.ndarray    # (2, nc) mm
    above: np.ndarray    # (2, nc) mm
    below: np.ndarray    # (2, nc) mm
    crack: np.ndarray    # (nc,) crack index (0-based, in input order)
    law: np.ndarray      # (nc,) traction-law index into the scene's materials, -1 = none
    first: np.ndarray    # (ncracks,) index of each crack's first particle
    count: np.ndarray    # (ncracks,) particles per crack
    tips: np.ndarray     # (ncracks, 2) tip codes at first and last particle
    fixed: np.ndarray    # (ncracks,) bool: crack does not move

    @classmethod
    def from_polylines(cls, polylines: list[np.ndarray], laws: list[np.ndarray],
                       tips: list[tuple[int, int]], fixed: list[bool] | None = None) -> "CrackSet":
        pts = np.hstack([np.asarray(p, dtype=float).reshape(-1, 2).T for p in polylines])
        counts = np.array([len(p) for p in polylines], dtype=np.int64)
        first = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
        crack = np.repeat(np.arange(len(polylines)), counts)
        return cls(plane=pts.copy(), above=pts.copy(), below=pts.copy(), crack=crack,
                   law=np.concatenate([np.asarray(l, dtype=np.int64) for l in laws]),
                   first=first, count=counts, tips=np.array(tips, dtype=np.int64).reshape(-1, 2),
                   fixed=np.array(fixed if fixed is not None else [False] * len(polylines)))

    @property
    def n_cracks(self) -> int:
        return len(self.first)

    def polyline(self, c: int) -> np.ndarray:
        """(k, 2) plane points of crack c."""
        s = self.first[c]
        return self.plane[:, s:s + self.count[c]].T

    def cod(self) -> tuple[np.ndarray, np.ndarray]:
        """Normal and tangential opening (mm) at every crack particle."""
        delta = self.above - self.below
        t = np.zeros_like(self.plane)
        for c in range(self.n_cracks):
            s, n = self.first[c], self.count[c]
            p = self.plane[:, s:s + n]
            tc = np.empty_like(p)
            tc[:, 1:-1] = 0.5 * (p[:, 2:] - p[:, :-2])
            tc[:, 0] = p[:, 1] - p[:, 0]
            tc[:, -1] = p[:, -1] - p[:, -2]
            t[:, s:s + n] = tc / np.linalg.norm(tc, axis=0)
        normal = np.vstack([-t[1], t[0]])
        return np.sum(delta * normal, axis=0), np.sum(delta * t, axis=0)


def _segments_cross(p1, p2, q1, q2) -> bool:
    """Proper intersection of segments p1-p2 and q1-q2 (touching ends do not count)."""
    def orient(a, b, c):
        return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    d1, d2 = orient(q1, q2, p1), orient(q1, q2, p2)
    d3, d4 = orient(p1, p2, q1), orient(p1, p2, q2)
    return d1 * d2 < 0 and d3 * d4 < 0


def polyline_problems(points: np.ndarray, xlim: tuple[float, float],
                      ylim: tuple[float, float], cell: float) -> list[str]:
    """What is wrong with one crack's polyline, as messages (empty if fine)."""
    out = []
    pts = np.asarray(points, dtype=float)
    outside = (pts[:, 0] < xlim[0]) | (pts[:, 0] > xlim[1]) | (pts[:, 1] < ylim[0]) | (pts[:, 1] > ylim[1])
    if outside.any():
        i = int(np.argmax(outside))
        out.append(f"crack point {i + 1} ({pts[i, 0]:g}, {pts[i, 1]:g}) is outside the grid")
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    if (seg <= 1e-9 * cell).any():
        i = int(np.argmax(seg <= 1e-9 * cell))
        out.append(f"crack segment {i + 1} has zero length (points {i + 1} and {i + 2} coincide)")
        return out
    n = len(pts) - 1
    for i in range(n):
        for j in range(i + 2, n):
            if _segments_cross(pts[i], pts[i + 1], pts[j], pts[j + 1]):
                out.append(f"crack crosses itself (segments {i + 1} and {j + 1})")
                return out
    return out
