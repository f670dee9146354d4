"""Chambers of the diagram: how many Liouville tori lie over a point (h, k).

The level ``F^-1(h, k)`` (on ``|gamma| = 1, I3 = 0``) is sampled on a Fibonacci grid of
gamma: over each gamma the states of energy h form a conic (the plane I3 = 0 cut by the
energy ellipsoid, :func:`~chargedesign.topology.critical.states_on_level`), and the points of
the conic where I4 = k are found by sign changes of ``I4 - k`` at ``angles`` samples (one
secant refinement). The sampled points are joined when closer than a few grid spacings
(states scaled to unit size) and the connected components are counted: each compact
regular component is one torus (Liouville-Arnold).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from chargedesign.topology.critical import plane_basis, sphere_points
from chargedesign.topology.equations import MomentumMap

#: each sampled point is joined to this many nearest others
NEIGHBOURS = 10


@dataclass(frozen=True)
class LevelSampling:
    """Resolution of the level sampling: gamma grid points and angles on each conic."""

    gammas: int = 3000
    angles: int = 64

    def doubled(self) -> LevelSampling:
        return LevelSampling(2 * self.gammas, 2 * self.angles)


class LevelSampler:
    """The conics of one energy over a fixed gamma grid (reused for many k)."""

    def __init__(self, F: MomentumMap, h: float, sampling: LevelSampling) -> None:
        self.F = F
        self.sampling = sampling
        gamma = sphere_points(sampling.gammas)
        omega0, e1, e2 = plane_basis(F, gamma)
        base = F.values(np.concatenate([omega0, gamma], axis=1))[:, 0]
        inside = base < h
        self.gamma, self.omega0 = gamma[inside], omega0[inside]
        self.e1, self.e2 = e1[inside], e2[inside]
        self.radius = np.sqrt(h - base[inside])
        self.phi = np.linspace(0.0, 2 * np.pi, sampling.angles, endpoint=False)
        self.quartic = self._quartic(np.broadcast_to(self.phi, (len(self.gamma), len(self.phi))))
        self.spacing = np.sqrt(4 * np.pi / sampling.gammas)
        self.omega_scale = max(float(np.max(np.abs(self.omega0), initial=0.0)), 1e-300) + float(
            np.max(self.radius, initial=0.0)
        )

    def _states(self, phi: np.ndarray, rows: np.ndarray | None = None) -> np.ndarray:
        """States at angles phi (m, j) on the conics of ``rows`` (default all), (m, j, 6)."""
        sel = slice(None) if rows is None else rows
        omega = self.omega0[sel][:, None, :] + self.radius[sel][:, None, None] * (
            np.cos(phi)[..., None] * self.e1[sel][:, None, :]
            + np.sin(phi)[..., None] * self.e2[sel][:, None, :]
        )
        gamma = np.broadcast_to(self.gamma[sel][:, None, :], omega.shape)
        return np.concatenate([omega, gamma], axis=2)

    def _quartic(self, phi: np.ndarray, rows: np.ndarray | None = None) -> np.ndarray:
        x = self._states(phi, rows)
        return self.F.values(x.reshape(-1, 6))[:, 1].reshape(phi.shape)

    def points(self, k: float) -> np.ndarray:
        """Sampled points of ``F^-1(h, k)``, scaled states (m, 6)."""
        g = self.quartic - k
        after = np.roll(g, -1, axis=1)
        rows, cols = np.nonzero(np.sign(g) != np.sign(after))
        if len(rows) == 0:
            return np.zeros((0, 6))
        step = self.phi[1] - self.phi[0]
        g0, g1 = g[rows, cols], after[rows, cols]
        phi = self.phi[cols] + step * g0 / (g0 - g1)
        # one secant refinement on the conic
        value = self._quartic(phi[:, None], rows)[:, 0] - k
        left = np.where(np.sign(value) == np.sign(g0), phi, self.phi[cols])
        right = np.where(np.sign(value) == np.sign(g0), self.phi[cols] + step, phi)
        gl = np.where(np.sign(value) == np.sign(g0), value, g0)
        gr = np.where(np.sign(value) == np.sign(g0), g1, value)
        phi = left + (right - left) * gl / np.where(gl != gr, gl - gr, 1.0)
        x = self._states(phi[:, None], rows)[:, 0]
        return x / np.array([self.omega_scale] * 3 + [1.0] * 3)

    def tori(self, k: float) -> int:
        """The number of connected components of the sampled level (0 when empty)."""
        from scipy.sparse.csgraph import connected_components
        from scipy.spatial import cKDTree

        pts = self.points(k)
        if len(pts) == 0:
            return 0
        from scipy.sparse import coo_matrix

        neighbours = min(NEIGHBOURS + 1, len(pts))
        _, idx = cKDTree(pts).query(pts, k=neighbours)
        rows = np.repeat(np.arange(len(pts)), neighbours)
        graph = coo_matrix((np.ones(rows.size), (rows, idx.reshape(-1))), shape=(len(pts),) * 2)
        return int(connected_components(graph, directed=False)[0])
