"""Grid-side crack kernels of the engine (``cracks/crack_kernels``, loaded here as
the plain template, and ``cracks/crack_lists``): chord lists per cell, the
particle-node field choice, contact."""
import numpy as np

from nairnmpm_py.cracks import crack_kernels as K
from nairnmpm_py.cracks.bundle import NR
from nairnmpm_py.cracks.crack_lists import build_crack_lists

GEOM = np.array([-1.0, -1.0, 1.0, 1.0, 12.0])   # node 0 at (-1, -1), 1 mm cells
NNX = 12
NCX = NCY = 11


class Lists:
    """The persistent arrays the scene keeps for ``crack_lists``."""

    def __init__(self):
        self.nslot = np.full((2, NNX * NNX), -1, dtype=np.int64)
        self.cstart = np.zeros((2, NCX * NCY), dtype=np.int64)
        self.cnear = np.zeros(NNX * NNX, dtype=np.uint8)
        self.cbox = np.array([0, -1, 0, -1], dtype=np.int64)

    def build(self, c):
        self.chords, self.cxy, self.cnodes = build_crack_lists(
            c["cp"], c["cfirst"], c["clast"], c["cext0"], c["cext1"], c["ccrack"], GEOM, NCX,
            NCY, NNX, self.nslot, self.cstart, self.cnear, self.cbox)
        return self


def _crack(xs, y):
    px = np.asarray(xs, dtype=float)
    return dict(cp=np.vstack([px, np.full(px.size, y)]), cfirst=np.array([0]),
                clast=np.array([px.size - 1]), cext0=np.array([False]),
                cext1=np.array([False]), ccrack=np.zeros(px.size, dtype=np.int64))


def _cell(x, y):
    return int(np.floor(y - GEOM[1])) * NCX + int(np.floor(x - GEOM[0]))


def _origin(x, y, ugimp=True):
    """A particle's first stencil node, as the shape functions find it."""
    xi, yi = x - GEOM[0], y - GEOM[1]
    if ugimp:
        return (int(np.floor(yi + 0.5)) - 1) * NNX + int(np.floor(xi + 0.5)) - 1
    return int(np.floor(yi)) * NNX + int(np.floor(xi))


def _field(c, lists, x, y, nx, ny):
    node = int(round(ny - GEOM[1])) * NNX + int(round(nx - GEOM[0]))
    f, *_ = K._pair_field(x, y, nx, ny, node, _cell(x, y), lists.cstart, lists.chords, lists.cxy,
                          c["ccrack"], lists.nslot, 2)
    return f


def test_chord_lists_cover_cells_near_the_crack_only_and_follow_it():
    c = _crack([1.2, 3.2, 5.2], 2.01)
    lists = Lists().build(c)
    per_cell = lists.cstart[1] - lists.cstart[0]
    assert per_cell[_cell(2.5, 2.5)] == 2 and per_cell[_cell(9.5, 9.5)] == 0
    # each entry carries its chord's end points
    q = lists.cstart[0, _cell(2.5, 2.5)]
    k = lists.chords[q]
    assert np.array_equal(lists.cxy[q], [c["cp"][0, k], c["cp"][1, k], c["cp"][0, k + 1], c["cp"][1, k + 1]])
    assert lists.cnear[_origin(2.5, 4.5)] == 1 and lists.cnear[_origin(9.5, 9.5)] == 0
    slotted = set(lists.cnodes.tolist())
    assert int(round(2.0 - GEOM[1])) * NNX + int(round(2.0 - GEOM[0])) in slotted
    # moved far away, the crack leaves nothing behind in its old cells and nodes
    c["cp"][1] += 6.0
    lists.build(c)
    per_cell = lists.cstart[1] - lists.cstart[0]
    assert per_cell[_cell(2.5, 2.5)] == 0 and per_cell[_cell(2.5, 8.5)] == 2
    assert lists.cnear[_origin(2.5, 2.5)] == 0
    assert np.all(lists.nslot[0, : 3 * NNX] == -1)
    assert set(lists.cnodes.tolist()) == set(np.flatnonzero(lists.nslot[0] >= 0).tolist())


