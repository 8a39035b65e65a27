"""Does the line from a particle to a node cross a crack?  (CRAMP crossing test.)

This decides which velocity field of a node a particle goes to: field 0 if the
particle and node are on the same side of every crack, or the "across" field of a
crack if the straight particle-to-node line crosses it (CRAMP.md section 2.1).

Conventions (same as ``cracks.geometry``): a crack is a polyline of crack particles
walked first -> last; "above" is the left side of that walk.  The crossing test
uses the crack *plane* positions.

``T(a, b, c)`` is twice the signed area of triangle abc: positive when c lies left
of a -> b.  For a chord s3 -> s4 of the crack and the particle p / node n line:

* the chord must straddle the p-n line: ``A1 = T(p, n, s3)`` and ``A2 = T(p, n, s4)``
  of opposite signs, where a vertex exactly *on* the line counts as being on the
  positive side (``A >= 0``).  This is the usual symbolic-perturbation rule; it
  differs from NairnMPM only where a crack vertex lies exactly on the p-n line;
* p must be strictly on one side of the chord and n on the other side *or on the
  chord line*: a node on the crack counts as crossed, a particle on it does not;
* the particle's side names the result: +1 = ABOVE, -1 = BELOW.

Each hit toggles the result (an even number of hits is no crossing; with an odd
number the last hit's side is returned), as in NairnMPM.

Fix of the NairnMPM double count (CRAMP.md section 5): NairnMPM accepts
``A1 = 0, A2 > 0`` as well as ``A1 < 0, A2 = 0`` for ABOVE, so a p-n line passing
exactly through an interior crack particle is hit by *both* chords that share it
and the toggle cancels a real crossing.  Because the shared vertex's ``A`` is the
same floating-point number for both chords, the ``A >= 0`` rule gives it to exactly
one of them for a real crossing, and to none or both (-> no crossing) when the line
only touches the polyline at that vertex.

Exterior crack ends (tip code -2, ``geometry.EXTERIOR_END``) are extended by 4x
their end chord, so lines passing just beyond an end that lies on the edge of the
body still see the crack.
"""
from __future__ import annotations

import numpy as np
from numba import njit

NO_CROSS = 0
ABOVE = 1
BELOW = -1


@njit(cache=True, inline="always")
def tri(ax, ay, bx, by, cx, cy):
    """Twice the signed area of triangle abc (> 0 when c is left of a -> b)."""
    return ax * (by - cy) + bx * (cy - ay) + cx * (ay - by)


@njit(cache=True, inline="always")
def segment_crossing_side(px, py, nx, ny, x3, y3, x4, y4):
    """Crossing of the particle (p) -> node (n) line with one crack chord s3 -> s4.

    Returns +1 (particle ABOVE = left of s3 -> s4, line crosses), -1 (BELOW) or 0.
    """
    # cheap rejection on bounding boxes (closed, so touching cases are kept)
    if max(px, nx) < min(x3, x4) or min(px, nx) > max(x3, x4):
        return 0
    if max(py, ny) < min(y3, y4) or min(py, ny) > max(y3, y4):
        return 0
    a1 = tri(px, py, nx, ny, x3, y3)
    a2 = tri(px, py, nx, ny, x4, y4)
    if a1 < 0.0 and a2 >= 0.0:
        if tri(x3, y3, x4, y4, px, py) > 0.0 and tri(x3, y3, x4, y4, nx, ny) <= 0.0:
            return ABOVE
    elif a1 >= 0.0 and a2 < 0.0:
        if tri(x3, y3, x4, y4, px, py) < 0.0 and tri(x3, y3, x4, y4, nx, ny) >= 0.0:
            return BELOW
    return 0


@njit(cache=True, inline="always")
def extended_chord(x3, y3, x4, y4, extend_start, extend_end):
    """A chord's end points, an exterior crack end pushed out by four chord lengths so
    that lines to nodes near the edge of the body still cross it."""
    ex = x4 - x3
    ey = y4 - y3
    if extend_start:
        x3 -= 4.0 * ex
        y3 -= 4.0 * ey
    if extend_end:
        x4 += 4.0 * ex
        y4 += 4.0 * ey
    return x3, y3, x4, y4


@njit(cache=True)
def line_crosses_crack(px, py, nx, ny, seg_x, seg_y, first, count, ext_start, ext_end):
    """Which side of one crack the particle is on, if the p -> n line crosses it.

    px, py: particle position; nx, ny: node position (mm).
    seg_x, seg_y: plane x and y of all crack particles (e.g. ``CrackSet.plane[0]``,
    ``CrackSet.plane[1]``); this crack is particles ``first .. first + count - 1``.
    ext_start, ext_end: True when that end is an exterior end (tip code -2); it is
    then extended by 4 times its end chord.

    Returns +1 (particle ABOVE the crack and the line crosses it an odd number of
    times), -1 (BELOW, likewise) or 0 (no crossing, or an even number).
    """
    side = 0
    last = first + count - 1
    for k in range(first, last):
        x3, y3, x4, y4 = extended_chord(seg_x[k], seg_y[k], seg_x[k + 1], seg_y[k + 1],
                                        k == first and ext_start, k == last - 1 and ext_end)
        hit = segment_crossing_side(px, py, nx, ny, x3, y3, x4, y4)
        if hit != 0:
            side = hit if side == 0 else 0
    return side


@njit(cache=True)
def segment_intersection(ax, ay, bx, by, cx, cy, dx, dy):
    """Intersection of segments a-b and c-d.

    Returns (hit, t, u): the lines meet at a + t(b - a) = c + u(d - c); ``hit`` is
    True when both 0 <= t <= 1 and 0 <= u <= 1 (closed ranges: callers that need
    half-open ranges test t and u themselves).  Parallel segments (including
    collinear overlapping ones) return (False, nan, nan); callers that must not
    miss a collinear overlap should test for it separately.
    """
    rx = bx - ax
    ry = by - ay
    sx = dx - cx
    sy = dy - cy
    den = rx * sy - ry * sx
    if den == 0.0:
        return False, np.nan, np.nan
    qx = cx - ax
    qy = cy - ay
    t = (qx * sy - qy * sx) / den
    u = (qx * ry - qy * rx) / den
    return (0.0 <= t <= 1.0) and (0.0 <= u <= 1.0), t, u


@njit(cache=True)
def collinear_overlap(ax, ay, bx, by, cx, cy, dx, dy, tol):
    """True if segment c-d lies along segment a-b (within ``tol`` mm) and overlaps it."""
    lab = ((bx - ax) ** 2 + (by - ay) ** 2) ** 0.5
    if lab == 0.0:
        return False
    # distances of c and d from the line a-b
    dc = abs(tri(ax, ay, bx, by, cx, cy)) / lab
    dd = abs(tri(ax, ay, bx, by, dx, dy)) / lab
    if dc > tol or dd > tol:
        return False
    tc = ((cx - ax) * (bx - ax) + (cy - ay) * (by - ay)) / (lab * lab)
    td = ((dx - ax) * (bx - ax) + (dy - ay) * (by - ay)) / (lab * lab)
    return max(tc, td) >= 0.0 and min(tc, td) <= 1.0
