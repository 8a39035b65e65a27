"""Grid-side crack kernels: chord lists per cell, particle-node fields, contact."""
import numpy as np

from nairnmpm_py.cracks import fields

GEOM = np.array([-1.0, -1.0, 1.0, 1.0, 12.0])   # node 0 at (-1, -1), 1 mm cells
NCX = NCY = 11


def _crack(xs, y):
    px = np.asarray(xs, dtype=float)
    py = np.full(px.size, y)
    return dict(px=px, py=py, first_of=np.array([0]), last_of=np.array([px.size - 1]),
                ext_start=np.array([False]), ext_end=np.array([False]),
                crack_of=np.zeros(px.size, dtype=np.int64))


def _field(c, x, y, nx, ny):
    st, ch = fields.cell_segments(c["px"], c["py"], c["first_of"], c["last_of"],
                                  c["ext_start"], c["ext_end"], c["crack_of"], GEOM, NCX, NCY)
    cell = int(np.floor(y - GEOM[1])) * NCX + int(np.floor(x - GEOM[0]))
    return fields.particle_node_field(x, y, nx, ny, cell, st, ch, c["px"], c["py"],
                                      c["first_of"], c["last_of"], c["ext_start"],
                                      c["ext_end"], c["crack_of"])


def test_chord_lists_cover_cells_near_the_crack_only():
    c = _crack([1.2, 3.2, 5.2], 2.01)
    st, ch = fields.cell_segments(c["px"], c["py"], c["first_of"], c["last_of"],
                                  c["ext_start"], c["ext_end"], c["crack_of"], GEOM, NCX, NCY)
    per_cell = np.diff(st)
    near = (3 + 1) * NCX + (2 + 1)      # cell holding (2.5, 3.5)
    far = (9 + 1) * NCX + (9 + 1)       # cell holding (9.5, 9.5)
    assert per_cell[near] == 2 and per_cell[far] == 0


def test_field_is_one_across_the_crack_and_zero_beside_or_beyond_the_tip():
    c = _crack([1.2, 3.2, 5.2], 2.01)
    assert _field(c, 2.5, 2.5, 2.0, 2.0) == 1      # line crosses y = 2.01
    assert _field(c, 2.5, 2.5, 2.0, 3.0) == 0      # same side
    assert _field(c, 6.5, 2.5, 6.0, 2.0) == 0      # beyond the tip at x = 5.2


def test_contact_stops_approach_without_changing_total_momentum():
    g = np.zeros((2, 5, 1))
    g[0, 0, 0], g[1, 0, 0] = 2.0, 1.0                 # masses
    g[0, 2, 0], g[1, 2, 0] = 2.0 * -1.0, 1.0 * 0.5    # field 0 moves down onto field 1
    gu = np.zeros((2, 2, 1))
    normal = np.array([[0.0], [-1.0]])                # above -> below is -y
    above = np.array([0], dtype=np.int64)             # field 0 is the above side
    total = g[0, 1:3, 0] + g[1, 1:3, 0]
    fields.contact(g, gu, normal, above, 0.01, False, 0.0, 1.0)
    va = g[0, 2, 0] / g[0, 0, 0]
    vb = g[1, 2, 0] / g[1, 0, 0]
    assert np.isclose(va, vb)                         # normal velocities equal: no approach
    assert np.allclose(g[0, 1:3, 0] + g[1, 1:3, 0], total)
    # separating fields are left alone
    g[0, 2, 0], g[1, 2, 0] = 2.0 * 1.0, 1.0 * -0.5
    before = g.copy()
    fields.contact(g, gu, normal, above, 0.01, False, 0.0, 1.0)
    assert np.array_equal(g, before)
