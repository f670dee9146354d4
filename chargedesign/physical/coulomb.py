"""The Coulomb field of point charges: the one place it is written, in its forms.

- :func:`point_charge_field`: the magnitude ``|q| / (4 pi eps0 s^2)`` of one charge;
- :func:`coulomb_field`: the direct sum over (points, charges) differences, the reference
  the others are tested against;
- :func:`coulomb_field_gemm`: the same sum by matrix products (BLAS), with cancellation in
  the distances, used by the independent limits check (:mod:`chargedesign.physical.limits`:
  a code path of its own, not the design's);
- :func:`sphere_fields`: the field on carriers' spheres, summed in each carrier's own
  coordinates (its own charge exact), used by the design's in-loop surface check;
  :class:`SphereKernel` keeps its charge-free geometry for the check's repeated calls;
- :func:`coulomb_kernel`: the field per unit charge as a matrix (points x 3 x charges), the
  rows of the charges' cone programs (:mod:`chargedesign.designer.cone_program`).

All are tested against the direct sum (tests/physical/test_coulomb.py).
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
    ``|p - x|^2 = |p|^2 + |x|^2 - 2 p.x``: per block one product ``[p, 1] @ [-2 x; |x|^2]``
    gives the distances and one ``w @ [q, q x]`` both sums (BLAS), about 1.7x faster than
    :func:`coulomb_field`. The distances lose ``(|p| / |p - x|)^2`` ulps to cancellation: on
    random bodies the two agree to about 1e-11 (a test), far below the design's margin of
    1e-3.

    The (p, n) work arrays are cut into blocks of about :data:`FIELD_BLOCK_ELEMENTS` and
    updated in place, so they stay in cache: the elementwise passes, not the products, set
    the cost (measured 6x faster than 32 MB blocks at 250 carriers, 200 samples each).
    """
    out = np.empty((len(points), 3))
    n = len(sources)
    right = np.empty((4, n))
    right[:3] = -2.0 * sources.T
    right[3] = np.einsum("nk,nk->n", sources, sources)
    sums = np.empty((n, 4))
    sums[:, 0] = charges
    sums[:, 1:] = charges[:, None] * sources
    block = max(1, FIELD_BLOCK_ELEMENTS // max(1, n))
    left = np.ones((min(block, len(points)), 4))
    for start in range(0, len(points), block):
        p = points[start : start + block]
        rows = left[: len(p)]
        rows[:, :3] = p
        r2 = rows @ right  # |x|^2 - 2 p.x
        r2 += np.einsum("pk,pk->p", p, p)[:, None]
        w = np.sqrt(r2)
        w *= r2
        np.divide(1.0, w, out=w)
        t = w @ sums  # sum q_j w_j, sum q_j w_j x_j
        out[start : start + block] = COULOMB * (p * t[:, :1] - t[:, 1:])
    return out


def coulomb_kernel(sources: np.ndarray, points: np.ndarray, scale: float = COULOMB) -> np.ndarray:
    """The field at ``points`` (m, 3) of a unit charge at each of ``sources`` (k, 3), times
    ``scale`` over ``COULOMB`` (the default gives V/m per C): shape (m, 3, k). ``scale``
    takes a program's units in one product (``COULOMB * charge_unit / field_unit``)."""
    d = points[:, None, :] - sources[None, :, :]  # (m, k, 3)
    r3 = np.einsum("mkc,mkc->mk", d, d) ** 1.5
    return scale * (d / r3[:, :, None]).transpose(0, 2, 1)


#: elements of the sphere kernel's (samples, charges) work arrays per block (512 kB: in cache)
SPHERE_BLOCK_ELEMENTS = 1 << 16


def _offsets_and_squares(centres: np.ndarray, radii: np.ndarray, block: slice) -> tuple:
    """The carriers ``block``'s offsets ``d_j = x_j - x_i`` (b, k, 3) and the rows (b, 4, k)
    that give ``|a n - d_j|^2 = a^2 + |d_j|^2 - 2 a n . d_j`` as ``[n, 1] @ rows``."""
    d = centres[None, :, :] - centres[block, None, :]
    a = radii[block]
    rows = np.empty((len(d), 4, len(centres)))
    rows[:, :3] = (-2.0 * a)[:, None, None] * d.transpose(0, 2, 1)
    rows[:, 3] = (a * a)[:, None] + np.einsum("bjk,bjk->bj", d, d)
    return d, rows


def _inverse_cubes(lhs: np.ndarray, rows: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """``1 / |a n - d_j|^3`` from ``[n, 1]`` (b, m, 4) and the rows (b, 4, k): (b, m, k)."""
    w = np.matmul(lhs, rows, out=out)  # |a n - d_j|^2
    r = np.sqrt(w)
    w *= r
    return np.divide(1.0, w, out=w)


def _blocks(k: int, m: int) -> tuple[int, int]:
    """Carriers and samples per block: about :data:`SPHERE_BLOCK_ELEMENTS` pairs."""
    samples = min(m, max(1, SPHERE_BLOCK_ELEMENTS // max(1, k)))
    return max(1, SPHERE_BLOCK_ELEMENTS // (samples * max(1, k))), samples


def _directions_with_one(directions: np.ndarray) -> np.ndarray:
    out = np.empty((*directions.shape[:-1], 4))
    out[..., :3] = directions
    out[..., 3] = 1.0
    return out


def sphere_fields(
    centres: np.ndarray, charges: np.ndarray, radii: np.ndarray, directions: np.ndarray
) -> np.ndarray:
    """Field of the point charges at ``centres`` (k, 3) on every carrier's sphere, V/m.

    The points are ``centres[i] + radii[i] * directions`` (``directions`` (m, 3), the same
    for every carrier, or (k, m, 3), each carrier's own): shape (k, m, 3). Summed in each
    carrier's own coordinates, ``E = k_e sum_j q_j (a n - d_j) / |a n - d_j|^3`` with
    ``d_j = x_j - x_i``: the carrier's own charge (``d = 0``) gives its radial
    ``q / (4 pi eps0 a^2)`` to rounding, and the distances lose nothing to the body's size
    (:func:`coulomb_field_gemm` loses ``(|p| / |p - x|)^2`` ulps). Per block of carriers,
    one matrix product ``[n, 1] @ rows`` gives the squared distances and one,
    ``w @ [q, q d]``, the sums (tests/physical/test_coulomb.py against the direct sum).
    """
    k = len(centres)
    radii = np.broadcast_to(np.asarray(radii, dtype=float), (k,))
    m = directions.shape[-2]
    lhs = _directions_with_one(directions)
    if directions.ndim == 2:
        lhs = np.broadcast_to(lhs, (k, m, 4))
    out = np.empty((k, m, 3))
    per_block, per_samples = _blocks(k, m)
    for start in range(0, k, per_block):
        block = slice(start, start + per_block)
        d, rows = _offsets_and_squares(centres, radii, block)
        sums = np.empty((len(d), k, 4))
        sums[..., 0] = charges
        np.multiply(charges[:, None], d, out=sums[..., 1:])
        a = radii[block, None, None]
        for first in range(0, m, per_samples):
            part = slice(first, first + per_samples)
            t = np.matmul(_inverse_cubes(lhs[block, part], rows), sums)  # sum q w [1, d]
            out[block, part] = (a * t[..., :1]) * lhs[block, part, :3] - t[..., 1:]
    out *= COULOMB
    return out


#: largest (carriers, samples, carriers) array a :class:`SphereKernel` keeps (2^25 doubles:
#: 268 MB; the default body's 257 candidates at 200 samples take 13.2M), and the most
#: elements all kept kernels hold together
SPHERE_KERNEL_ELEMENTS = 1 << 25


class SphereKernel:
    """The charge-free geometry of :func:`sphere_fields` on fixed carriers and directions.

    ``1 / |a n_m - d_ij|^3`` for every carrier i, direction m and carrier j (shape (k, m, k))
    and the sample points' distances from the origin do not depend on the charges: computed
    once, each evaluation is then one matrix product per carrier (the charges on any subset
    of the carriers, zero on the rest). Kept by :func:`sphere_kernel` per content.
    """

    def __init__(self, centres: np.ndarray, radius: float, directions: np.ndarray) -> None:
        self.centres = np.array(centres, dtype=float)
        self.radius = float(radius)
        self.directions = np.array(directions, dtype=float)
        k, m = len(self.centres), len(self.directions)
        self.index = {row.tobytes(): i for i, row in enumerate(self.centres)}
        radii = np.full(k, self.radius)
        self.offsets, rows = _offsets_and_squares(self.centres, radii, slice(0, k))
        self.inverse_cubes = np.empty((k, m, k))
        lhs = _directions_with_one(self.directions)
        per_block, per_samples = _blocks(k, m)
        for start in range(0, k, per_block):
            block = slice(start, start + per_block)
            for first in range(0, m, per_samples):
                part = slice(first, first + per_samples)
                _inverse_cubes(lhs[part], rows[block], self.inverse_cubes[block, part])
        points = self.centres[:, None, :] + self.radius * self.directions[None, :, :]
        self.distances = np.linalg.norm(points, axis=2)  # (k, m): |x_i + a n_m|

    @property
    def elements(self) -> int:
        return self.inverse_cubes.size

    def rows_of(self, positions: np.ndarray) -> np.ndarray | None:
        """The carriers' indices of ``positions`` (rows of the centres), None if one is not."""
        rows = [self.index.get(np.asarray(p, dtype=float).tobytes()) for p in positions]
        if any(r is None for r in rows):
            return None
        return np.array(rows, dtype=int)

    def fields(self, rows: np.ndarray, charges: np.ndarray) -> np.ndarray:
        """:func:`sphere_fields` of ``charges`` on the carriers ``rows``, at their own spheres'
        directions: shape (len(rows), m, 3), V/m."""
        full = np.zeros(len(self.centres))
        full[rows] = charges
        n = self.directions
        out = np.empty((len(rows), len(n), 3))
        sums = np.empty((len(self.centres), 4))
        sums[:, 0] = full
        for out_i, i in zip(out, rows, strict=True):
            np.multiply(full[:, None], self.offsets[i], out=sums[:, 1:])
            t = self.inverse_cubes[i] @ sums
            np.subtract((self.radius * t[:, :1]) * n, t[:, 1:], out=out_i)
        out *= COULOMB
        return out


_KERNELS: dict[tuple[bytes, float, bytes], SphereKernel] = {}


def sphere_kernel(
    centres: np.ndarray, radius: float, directions: np.ndarray
) -> SphereKernel | None:
    """The :class:`SphereKernel` of these carriers and directions, computed on first use and
    kept (the most recent first, :data:`SPHERE_KERNEL_ELEMENTS` in all); None when it would
    be larger than that (then sum directly, :func:`sphere_fields`)."""
    k, m = len(centres), len(directions)
    if k * k * m > SPHERE_KERNEL_ELEMENTS:
        return None
    key = (
        np.ascontiguousarray(centres, dtype=float).tobytes(),
        float(radius),
        np.ascontiguousarray(directions, dtype=float).tobytes(),
    )
    kernel = _KERNELS.pop(key, None)
    if kernel is None:
        kernel = SphereKernel(centres, radius, directions)
    _KERNELS[key] = kernel  # the most recent last
    while sum(kern.elements for kern in _KERNELS.values()) > SPHERE_KERNEL_ELEMENTS:
        del _KERNELS[next(iter(_KERNELS))]
    return kernel
