"""The largest applied field over the body's orientations, as a function of radius.

An axisymmetric applied field (Legendre coefficients,
:class:`chargedesign.fields.AxisymmetricField`) reaches a point of the body at distance r
under every polar angle as the body turns: the limits, the design and the realism budget
bound it by its largest value over that sphere.
"""

from __future__ import annotations

import numpy as np

from chargedesign.fields import AxisymmetricField

#: polar angles sampled for the largest field over orientations
ANGLE_SAMPLES = 2001


def field_magnitude_max(legendre: tuple[float, ...], radii: np.ndarray) -> np.ndarray:
    """Largest ``|grad Phi|`` over every orientation at each radius (m), shape like ``radii``.

    An axisymmetric field at distance r takes every polar angle as the body turns, so the
    largest magnitude over orientations is the largest over the polar angle on the sphere of
    radius r. It is also the largest over the ball of radius r (``|grad Phi|^2`` is
    subharmonic), hence nondecreasing in r.
    """
    radii = np.asarray(radii, dtype=float)
    fld = AxisymmetricField(tuple(legendre))
    if fld.is_zero or radii.size == 0:
        return np.zeros_like(radii)
    theta = np.linspace(0.0, np.pi, ANGLE_SAMPLES)
    unit = np.column_stack([np.sin(theta), np.zeros_like(theta), np.cos(theta)])
    flat = radii.reshape(-1)
    out = np.empty(len(flat))
    for start in range(0, len(flat), 256):
        r = flat[start : start + 256]
        pts = (r[:, None, None] * unit[None, :, :]).reshape(-1, 3)
        mag = np.linalg.norm(fld.gradient(pts), axis=1).reshape(len(r), -1)
        # the grid misses the true maximum by O(h^2): add that bound (second differences)
        top = mag.max(axis=1)
        curvature = np.abs(np.diff(mag, 2, axis=1)).max(axis=1) if mag.shape[1] > 2 else 0.0
        out[start : start + 256] = top + curvature
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
