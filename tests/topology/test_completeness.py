"""Completeness: an independent brute-force search finds no critical value off the diagram.

The search shares only the exact gradients with the package (checked against central
differences of the model's own evaluators below): from random states it solves the rank
condition ``cos t dH + sin t dI4 + beta dI2 + delta dI3 = 0`` with ``|gamma| = 1, I3 = 0``
and a random linear slice through the start, by scipy's least squares (no seeds, no
continuation, no knowledge of the families).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares
from unit_scene import UNIT_PARAMETERS as UNIT

from chargedesign.model.evaluators import integrals
from chargedesign.topology.equations import MomentumMap, relative_singular_value

#: the unit-scale case (examples/scenes/unit_scale.toml)


def test_exact_gradients_match_differences_of_the_model():
    F = MomentumMap(UNIT)
    x = np.random.default_rng(1).normal(size=6)
    step = 1e-6
    shifts = np.concatenate([np.eye(6) * step, -np.eye(6) * step])
    values = integrals(x + shifts, UNIT)[:, [0, 3, 1, 2]]  # H, I4, I2, I3
    differences = ((values[:6] - values[6:]) / (2 * step)).T
    assert np.allclose(F.gradients(x)[0], differences, rtol=1e-6, atol=1e-7)


def brute_force(F, count, h_range, scales, seed=7):
    """(h, k) of the critical points found from ``count`` random starts inside h_range."""
    rng = np.random.default_rng(seed)

    def residual(u, normal, value):
        x, t, beta, delta = u[:6], u[6], u[7], u[8]
        g = F.gradients(x)[0]
        v = F.values(x)[0]
        weights = np.array([np.cos(t) / scales[0], np.sin(t) / scales[1], beta, delta])
        return np.concatenate([weights @ g, [v[2] - 1.0, v[3], normal @ x - value]])

    def jacobian(u, normal, value):
        x, t = u[:6], u[6]
        g, hess = F.gradients(x)[0], F.hessians(x)[0]
        weights = np.array([np.cos(t) / scales[0], np.sin(t) / scales[1], u[7], u[8]])
        J = np.zeros((9, 9))
        J[:6, :6] = np.einsum("i,ijk->jk", weights, hess)
        J[:6, 6] = -np.sin(t) * g[0] / scales[0] + np.cos(t) * g[1] / scales[1]
        J[:6, 7], J[:6, 8] = g[2], g[3]
        J[6, :6], J[7, :6], J[8, :6] = g[2], g[3], normal
        return J

    found = []
    for _ in range(count):
        gamma = rng.normal(size=3)
        x = np.concatenate([rng.normal(size=3) * np.sqrt(scales[0]), gamma / np.linalg.norm(gamma)])
        normal = rng.normal(size=6)
        start = np.concatenate([x, [rng.uniform(0, np.pi), 0.0, 0.0]])
        fit = least_squares(
            residual,
            start,
            jac=jacobian,
            args=(normal, normal @ x),
            xtol=1e-15,
            ftol=1e-15,
            gtol=1e-15,
            max_nfev=100,
        )
        x = fit.x[:6]
        h, k = F.values(x)[0, :2]
        critical = relative_singular_value(F.gradients(x))[0] <= 1e-6
        if np.linalg.norm(fit.fun) < 1e-9 and critical and h_range[0] < h < h_range[1]:
            found.append((h, k))
    return np.array(found).reshape(-1, 2)


def _distance(point, curves, vertices, size):
    """Distance (diagram units) from an image point to polylines ``curves`` and points."""
    best = np.inf
    q = point / size
    for hk in curves:
        a, b = hk[:-1] / size, hk[1:] / size
        ab = b - a
        s = np.einsum("ij,ij->i", q - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
        s = np.clip(s, 0.0, 1.0)
        best = min(best, float(np.min(np.linalg.norm(a + s[:, None] * ab - q, axis=1))))
    for v in vertices:
        best = min(best, float(np.linalg.norm(v / size - q)))
    return best


def test_brute_force_finds_nothing_off_the_diagram(unit_diagram):
    lo, hi = unit_diagram.raw.h_range
    curves = [b.hk for b in unit_diagram.branches]
    vertices = [v.hk for v in unit_diagram.raw.vertices]
    size = np.ptp(np.concatenate(curves), axis=0)
    found = brute_force(MomentumMap(UNIT), 150, (lo, hi), size)
    assert len(found) >= 20, len(found)  # the search works
    distances = [_distance(p, curves, vertices, size) for p in found]
    assert max(distances) < 0.01, found[int(np.argmax(distances))]
    # and the search, knowing nothing of the branches, meets every one of them
    for hk in curves:
        assert min(_distance(p, [hk], [], size) for p in found) < 0.01
