"""Moments of weighted point sets.

Moment keys name Cartesian moments by sorted axis letters: ``"xxz"`` is ``sum_j w_j x_j^2 z_j``,
``""`` the total weight. Dipole moments use ``"<component>:<letters>"``: ``"z:xy"`` is
``sum_j sigma_{j,z} x_j y_j``.

Solid-harmonic moments use real regular solid harmonics in the Racah (Schmidt
semi-normalised) convention, ``R_lm(r) = sqrt(4 pi / (2l + 1)) |r|^l Y_lm(r / |r|)`` with real
``Y_lm`` and no Condon-Shortley phase (``R_11 = x``, ``R_1,-1 = y``, ``R_10 = z``), so that the
addition theorem reads ``sum_m R_lm(a) R_lm(b) = |a|^l |b|^l P_l(a_hat . b_hat)``. Columns are
ordered ``l*l + l + m`` for ``m = -l .. l``. See docs/fields-and-moments.md.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from chargedesign.validation import (
    MOMENT_AXES,
    as_array,
    as_points,
    as_weights,
    input_error,
    parse_moment_key,
)


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


#: Largest order accepted by :func:`cartesian_moment_tensor` (3**order entries).
MAX_TENSOR_ORDER = 8


def _points_and_weights(
    points: Any, weights: Any, weights_name: str = "weights"
) -> tuple[np.ndarray, np.ndarray]:
    pts = as_points(points, "points")
    if isinstance(weights, (list, tuple)) and len(weights) == 0:
        weights = np.zeros(0)
    w = as_weights(weights, weights_name, n=len(pts))
    return pts, w


def cartesian_moment_tensor(points: Any, weights: Any, order: int) -> np.ndarray:
    """The symmetric Cartesian moment tensor ``T_{a b ...} = sum_j w_j x_{j,a} x_{j,b} ...``.

    Parameters
    ----------
    points : ndarray, shape (n, 3)
        Positions in m.
    weights : ndarray, shape (n,)
        Weights (charges in C, masses in kg, ...).
    order : int
        Tensor order, 0 .. 8.

    Returns
    -------
    ndarray, shape (3,) * order
        Symmetric under any permutation of its indices; order 0 gives a 0-d array (the total
        weight). Units: weight unit times m^order.
    """
    pts, w = _points_and_weights(points, weights)
    k = as_order(order, "order", MAX_TENSOR_ORDER)
    # Build sum_j w_j x_j (x) x_j (x) ... as one (n, 3, ..., 3) product, then sum over j.
    prod = w.copy()
    for _ in range(k):
        prod = prod[..., None] * pts.reshape((len(pts),) + (1,) * (prod.ndim - 1) + (3,))
    return np.asarray(prod.sum(axis=0))


def cartesian_moments(points: Any, weights: Any, order: int) -> dict[str, float]:
    """All Cartesian moments of one order, keyed by sorted axis letters (:func:`moment_keys`).

    Parameters
    ----------
    points : ndarray, shape (n, 3)
        Positions in m.
    weights : ndarray, shape (n,)
        Weights.
    order : int
        Moment order (>= 0).

    Returns
    -------
    dict[str, float]
        ``{"xx": sum w x^2, "xy": sum w x y, ...}`` for ``order = 2``; ``{"": sum w}`` for 0.
    """
    pts, w = _points_and_weights(points, weights)
    keys = moment_keys(as_order(order, "order"))
    values = monomial_matrix(pts, keys) @ w
    return {key: float(v) for key, v in zip(keys, values, strict=True)}


def dipole_moments(points: Any, moments: Any, order: int) -> dict[str, float]:
    """Moments of a dipole distribution: ``"c:letters" -> sum_j sigma_{j,c} * monomial_j``.

    Parameters
    ----------
    points : ndarray, shape (n, 3)
        Dipole positions in m.
    moments : ndarray, shape (n, 3)
        Dipole moments sigma (body axes), A m^2.
    order : int
        Order of the position monomial (>= 0).

    Returns
    -------
    dict[str, float]
        Keys ``"x:<letters>"``, ``"y:<letters>"``, ``"z:<letters>"`` for every key of
        :func:`moment_keys` (``order``): ``"z:xy"`` is ``sum_j sigma_{j,z} x_j y_j``.
    """
    pts = as_points(points, "points")
    if isinstance(moments, (list, tuple)) and len(moments) == 0:
        moments = np.zeros((0, 3))
    sig = as_array(moments, "moments", (len(pts), 3))
    keys = moment_keys(as_order(order, "order"))
    values = monomial_matrix(pts, keys) @ sig  # (len(keys), 3)
    return {
        f"{axis}:{key}": float(values[a, c])
        for c, axis in enumerate(MOMENT_AXES)
        for a, key in enumerate(keys)
    }


def solid_harmonic_index(l: int, m: int) -> int:
    """Column of ``R_lm`` in :func:`solid_harmonics`: ``l*l + l + m`` (``-l <= m <= l``)."""
    if not -l <= m <= l:
        raise ValueError(f"m: expected an integer in -{l}..{l}, got {m}")
    return l * l + l + m


def solid_harmonics(points: Any, lmax: int) -> np.ndarray:
    """Real regular solid harmonics ``R_lm`` (Racah normalisation) at each point.

    Parameters
    ----------
    points : ndarray, shape (n, 3)
        Positions in m.
    lmax : int
        Highest degree (>= 0).

    Returns
    -------
    ndarray, shape (n, (lmax + 1)**2)
        ``out[j, l*l + l + m] = R_lm(points[j])`` (units m^l); polynomials in x, y, z,
        regular at the origin. ``R_00 = 1``; ``R_1,(-1, 0, 1) = (y, z, x)``;
        ``R_20 = z^2 - (x^2 + y^2) / 2``, ``R_22 = sqrt(3) (x^2 - y^2) / 2``,
        ``R_2,-2 = sqrt(3) x y``, ``R_21 = sqrt(3) x z``, ``R_2,-1 = sqrt(3) y z``.

    Notes
    -----
    With ``R_l^m = C_l^m + i S_l^m`` the complex Racah harmonic without Condon-Shortley phase
    (``m >= 0``), ``R_lm = sqrt(2) C_l^m`` and ``R_l,-m = sqrt(2) S_l^m`` for ``m > 0`` and
    ``R_l0 = C_l^0``. The recurrences, exact and polynomial:

    - ``R_m^m = sqrt((2m - 1) / (2m)) (x + i y) R_{m-1}^{m-1}``,
    - ``R_{l+1}^m = ((2l + 1) z R_l^m - sqrt(l^2 - m^2) r^2 R_{l-1}^m) / sqrt((l+1)^2 - m^2)``.
    """
    pts = as_points(points, "points")
    L = as_order(lmax, "lmax")
    n = len(pts)
    x, y, z = pts[:, 0], pts[:, 1], pts[:, 2]
    r2 = np.einsum("ij,ij->i", pts, pts)
    out = np.empty((n, (L + 1) ** 2))
    # Diagonal (C_m^m, S_m^m) by the sectoral recurrence, then up the column in l.
    cm, sm = np.ones(n), np.zeros(n)
    for m in range(L + 1):
        if m > 0:
            f = np.sqrt((2 * m - 1) / (2 * m))
            cm, sm = f * (x * cm - y * sm), f * (x * sm + y * cm)
        _harmonic_column(out, m, L, z, r2, cm, sm)
    return out


def _harmonic_column(
    out: np.ndarray, m: int, L: int, z: np.ndarray, r2: np.ndarray, cm: np.ndarray, sm: np.ndarray
) -> None:
    """Fill the column of order ``m`` (degrees m..L) of ``out`` from ``(C_m^m, S_m^m)`` by the
    recurrence in l."""
    n = len(z)
    root2 = np.sqrt(2.0)
    c_prev, s_prev = np.zeros(n), np.zeros(n)
    c_cur, s_cur = cm, sm
    for l in range(m, L + 1):
        if m == 0:
            out[:, l * l + l] = c_cur
        else:
            out[:, l * l + l + m] = root2 * c_cur
            out[:, l * l + l - m] = root2 * s_cur
        if l == L:
            break
        a = (2 * l + 1) / np.sqrt((l + 1) ** 2 - m * m)
        b = np.sqrt(l * l - m * m) / np.sqrt((l + 1) ** 2 - m * m)
        c_next = a * z * c_cur - b * r2 * c_prev
        s_next = a * z * s_cur - b * r2 * s_prev
        c_prev, s_prev, c_cur, s_cur = c_cur, s_cur, c_next, s_next


def multipole_moments(points: Any, weights: Any, lmax: int) -> np.ndarray:
    """Solid-harmonic moments ``Q_lm = sum_j w_j R_lm(r_j)``.

    Parameters
    ----------
    points : ndarray, shape (n, 3)
        Positions in m.
    weights : ndarray, shape (n,)
        Weights.
    lmax : int
        Highest degree (>= 0).

    Returns
    -------
    ndarray, shape ((lmax + 1)**2,)
        Index ``l*l + l + m``. By the addition theorem, for a unit vector gamma,
        ``sum_j w_j |r_j|^l P_l(r_hat_j . gamma) = sum_m Q_lm R_lm(gamma)``.
    """
    pts, w = _points_and_weights(points, weights)
    return solid_harmonics(pts, lmax).T @ w


def as_order(value: Any, name: str, top: int | None = None) -> int:
    """A non-negative int (bools rejected), at most ``top`` when given."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise input_error(name, "a non-negative integer", value)
    out = int(value)
    if out < 0 or (top is not None and out > top):
        bound = f"an integer in 0..{top}" if top is not None else "a non-negative integer"
        raise input_error(name, bound, value)
    return out
