"""Crack work on the grid, as Numba kernels the step calls when a scene has cracks.

* ``cell_segments``: which crack chords lie near each cell (rebuilt after the cracks
  move), so a particle tests only the few chords that can cut its node lines;
* ``particle_node_field``: the velocity field (0 = same side as the node, 1 = across
  one crack) a particle uses at one node (the CRAMP crossing test);
* ``contact``: frictionless contact between the two fields of a node;
* ``move_surfaces``: crack surfaces moved with the field on their side, the plane
  with the mean of the two.

One crack per node is supported (two fields); a node whose lines cross two cracks
puts the particle in field 0 and is counted in ``conflicts``.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .crossing import segment_crossing_side, tri

# a chord that cuts a particle-node line lies within the cells next to the particle's
# cell (uGIMP nodes are at most 1.5 cells away) and within the cells next to the
# node's four cells, so one cell of padding finds every chord that can matter
SEARCH_PAD_CELLS = 1


@njit(cache=True, inline="always")
def _chord(k, px, py, first_of, last_of, ext_start, ext_end, crack_of):
    """End points of chord k (particles k, k+1), exterior ends extended 4x."""
    c = crack_of[k]
    x3 = px[k]
    y3 = py[k]
    x4 = px[k + 1]
    y4 = py[k + 1]
    ex = x4 - x3
    ey = y4 - y3
    if k == first_of[c] and ext_start[c]:
        x3 -= 4.0 * ex
        y3 -= 4.0 * ey
    if k + 1 == last_of[c] and ext_end[c]:
        x4 += 4.0 * ex
        y4 += 4.0 * ey
    return x3, y3, x4, y4


@njit(cache=True, inline="always")
def _chord_cells(k, px, py, first_of, last_of, ext_start, ext_end, crack_of, geom, ncx, ncy):
    """Range of cells (i0, i1, j0, j1) a particle near chord k may sit in."""
    x3, y3, x4, y4 = _chord(k, px, py, first_of, last_of, ext_start, ext_end, crack_of)
    i0 = max(int(math.floor((min(x3, x4) - geom[0]) / geom[2])) - SEARCH_PAD_CELLS, 0)
    i1 = min(int(math.floor((max(x3, x4) - geom[0]) / geom[2])) + SEARCH_PAD_CELLS, ncx - 1)
    j0 = max(int(math.floor((min(y3, y4) - geom[1]) / geom[3])) - SEARCH_PAD_CELLS, 0)
    j1 = min(int(math.floor((max(y3, y4) - geom[1]) / geom[3])) + SEARCH_PAD_CELLS, ncy - 1)
    return i0, i1, j0, j1


@njit(cache=True)
def cell_segments(px, py, first_of, last_of, ext_start, ext_end, crack_of, geom, ncx, ncy):
    """CSR lists of the chords near each cell (cells of the ghost-inclusive grid).

    Returns (start (ncx*ncy + 1), chords): chord k joins crack particles k and k+1.
    """
    start = np.zeros(ncx * ncy + 1, dtype=np.int64)
    n = px.size
    for k in range(n - 1):
        if crack_of[k] != crack_of[k + 1]:
            continue
        i0, i1, j0, j1 = _chord_cells(k, px, py, first_of, last_of, ext_start, ext_end,
                                      crack_of, geom, ncx, ncy)
        for j in range(j0, j1 + 1):
            for i in range(i0, i1 + 1):
                start[j * ncx + i + 1] += 1
    for i in range(ncx * ncy):
        start[i + 1] += start[i]
    chords = np.empty(start[ncx * ncy], dtype=np.int64)
    fill = start[:-1].copy()
    for k in range(n - 1):
        if crack_of[k] != crack_of[k + 1]:
            continue
        i0, i1, j0, j1 = _chord_cells(k, px, py, first_of, last_of, ext_start, ext_end,
                                      crack_of, geom, ncx, ncy)
        for j in range(j0, j1 + 1):
            for i in range(i0, i1 + 1):
                cell = j * ncx + i
                chords[fill[cell]] = k
                fill[cell] += 1
    return start, chords


@njit(cache=True, inline="always")
def particle_node_field(x, y, nx, ny, cell, cstart, chords, px, py, first_of, last_of,
                        ext_start, ext_end, crack_of):
    """0 if no crack cuts the particle -> node line, 1 if one crack does (an odd
    number of its chords), -1 if two different cracks do (unsupported: field 0)."""
    crossed = -1
    parity = 0
    other = False
    for q in range(cstart[cell], cstart[cell + 1]):
        k = chords[q]
        x3, y3, x4, y4 = _chord(k, px, py, first_of, last_of, ext_start, ext_end, crack_of)
        if segment_crossing_side(x, y, nx, ny, x3, y3, x4, y4) != 0:
            c = crack_of[k]
            if crossed < 0 or crossed == c:
                crossed = c
                parity ^= 1
            else:
                other = True
    if other:
        return -1
    return parity


@njit(cache=True)
def node_normals(gm, node_x, node_y, geom, ncx, cstart, chords, px, py, first_of, last_of,
                 ext_start, ext_end, crack_of, normal, above_field):
    """For nodes holding mass in both fields: the unit normal of the nearest chord
    (pointing from the above side to the below side) and which field is above."""
    nn = gm.shape[1]
    dx = geom[2]
    dy = geom[3]
    for k in range(nn):
        above_field[k] = -1
        if gm[0, k] <= 0.0 or gm[1, k] <= 0.0:
            continue
        ci = int(math.floor((node_x[k] - geom[0]) / dx + 1e-9))
        cj = int(math.floor((node_y[k] - geom[1]) / dy + 1e-9))
        ci = min(max(ci, 0), ncx - 1)
        cell = cj * ncx + ci
        best = 1e300
        bx = 0.0
        by = 0.0
        side = 0.0
        for q in range(cstart[cell], cstart[cell + 1]):
            c = chords[q]
            x3, y3, x4, y4 = _chord(c, px, py, first_of, last_of, ext_start, ext_end, crack_of)
            ex = x4 - x3
            ey = y4 - y3
            L2 = ex * ex + ey * ey
            t = ((node_x[k] - x3) * ex + (node_y[k] - y3) * ey) / L2
            t = min(max(t, 0.0), 1.0)
            qx = x3 + t * ex - node_x[k]
            qy = y3 + t * ey - node_y[k]
            d = qx * qx + qy * qy
            if d < best:
                best = d
                L = math.sqrt(L2)
                bx = ey / L        # (dy, -dx)/L points to the below (right) side
                by = -ex / L
                side = tri(x3, y3, x4, y4, node_x[k], node_y[k])
        if best < 1e300:
            normal[0, k] = bx
            normal[1, k] = by
            # field 0 holds the particles on the node's own side
            above_field[k] = 0 if side > 0.0 else 1


@njit(cache=True)
def contact(g, gu, normal, above_field, dt, with_forces, position_cutoff, cell):
    """Frictionless contact between the two fields of each two-field node.

    ``g`` is (field, component, node) with components m, px, py, fx, fy; ``gu`` the
    mass-weighted displacement (or position) sums per field.  In contact when the
    fields approach and their separation, predicted over the step, is negative.
    With ``with_forces`` (after the momentum update) the forces change too, so
    accelerations stay consistent with the corrected momenta.
    """
    nn = g.shape[2]
    for k in range(nn):
        fa = above_field[k]
        if fa < 0:
            continue
        fb = 1 - fa
        ma = g[fa, 0, k]
        mb = g[fb, 0, k]
        if ma <= 0.0 or mb <= 0.0:
            continue
        nxk = normal[0, k]
        nyk = normal[1, k]
        msum = ma + mb
        dpx = (ma * g[fb, 1, k] - mb * g[fa, 1, k]) / msum
        dpy = (ma * g[fb, 2, k] - mb * g[fa, 2, k]) / msum
        dpn = dpx * nxk + dpy * nyk
        if dpn >= 0.0:
            continue  # separating
        sep = ((gu[fb, 0, k] / mb - gu[fa, 0, k] / ma) * nxk
               + (gu[fb, 1, k] / mb - gu[fa, 1, k] / ma) * nyk)
        if position_cutoff > 0.0:
            sep -= position_cutoff * cell
        mred = ma * mb / msum
        if sep + dt * dpn / mred >= 0.0:
            continue  # will not touch within this step
        cx = dpn * nxk
        cy = dpn * nyk
        g[fa, 1, k] += cx
        g[fa, 2, k] += cy
        g[fb, 1, k] -= cx
        g[fb, 2, k] -= cy
        if with_forces:
            g[fa, 3, k] += cx / dt
            g[fa, 4, k] += cy / dt
            g[fb, 3, k] -= cx / dt
            g[fb, 4, k] -= cy / dt


NUDGE_CELLS = 1e-4  # a surface on the plane is tested from just off it, on its own side


@njit(cache=True)
def move_surfaces(above, below, plane, first_of, last_of, fixed, crack_of, ext_start,
                  ext_end, g, ga, gvn, geom, ncx, cstart, chords, dt):
    """Move each crack surface with the field on its side (classic shape functions,
    mass-weighted, the mean of the old and new grid velocities as particles move),
    and the plane with the mean of the two surface moves.

    Returns the number of surface points that found no field on either side.
    """
    nnx = int(geom[4])
    dx = geom[2]
    dy = geom[3]
    lost = 0
    n = plane.shape[1]
    moves = np.zeros((2, 2))
    for k in range(n):
        c = crack_of[k]
        if fixed[c]:
            continue
        # tangent from the neighbouring plane points, normal to the above side
        kp = k - 1 if k > first_of[c] else k
        kn = k + 1 if k < last_of[c] else k
        tx = plane[0, kn] - plane[0, kp]
        ty = plane[1, kn] - plane[1, kp]
        tl = math.sqrt(tx * tx + ty * ty)
        ux = -ty / tl
        uy = tx / tl
        found = np.zeros(2, dtype=np.bool_)
        for side in range(2):
            sx = above[0, k] if side == 0 else below[0, k]
            sy = above[1, k] if side == 0 else below[1, k]
            sgn = 1.0 if side == 0 else -1.0
            tx_ = sx + sgn * NUDGE_CELLS * dx * ux
            ty_ = sy + sgn * NUDGE_CELLS * dy * uy
            xi = (sx - geom[0]) / dx
            eta = (sy - geom[1]) / dy
            i0 = int(math.floor(xi))
            j0 = int(math.floor(eta))
            rx = xi - i0
            ry = eta - j0
            cell = j0 * ncx + i0
            msum = 0.0
            vnx = 0.0
            vny = 0.0
            vox = 0.0
            voy = 0.0
            for b in range(2):
                for a in range(2):
                    s = (rx if a == 1 else 1.0 - rx) * (ry if b == 1 else 1.0 - ry)
                    if s <= 0.0:
                        continue
                    node = (j0 + b) * nnx + i0 + a
                    nxp = geom[0] + (i0 + a) * dx
                    nyp = geom[1] + (j0 + b) * dy
                    f = particle_node_field(tx_, ty_, nxp, nyp, cell, cstart, chords,
                                            plane[0], plane[1], first_of, last_of,
                                            ext_start, ext_end, crack_of)
                    if f < 0:
                        continue
                    m = g[f, 0, node]
                    if m <= 0.0:
                        continue
                    w = s * m
                    msum += w
                    vnx += w * gvn[f, 0, node]
                    vny += w * gvn[f, 1, node]
                    vox += w * (gvn[f, 0, node] - ga[f, 0, node] * dt)
                    voy += w * (gvn[f, 1, node] - ga[f, 1, node] * dt)
            if msum > 0.0:
                found[side] = True
                moves[side, 0] = 0.5 * (vnx + vox) / msum * dt
                moves[side, 1] = 0.5 * (vny + voy) / msum * dt
        if not found[0] and not found[1]:
            lost += 1
            continue
        if not found[0]:
            moves[0, 0] = moves[1, 0]
            moves[0, 1] = moves[1, 1]
        if not found[1]:
            moves[1, 0] = moves[0, 0]
            moves[1, 1] = moves[0, 1]
        above[0, k] += moves[0, 0]
        above[1, k] += moves[0, 1]
        below[0, k] += moves[1, 0]
        below[1, k] += moves[1, 1]
        plane[0, k] += 0.5 * (moves[0, 0] + moves[1, 0])
        plane[1, k] += 0.5 * (moves[0, 1] + moves[1, 1])
    return lost
