"""The parts' induced magnetisation in the paper's field: the orientation-dependent energy of
parts of susceptibility chi and volume v, and the rows whose vanishing cancels it.

Pure functions (a physics kernel): the physical design cancels these rows
(:mod:`chargedesign.designer.assembly`) and the tolerance analysis prices material errors
with the energy (:mod:`chargedesign.tolerancing`).
"""

from __future__ import annotations

import numpy as np

from chargedesign.constants import MU_0
from chargedesign.errors import InputError


def induced_rows(legendre: tuple[float, ...], points: np.ndarray) -> np.ndarray:
    """The induced-magnetisation moments that depend on the orientation, per unit chi v.

    For ``Phi = a1 Z + a2 (3 Z^2 - R^2)`` (legendre ``[a1, 2 a2]``) a part at body position x
    sees ``|B|^2 = a1^2 + 4 a2^2 |x|^2 + 8 a1 a2 (gamma . x) + 12 a2^2 (gamma . x)^2``, so the
    parts' energy ``-sum chi v |B|^2 / (2 mu0)`` depends on gamma through ``8 a1 a2 D . gamma``
    and ``12 a2^2 gamma^T S gamma`` (``D = sum chi v x``, ``S = sum chi v x x^T``), and it is
    the same at every orientation exactly when D = 0 (if a1 a2 != 0) and S is a multiple of
    the identity (if a2 != 0: its five trace-free components vanish).

    Parameters
    ----------
    legendre : tuple of float
        The magnetic field's Legendre coefficients (T, T/m).
    points : ndarray, shape (p, 3)
        Part centres, m.

    Returns
    -------
    ndarray, shape (r, p)
        Rows ``8 a1 a2 (x1, x2, x3)`` and ``12 a2^2 (x1^2 - x2^2, x3^2 - (x1^2 + x2^2) / 2,
        x1 x2, x1 x3, x2 x3)`` (T^2 m or T^2 m^2 per unit chi v; the rows present for the
        nonzero coefficients): the weights ``chi v`` must make every row sum to zero.
    """
    coeffs = (*legendre, 0.0, 0.0)
    if any(x != 0 for x in coeffs[2:]):  # the rows above are derived for degree <= 2
        raise InputError(
            "fields.magnetic: cancelling the induced magnetisation needs a field of degree <= 2 "
            "(the paper's a1 Z + a2 (3 Z^2 - R^2)); give one ballast material"
        )
    a1, a2 = coeffs[0], coeffs[1] / 2.0
    x1, x2, x3 = points[:, 0], points[:, 1], points[:, 2]
    rows = []
    if a1 * a2 != 0:
        rows += [8 * a1 * a2 * x1, 8 * a1 * a2 * x2, 8 * a1 * a2 * x3]
    if a2 != 0:
        rows += [
            12 * a2**2 * (x1**2 - x2**2),
            12 * a2**2 * (x3**2 - (x1**2 + x2**2) / 2),
            12 * a2**2 * x1 * x2,
            12 * a2**2 * x1 * x3,
            12 * a2**2 * x2 * x3,
        ]
    return np.array(rows).reshape(len(rows), len(points))


def induced_energy(
    legendre: tuple[float, ...], points: np.ndarray, weights: np.ndarray, gammas: np.ndarray
) -> np.ndarray:
    """The orientation-dependent induced energy of parts by their moments (J), shape (m,).

    ``-(8 a1 a2 D . gamma + 12 a2^2 gamma^T S gamma) / (2 mu0)`` without its constant, from
    the rows of :func:`induced_rows` (``gamma^T S gamma = tr S / 3 + (S11 - S22) (g1^2 - g2^2)
    / 2 + (S33 - (S11 + S22) / 2) (g3^2 - 1/3) + 2 S12 g1 g2 + 2 S13 g1 g3 + 2 S23 g2 g3`` on
    the unit sphere).

    Parameters
    ----------
    legendre : tuple of float
        The magnetic field (degree <= 2), T, T/m.
    points : ndarray, shape (p, 3)
        Part centres, m.
    weights : ndarray, shape (p,)
        ``chi v`` of each part, m^3.
    gammas : ndarray, shape (m, 3)
        Unit vectors of the field axis in body axes.
    """
    coeffs = (*legendre, 0.0, 0.0)
    a1, a2 = coeffs[0], coeffs[1] / 2.0
    g = np.asarray(gammas, dtype=float)
    basis = []
    if a1 * a2 != 0:
        basis += [g[:, 0], g[:, 1], g[:, 2]]
    if a2 != 0:
        basis += [
            (g[:, 0] ** 2 - g[:, 1] ** 2) / 2,
            g[:, 2] ** 2,
            2 * g[:, 0] * g[:, 1],
            2 * g[:, 0] * g[:, 2],
            2 * g[:, 1] * g[:, 2],
        ]
    if not basis:
        return np.zeros(len(g))
    moments = induced_rows(tuple(legendre), np.asarray(points, float)) @ np.asarray(weights)
    return -(np.array(basis).T @ moments) / (2.0 * MU_0)
