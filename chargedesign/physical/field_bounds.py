"""The largest applied field over the body's orientations, as a function of radius.

An axisymmetric applied field (Legendre coefficients,
:class:`chargedesign.fields.AxisymmetricField`) reaches a point of the body at distance r
under every polar angle as the body turns: the limits, the design and the realism budget
bound it by its largest value over that sphere.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from chargedesign.fields import AxisymmetricField

#: radii of the electric field's grid over the body region (its last radius is the region's)
REGION_GRID_RADII = 513
#: polar angles sampled for the largest field over orientations
ANGLE_SAMPLES = 2001
#: radii per block of the (angles, radii) work arrays (2001 x 64 doubles: 1 MB)
RADII_BLOCK = 64


#: up to this many radii the recurrence runs at every angle (the screen costs more there)
DIRECT_RADII = 8
#: the screen's tolerance, relative to the sum of the magnitudes of the field's terms: far
#: above the rounding of either route (both sum the same few terms; measured below 2e-14)
SCREEN_TOLERANCE = 1e-12


@functools.lru_cache(maxsize=1)
def _unit_circle() -> np.ndarray:
    theta = np.linspace(0.0, np.pi, ANGLE_SAMPLES)
    out = np.column_stack([np.sin(theta), np.zeros_like(theta), np.cos(theta)])
    out.flags.writeable = False
    return out


@functools.lru_cache(maxsize=16)
def _unit_gradients(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """``grad u_k`` on the unit half circle in the (X, Z) plane, ``k = 1 .. degree``: its X
    and Z components, each of shape (angles, degree) (its Y component is 0), read-only.

    ``u_k = R^k P_k(Z / R)`` is homogeneous of degree k, so ``grad u_k(r e) = r^(k-1) grad
    u_k(e)``: the field at every radius is a matrix product with these.
    """
    unit = _unit_circle()
    x, z = np.empty((ANGLE_SAMPLES, degree)), np.empty((ANGLE_SAMPLES, degree))
    for k in range(1, degree + 1):
        grad = AxisymmetricField((0.0,) * (k - 1) + (1.0,)).gradient(unit)
        x[:, k - 1], z[:, k - 1] = grad[:, 0], grad[:, 2]
    x.flags.writeable = False
    z.flags.writeable = False
    return x, z


def _direct_magnitudes(fld: AxisymmetricField, radii: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """``|grad Phi|`` at the points ``radii * e(angle index)`` by the recurrence (the
    reference route, point by point)."""
    return np.linalg.norm(fld.gradient(radii[:, None] * _unit_circle()[angles]), axis=1)


def _second_differences(values: np.ndarray) -> np.ndarray:
    """``|np.diff(values, 2, axis=0)|`` (the same operations, along the angles)."""
    first = values[1:] - values[:-1]
    out = first[1:] - first[:-1]
    return np.abs(out, out=out)


def field_magnitude_max(legendre: tuple[float, ...], radii: np.ndarray) -> np.ndarray:
    """Largest ``|grad Phi|`` over every orientation at each radius (m), shape like ``radii``.

    An axisymmetric field at distance r takes every polar angle as the body turns, so the
    largest magnitude over orientations is the largest over the polar angle on the sphere of
    radius r. It is also the largest over the ball of radius r (``|grad Phi|^2`` is
    subharmonic), hence nondecreasing in r. The grid of :data:`ANGLE_SAMPLES` polar angles
    misses the true maximum by O(h^2): the largest second difference is added as that bound.

    Computed in two steps with the answer of the point-by-point recurrence, to the last bit:
    a screen, ``sum_k f_k r^(k-1) grad u_k(e)`` at every angle and radius (each ``u_k``
    homogeneous of degree k: one matrix product with the unit circle's gradients,
    :func:`_unit_gradients`), then the recurrence at the few angles whose screened magnitude
    or second difference comes within the screen's error bound (:data:`SCREEN_TOLERANCE`
    times the sum of the terms' magnitudes) of the largest: the largest of the recurrence's
    values is among them. tests/physical/test_field_bounds.py compares it with the
    recurrence at every angle.
    """
    radii = np.asarray(radii, dtype=float)
    fld = AxisymmetricField(tuple(legendre))
    if fld.is_zero or radii.size == 0:
        return np.zeros_like(radii)
    degree = fld.degree
    f = np.asarray(fld.legendre[:degree])
    unit_x, unit_z = _unit_gradients(degree)
    gx, gz = unit_x * f, unit_z * f
    # the size of each term, for the screen's error bound
    term_size = np.abs(f) * np.sqrt(unit_x**2 + unit_z**2).max(axis=0)
    powers = np.arange(degree)[:, None]
    flat = radii.reshape(-1)
    if len(flat) <= DIRECT_RADII:
        angles = np.tile(np.arange(ANGLE_SAMPLES), len(flat))
        mag = _direct_magnitudes(fld, np.repeat(flat, ANGLE_SAMPLES), angles)
        mag = mag.reshape(len(flat), ANGLE_SAMPLES).T
        return (mag.max(axis=0) + _second_differences(mag).max(axis=0)).reshape(radii.shape)
    out = np.empty(len(flat))
    for start in range(0, len(flat), RADII_BLOCK):
        r = flat[start : start + RADII_BLOCK]
        r_pow = r[None, :] ** powers  # (degree, radii)
        mag = gx @ r_pow
        mag *= mag
        ez = gz @ r_pow
        ez *= ez
        mag += ez
        np.sqrt(mag, out=mag)  # (angles, radii), to rounding
        tol = SCREEN_TOLERANCE * (term_size @ np.abs(r_pow))
        near_top = mag >= mag.max(axis=0) - 2.0 * tol
        bend = _second_differences(mag)
        near_bend = bend >= bend.max(axis=0) - 8.0 * tol
        # the recurrence where the screen cannot tell: near the largest value, and at the
        # three points of every second difference near the largest one
        need = near_top.copy()
        for shift in range(3):
            need[shift : shift + len(bend)] |= near_bend
        flat_need = np.flatnonzero(need)
        angles, cols = np.divmod(flat_need, len(r))
        exact = np.empty_like(mag)
        exact.flat[flat_need] = _direct_magnitudes(fld, r[cols], angles)
        top = np.full(len(r), -np.inf)
        at = np.flatnonzero(near_top)
        np.maximum.at(top, at % len(r), exact.flat[at])
        curvature = np.full(len(r), -np.inf)
        c, col = np.divmod(np.flatnonzero(near_bend), len(r))
        e0, e1, e2 = exact[c, col], exact[c + 1, col], exact[c + 2, col]
        np.maximum.at(curvature, col, np.abs((e2 - e1) - (e1 - e0)))
        out[start : start + len(r)] = top + curvature
    return out.reshape(radii.shape)


class RadialBound:
    """The largest field over orientations as a function of radius, on a grid.

    ``field_magnitude_max`` is nondecreasing in the radius, so the value at the next grid
    radius up bounds it from above; the grid is fine enough that this costs < 1e-3.
    """

    def __init__(self, legendre: tuple[float, ...], r_max: float, n: int = 1025) -> None:
        self.zero = not any(legendre)
        self.grid = np.linspace(0.0, max(r_max, 1e-300), n)
        self.values = np.zeros(n) if self.zero else field_magnitude_max(legendre, self.grid)

    def __call__(self, radii: np.ndarray) -> np.ndarray:
        if self.zero:
            return np.zeros_like(radii)
        idx = np.minimum(np.searchsorted(self.grid, radii, side="left"), len(self.grid) - 1)
        beyond = radii > self.grid[-1]
        out = self.values[idx]
        if np.any(beyond):
            raise ValueError("RadialBound: radius beyond its grid")
        return out


def region_maxima(fields: Mapping[str, Sequence[float]], region: float) -> dict[str, float]:
    """The largest ``|grad Phi|`` of each given field (kind -> Legendre coefficients; empty
    ones left out) over the ball of radius ``region``: its value on that sphere, the
    magnitude being nondecreasing in the radius."""
    radius = np.array([region])
    return {
        kind: float(field_magnitude_max(tuple(coeffs), radius)[0])
        for kind, coeffs in fields.items()
        if coeffs
    }


@dataclass(frozen=True)
class FieldReach:
    """How strong the applied fields get over a body region, computed once for a design's
    setup: the largest magnitude of each field over the region, the electric field's bound
    on a grid of radii out to it, and the magnetic field's at chosen radii."""

    region: float
    #: kind -> the largest magnitude over the ball of radius ``region``
    maxima: dict[str, float]
    #: radii from 0 to ``region`` (:data:`REGION_GRID_RADII`, the last the region's exactly)
    electric_grid: np.ndarray
    #: the electric field's largest magnitude at each grid radius (zeros without one)
    electric_values: np.ndarray
    #: the magnetic field's largest magnitude at the radii asked for (None: not asked)
    magnetic_at: np.ndarray | None


def field_reach(
    fields: Mapping[str, Sequence[float]],
    region: float,
    *,
    magnetic_radii: np.ndarray | None = None,
) -> FieldReach:
    """The :class:`FieldReach` of ``fields`` over the ball of radius ``region``; the
    magnetic field's bound at ``magnetic_radii`` too when they are given and it is not zero."""
    electric = tuple(fields.get("electric", ()))
    magnetic = tuple(fields.get("magnetic", ()))
    grid = np.linspace(0.0, region, REGION_GRID_RADII)
    values = field_magnitude_max(electric, grid) if electric else np.zeros_like(grid)
    at = None
    if magnetic_radii is not None and magnetic:
        at = field_magnitude_max(magnetic, magnetic_radii)
    return FieldReach(region, region_maxima(fields, region), grid, values, at)
