"""The symmetries of the charges' stage: maps of the body that carry its candidates and the
charges' conditions onto themselves.

The charges' programs (the minmax of :mod:`chargedesign.designer.frontier_probes`, the
design's surface cones in :mod:`chargedesign.designer.charges`) are convex and invariant
under such a map, so the mean of a solution over the maps is a solution as good: their optimum
is reached by charges constant (up to a sign) on every orbit of candidates, one unknown per
orbit. On the default body (257 candidates, 4 maps) the programs shrink to 67 unknowns and a
quarter of the cones (docs/benchmarks.md, "Frontier point compute").
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg as la

from chargedesign.designer.system import row_scaled

#: a map of the axes carries a candidate onto another when they agree to this fraction of the
#: body's size, and the charges' conditions onto themselves to this relative residual
SYMMETRY_TOLERANCE = 1e-9


@dataclass
class ChargeSymmetry:
    """The symmetries the charges' programs share: signed permutations of the axes ``R`` (the
    cube's 48 maps) that carry the candidates onto themselves and, with a sign ``sigma``,
    every solution of ``A u = b`` onto another (``u'[pi(j)] = sigma u[j]``, ``pi`` the
    candidates' permutation).

    The carriers are equal spheres and the external field's bound depends on the radius
    alone, so each map carries a carrier's surface field onto its image's: the minmax's
    feasible set is invariant, and the mean of any solution over the group is as good
    (``max |E|`` is convex; so is the design's ``sum |q|`` where its costs are the same on
    each orbit). Its optimum is then reached by charges constant (up to the
    signs) on each orbit of candidates: ``u = basis v`` with one unknown per orbit, and a
    cone at a point holds at every image of that point.

    Attributes
    ----------
    order : int
        The number of maps (1: none but the identity).
    maps : ndarray, shape (order, 3, 3)
        The maps ``R`` (body axes).
    signs : ndarray, shape (order,)
        Each map's ``sigma``.
    basis : ndarray, shape (k, r)
        Orthonormal columns, one per orbit whose charges may be nonzero: ``+-1 / sqrt(|O|)``
        on its candidates.
    reps : ndarray, shape (r,)
        A candidate of each orbit (the column's first).
    orbit : ndarray, shape (k,)
        Each candidate's column (-1: its charge is zero in every symmetric solution).
    """

    order: int
    maps: np.ndarray
    signs: np.ndarray
    basis: np.ndarray
    reps: np.ndarray
    orbit: np.ndarray


def _axis_maps() -> list[np.ndarray]:
    """The 48 signed permutations of the axes (the identity first)."""
    maps = []
    for perm in itertools.permutations(range(3)):
        for signs in itertools.product((1.0, -1.0), repeat=3):
            R = np.zeros((3, 3))
            R[np.arange(3), perm] = signs
            maps.append(R)
    return maps


def _coordinate_keys(points: np.ndarray, step: float) -> np.ndarray:
    """One integer per point: its coordinates in units of ``step`` (each within 2^20)."""
    ints = np.round(points / step).astype(np.int64) + (1 << 20)
    return (ints[:, 0] << 42) | (ints[:, 1] << 21) | ints[:, 2]


def _permutation(
    points: np.ndarray, order: np.ndarray, keys: np.ndarray, step: float, R: np.ndarray
) -> np.ndarray | None:
    """``pi`` with ``points[pi[j]] = R points[j]`` (None: ``R`` does not map the set onto
    itself); ``keys`` the candidates' :func:`_coordinate_keys`, sorted by ``order``."""
    image = points @ R.T
    where = np.searchsorted(keys, _coordinate_keys(image, step))
    where = np.minimum(where, len(keys) - 1)
    pi = order[where]
    if len(np.unique(pi)) != len(pi):
        return None
    if np.max(np.abs(points[pi] - image), initial=0.0) > SYMMETRY_TOLERANCE * step * 1e6:
        return None
    return pi


def charge_symmetry(A: np.ndarray, b: np.ndarray, points: np.ndarray) -> ChargeSymmetry | None:
    """The symmetries of the charges' conditions ``A u = b`` on the candidates ``points``
    (:class:`ChargeSymmetry`; None: the identity alone). The setup finds them once
    (:attr:`~chargedesign.designer.physical_setup.PhysicalSetup.symmetry`)."""
    k = len(points)
    if not np.any(b) or k == 0:
        return None
    As, bs = row_scaled(A, b, 1.0)
    # the row space of A (a map keeps the solutions' set when it keeps the row space, the
    # directions it constrains, and carries one solution onto another)
    Q, r, _ = la.qr(As.T, mode="economic", pivoting=True)
    diag = np.abs(np.diag(r))
    Q = Q[:, : int(np.sum(diag > 1e-10 * diag[0]))] if diag.size else Q
    u0 = Q @ (Q.T @ np.linalg.lstsq(As, bs, rcond=None)[0])
    scale = float(np.max(np.abs(bs)))
    # candidates are matched on a grid of a millionth of the body's size, then compared
    step = 1e-6 * max(float(np.max(np.abs(points))), 1e-300)
    keys = _coordinate_keys(points, step)
    order = np.argsort(keys)
    found: list[tuple[np.ndarray, float]] = []
    maps: list[np.ndarray] = []
    for R in _axis_maps():
        pi = _permutation(points, order, keys[order], step, R)
        if pi is None:
            continue
        # the map carries u onto u' with u'[pi] = sigma u: A u' = sigma A[:, pi] u
        moved = As[:, pi]
        rows = moved.T
        if np.max(np.abs(rows - Q @ (Q.T @ rows))) > SYMMETRY_TOLERANCE:
            continue
        for sigma in (1.0, -1.0):
            if np.max(np.abs(sigma * (moved @ u0) - bs)) <= SYMMETRY_TOLERANCE * scale:
                found.append((pi, sigma))
                maps.append(R)
                break
    if len(found) <= 1:
        return None
    orbit = np.full(k, -1)
    columns: list[np.ndarray] = []
    reps: list[int] = []
    seen = np.zeros(k, dtype=bool)
    for j in range(k):
        if seen[j]:
            continue
        signs: dict[int, float] = {}
        consistent = True
        for pi, sigma in found:
            image = int(pi[j])
            if signs.setdefault(image, sigma) != sigma:
                consistent = False
        members = np.array(sorted(signs))
        seen[members] = True
        if not consistent:
            continue  # a map fixes the orbit and flips its sign: its charges are zero
        column = np.zeros(k)
        column[members] = [signs[i] for i in members]
        column /= math.sqrt(len(members))
        orbit[members] = len(columns)
        columns.append(column)
        reps.append(j)
    return ChargeSymmetry(
        len(found),
        np.array(maps),
        np.array([sigma for _, sigma in found]),
        np.array(columns).T,
        np.array(reps),
        orbit,
    )


def one_per_orbit(near: np.ndarray, ratios: np.ndarray, orbit: np.ndarray) -> np.ndarray:
    """Of the carriers ``near``, the one with the largest ratio in each orbit (``orbit`` of
    each carrier; -1: none, kept): a cone at its worst point stands for the orbit's images
    in the symmetric programs."""
    order = near[np.argsort(-ratios[near], kind="stable")]
    _, first = np.unique(orbit[order], return_index=True)
    own = order[orbit[order] < 0]
    return np.union1d(order[first][orbit[order[first]] >= 0], own)
