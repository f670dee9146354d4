"""The golden-angle (Fibonacci) sphere sampler: the one place it is written."""

from __future__ import annotations

import math

import numpy as np

#: the golden angle, rad: successive samples turn by it about the axis
GOLDEN_ANGLE = math.pi * (3.0 - math.sqrt(5.0))


def fibonacci_sphere(n_points: int, phase: float = 0.5) -> np.ndarray:
    """``n_points`` nearly uniform unit vectors (golden-angle spiral), shape (n_points, 3).

    Point ``i`` sits at height ``z = 1 - (2 i + 1) / n`` (equal areas) and azimuth
    ``GOLDEN_ANGLE * (i + phase)``. (The forward check's orientations,
    :func:`chargedesign.checker.sample_orientations`, keep their own rounding order.)
    """
    i = np.arange(n_points) + 0.5
    z = 1.0 - 2.0 * i / n_points
    rho = np.sqrt(np.clip(1.0 - z * z, 0.0, None))
    phi = GOLDEN_ANGLE * (np.arange(n_points) + phase)
    return np.column_stack([rho * np.cos(phi), rho * np.sin(phi), z])
