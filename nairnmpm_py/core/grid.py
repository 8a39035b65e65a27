"""The background grid: a regular 2D mesh with one ghost node layer all round."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

GHOST = 1  # ghost node layers beyond each edge (uGIMP reaches one node outside)


@dataclass
class Grid:
    xmin: float
    xmax: float
    ymin: float
    ymax: float
    nx: int   # cells in x
    ny: int   # cells in y
    thickness: float = 1.0
    symmetry: list = field(default_factory=list)  # (axis 0|1, position) planes

    @property
    def dx(self) -> float:
        return (self.xmax - self.xmin) / self.nx

    @property
    def dy(self) -> float:
        return (self.ymax - self.ymin) / self.ny

    @property
    def nodes_x(self) -> int:
        return self.nx + 1 + 2 * GHOST

    @property
    def nodes_y(self) -> int:
        return self.ny + 1 + 2 * GHOST

    @property
    def n_nodes(self) -> int:
        return self.nodes_x * self.nodes_y

    @property
    def n_cells(self) -> int:
        return self.nx * self.ny

    def geometry_vector(self) -> np.ndarray:
        """(x of node 0, y of node 0, dx, dy, nodes per row) for the kernels."""
        return np.array([self.xmin - GHOST * self.dx, self.ymin - GHOST * self.dy,
                         self.dx, self.dy, float(self.nodes_x)])

    def bounds(self) -> np.ndarray:
        """Region particles must stay in: the real grid; the ghost layer beyond it is
        what uGIMP reaches from its edge cells (NairnMPM's extra cell layer)."""
        return np.array([self.xmin, self.xmax, self.ymin, self.ymax])

    def node_index(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        """Flat index of real-grid node (i, j), 0 <= i <= nx."""
        return (j + GHOST) * self.nodes_x + (i + GHOST)

    def node_coordinates(self) -> tuple[np.ndarray, np.ndarray]:
        """x and y of every node (flat, ghosts included)."""
        g = self.geometry_vector()
        i = np.arange(self.nodes_x)
        j = np.arange(self.nodes_y)
        xx, yy = np.meshgrid(g[0] + i * self.dx, g[1] + j * self.dy)
        return xx.ravel(), yy.ravel()