def test_every_particle_that_touches_a_crack_node_is_marked_near():
    """The far path (no crossing tests) must never see a crack node: every particle
    whose stencil (uGIMP 3x3, linear 2x2 nodes) holds a slotted node has its first
    stencil node marked in ``cnear``, whichever way the crack has moved."""
    rng = np.random.default_rng(3)
    c = _crack([1.2, 3.2, 5.2], 2.01)
    lists = Lists()
    for shift in (0.0, 3.3, 1.7):
        c["cp"][1] = 2.01 + shift
        lists.build(c)
        slotted = lists.nslot[0] >= 0
        for x, y in rng.uniform(0.05, 8.95, size=(4000, 2)):
            for ugimp, na in ((True, 3), (False, 2)):
                o = _origin(x, y, ugimp)
                nodes = [o + b * NNX + a for b in range(na) for a in range(na)]
                if slotted[nodes].any():
                    assert lists.cnear[o] == 1, (x, y, ugimp)


def test_field_is_one_across_the_crack_and_zero_beside_or_beyond_the_tip():
    c = _crack([1.2, 3.2, 5.2], 2.01)
    lists = Lists().build(c)
    assert _field(c, lists, 2.5, 2.5, 2.0, 2.0) == 1      # line crosses y = 2.01
    assert _field(c, lists, 2.5, 2.5, 2.0, 3.0) == 0      # same side
    assert _field(c, lists, 5.5, 2.5, 6.0, 2.0) == 0      # beyond the tip at x = 5.2


def test_contact_stops_approach_without_changing_total_momentum():
    g = np.zeros((2, NR, 1))
    g[0, K.GM, 0], g[1, K.GM, 0] = 2.0, 1.0                  # masses: 0 above, 1 below
    g[0, K.GPY, 0], g[1, K.GPY, 0] = 2.0 * -1.0, 1.0 * 0.5   # field 0 moves down onto 1
    g[0, K.GUY, 0] = 2.0 * -0.01                             # and already overlaps it
    g[1, K.GNY, 0] = -1.0                                    # normal above -> below: -y
    g[1, K.GSD, 0] = -1.0                                    # field 1's particles: below
    gv = np.zeros((2, 2, 1))
    nslot = np.array([[0], [-1]], dtype=np.int64)
    cnodes = np.array([0], dtype=np.int64)
    total = g[0, K.GPX:K.GPY + 1, 0] + g[1, K.GPX:K.GPY + 1, 0]
    K.contact(g, gv, nslot, cnodes, 0.01, False, False, 0.0, GEOM)
    va = g[0, K.GPY, 0] / g[0, K.GM, 0]
    vb = g[1, K.GPY, 0] / g[1, K.GM, 0]
    assert np.isclose(va, vb)                                # no approach left
    assert np.allclose(g[0, K.GPX:K.GPY + 1, 0] + g[1, K.GPX:K.GPY + 1, 0], total)
    assert np.isclose(gv[0, 1, 0], va) and np.isclose(gv[1, 1, 0], vb)
    # separating fields are left alone
    g[0, K.GPY, 0], g[1, K.GPY, 0] = 2.0 * 1.0, 1.0 * -0.5
    before = g.copy()
    K.contact(g, gv, nslot, cnodes, 0.01, False, False, 0.0, GEOM)
    assert np.array_equal(g, before)


def test_no_chord_joins_two_cracks():
    c = dict(cp=np.array([[1.2, 3.2, 5.2, 1.2, 3.2], [2.01, 2.01, 2.01, 6.01, 6.01]]),
             cfirst=np.array([0, 3]), clast=np.array([2, 4]),
             cext0=np.array([False, False]), cext1=np.array([False, False]),
             ccrack=np.array([0, 0, 0, 1, 1], dtype=np.int64))
    lists = Lists().build(c)
    assert sorted(set(lists.chords.tolist())) == [0, 1, 3]
    # nodes between the two cracks have both in their slots only where both are near
    assert np.all(lists.nslot[0, lists.cnodes] >= 0)
