"""Moments of weighted point sets: the keys and the monomials.

Moment keys name Cartesian moments by sorted axis letters: ``"xxz"`` is ``sum_j w_j x_j^2 z_j``,
``""`` the total weight; ``monomial_matrix(points, keys) @ weights`` are the moments. The
conditions engine's solid harmonics are exact (:mod:`chargedesign.moment_conditions.harmonics`).
See docs/fields-and-moments.md.
"""

from __future__ import annotations

import numpy as np

from chargedesign.validation import as_points, parse_moment_key


def moment_key(exponents: tuple[int, int, int]) -> str:
    """``(2, 0, 1) -> "xxz"``."""
    i, j, k = exponents
    return "x" * i + "y" * j + "z" * k


def moment_keys(order: int) -> list[str]:
    """All keys of one order, in lexicographic order (``order=2``: xx, xy, xz, yy, yz, zz)."""
    keys = []
    for i in range(order, -1, -1):
        for j in range(order - i, -1, -1):
            keys.append(moment_key((i, j, order - i - j)))
    return keys


def monomial_matrix(points: np.ndarray, keys: list[str]) -> np.ndarray:
    """Monomials of each key at each point.

    Parameters
    ----------
    points : ndarray, shape (n, 3)
        Positions in m.
    keys : list of str
        Moment keys (sorted axis letters).

    Returns
    -------
    ndarray, shape (len(keys), n)
        ``out[a, j] = x_j^i y_j^k z_j^l`` for ``keys[a]`` with exponents (i, k, l), so that
        ``out @ weights`` are the moments.
    """
    pts = as_points(points, "points")
    exps = [parse_moment_key(k) for k in keys]
    top = max((max(e) for e in exps), default=0)
    powers = np.ones((top + 1, len(pts), 3))
    for e in range(1, top + 1):
        powers[e] = powers[e - 1] * pts
    out = np.empty((len(keys), len(pts)))
    for a, (i, j, k) in enumerate(exps):
        out[a] = powers[i, :, 0] * powers[j, :, 1] * powers[k, :, 2]
    return out
