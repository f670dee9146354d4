"""The Coulomb field of point charges: the one place it is written, in its four forms.

- :func:`point_charge_field`: the magnitude ``|q| / (4 pi eps0 s^2)`` of one charge;
- :func:`coulomb_field`: the direct sum over (points, charges) differences, used by the
  independent limits check (:mod:`chargedesign.physical.limits`);
- :func:`coulomb_field_gemm`: the same sum by matrix products (BLAS), about 1.5x faster but
  with cancellation in the distances, used by the design's in-loop surface check;
- :func:`coulomb_kernel`: the field per unit charge as a matrix (points x 3 x charges), the
  rows of the charges' cone programs (:mod:`chargedesign.designer.cone_program`).

Both sums are tested against each other (tests/physical/test_coulomb.py).
"""

from __future__ import annotations

import math

import numpy as np

from chargedesign.constants import COULOMB, EPSILON_0

#: elements of the matrix-product kernel's (points, charges) work arrays per block (512 kB:
#: in cache)
FIELD_BLOCK_ELEMENTS = 1 << 16
#: elements of the direct kernel's (points, charges) arrays per block (256 kB: in cache)
DIRECT_BLOCK_ELEMENTS = 1 << 15


def point_charge_field(charge: float, distance: float) -> float:
    """Field magnitude ``|q| / (4 pi eps0 s^2)`` of a point charge, V/m.

    Parameters
    ----------
    charge : float
        Charge, C.
    distance : float
        Distance, m (> 0).
    """
    return abs(charge) / (4.0 * math.pi * EPSILON_0 * distance**2)


def coulomb_field(sources: np.ndarray, charges: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Field of point charges at ``points``, V/m, shape (p, 3), by the direct sum over the
    differences ``p - x_j`` (no cancellation: exact to a few ulps).

    The (points, charges) differences, one array per component, are cut into blocks of
    about :data:`DIRECT_BLOCK_ELEMENTS` so they stay in cache (measured 3.3x faster than
    one (p, n, 3) array per 2e6 elements, at 200 carriers x 1000 samples).
    """
    out = np.empty((len(points), 3))
    sx, sy, sz = sources[:, 0], sources[:, 1], sources[:, 2]
    block = max(1, DIRECT_BLOCK_ELEMENTS // max(1, len(sources)))
    for start in range(0, len(points), block):
        p = points[start : start + block]
        dx, dy, dz = p[:, 0:1] - sx, p[:, 1:2] - sy, p[:, 2:3] - sz
        r2 = dx * dx
        r2 += dy * dy
        r2 += dz * dz
        w = np.sqrt(r2)
        w *= r2
        np.divide(charges, w, out=w)  # q_j / |p - x_j|^3
        for axis, d in enumerate((dx, dy, dz)):
            out[start : start + block, axis] = np.einsum("pn,pn->p", d, w)
    out *= COULOMB
    return out


def coulomb_field_gemm(sources: np.ndarray, charges: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Field of point charges at ``points``, V/m, shape (p, 3), by matrix products.

    ``E(p) = k (p sum_j w_j - sum_j w_j x_j)`` with ``w_j = q_j / |p - x_j|^3`` and
    ``|p - x|^2 = |p|^2 + |x|^2 - 2 p.x`` (BLAS): about 1.5x faster than
    :func:`coulomb_field`. The distances lose ``(|p| / |p - x|)^2`` ulps to cancellation: on
    random bodies the two agree to about 1e-11 (a test), far below the design's margin of
    1e-3.

    The (p, n) work arrays are cut into blocks of about :data:`FIELD_BLOCK_ELEMENTS` and
    updated in place, so they stay in cache: the elementwise passes, not the products, set
    the cost (measured 6x faster than 32 MB blocks at 250 carriers, 200 samples each).
    """
    out = np.empty((len(points), 3))
    x2 = np.einsum("nk,nk->n", sources, sources)
    block = max(1, FIELD_BLOCK_ELEMENTS // max(1, len(sources)))
    for start in range(0, len(points), block):
        p = points[start : start + block]
        r2 = np.einsum("pk,pk->p", p, p)[:, None] + x2[None, :]
        dot = p @ sources.T
        dot *= 2.0
        r2 -= dot
        w = np.sqrt(r2)
        w *= r2
        np.divide(charges[None, :], w, out=w)
        out[start : start + block] = COULOMB * (p * w.sum(axis=1)[:, None] - w @ sources)
    return out


def coulomb_kernel(sources: np.ndarray, points: np.ndarray, scale: float = COULOMB) -> np.ndarray:
    """The field at ``points`` (m, 3) of a unit charge at each of ``sources`` (k, 3), times
    ``scale`` over ``COULOMB`` (the default gives V/m per C): shape (m, 3, k). ``scale``
    takes a program's units in one product (``COULOMB * charge_unit / field_unit``)."""
    d = points[:, None, :] - sources[None, :, :]  # (m, k, 3)
    r3 = np.einsum("mkc,mkc->mk", d, d) ** 1.5
    return scale * (d / r3[:, :, None]).transpose(0, 2, 1)
