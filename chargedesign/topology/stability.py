"""Stability type of critical points from the eigenvalues of the linearised flow.

At a critical point ``a dH + b dI4 + beta dI2 + delta dI3 = 0`` the Hamiltonian flow of
``L = a H + b I4 + beta I2 + delta I3`` has a fixed point (its differential is a combination
of the Casimirs'), and its linearisation is ``A = Pi(x) Hess L(x)`` with ``Pi`` the Poisson
tensor (:func:`~chargedesign.topology.equations.poisson_tensor`). On a rank-one point four
eigenvalues vanish (the two Casimirs, the orbit and the family) and the last pair is
``+-lambda``: imaginary for an elliptic orbit (tori shrink onto it), real for a hyperbolic
one (two families of tori meet along its separatrices). Where ``lambda`` vanishes to the
precision of the computation the point is ``degenerate``.
"""

from __future__ import annotations

import numpy as np

from chargedesign.topology.critical import Scales
from chargedesign.topology.equations import MomentumMap

#: the types written to the diagram, in the order of the legend
TYPES = ("elliptic", "hyperbolic", "degenerate")
#: eigenvalues below this fraction of the linearisation's norm count as zero
ZERO_EIGENVALUE = 1e-5


def linearised_eigenvalues(F: MomentumMap, z: np.ndarray, scales: Scales) -> np.ndarray:
    """The six eigenvalues (1/s) of the linearised flow of ``L`` at one solution ``z`` (9,).

    ``L``'s weights are those of the critical equations (H and I4 scaled as in
    :class:`~chargedesign.topology.critical.Scales`), so the eigenvalues are in 1/s up to
    that common scale; only their kind (real or imaginary) matters for the type.
    """
    x, t, beta, delta = z[:6], z[6], z[7], z[8]
    weights = np.array([np.cos(t) / scales.energy, np.sin(t) / scales.quartic, beta, delta])
    hess = np.einsum("i,ijk->jk", weights, F.hessians(x)[0])
    return np.linalg.eigvals(F.poisson(x) @ hess)


def classify(eigenvalues: np.ndarray) -> str:
    """``elliptic``, ``hyperbolic`` or ``degenerate`` from the non-zero eigenvalues."""
    scale = np.max(np.abs(eigenvalues))
    significant = eigenvalues[np.abs(eigenvalues) > ZERO_EIGENVALUE * max(scale, 1.0)]
    if len(significant) == 0:
        return "degenerate"
    if np.all(np.abs(significant.real) < np.abs(significant.imag)):
        return "elliptic"
    return "hyperbolic"


def equilibrium_type(eigenvalues: np.ndarray) -> str:
    """The type of a rank-zero point from its four non-zero eigenvalues (Williamson):
    ``centre-centre``, ``centre-saddle``, ``saddle-saddle`` or ``focus-focus``."""
    scale = max(float(np.max(np.abs(eigenvalues))), 1e-300)
    ev = eigenvalues[np.abs(eigenvalues) > ZERO_EIGENVALUE * max(scale, 1.0)]
    imaginary = np.abs(ev.real) < ZERO_EIGENVALUE * scale
    real = np.abs(ev.imag) < ZERO_EIGENVALUE * scale
    if len(ev) < 4:
        return "degenerate"
    if np.all(imaginary):
        return "centre-centre"
    if np.all(real):
        return "saddle-saddle"
    if np.any(imaginary) and np.any(real):
        return "centre-saddle"
    return "focus-focus"


def branch_types(F: MomentumMap, z: np.ndarray, scales: Scales) -> list[str]:
    """The type of each solution of a branch, z shape (m, 9)."""
    return [classify(linearised_eigenvalues(F, zi, scales)) for zi in z]
