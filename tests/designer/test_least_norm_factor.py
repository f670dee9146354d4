"""The least-norm solve with one factor of the matrix (``least_norm_solver``) against the
formula it replaced (a QR, or an ``lstsq``, per solve): the same bits."""

import numpy as np
import pytest

from chargedesign.designer.solvers import least_norm, least_norm_solver
from chargedesign.designer.system import polish_equal


def _old_least_norm(A, b):
    """The formula before the factor was shared: a fresh QR (or lstsq) for every solve."""

    def solve(rhs):
        if A.shape[1] > 4 * A.shape[0]:
            Q, R = np.linalg.qr(A.T)
            return Q @ np.linalg.lstsq(R.T, rhs, rcond=None)[0]
        return np.linalg.lstsq(A, rhs, rcond=None)[0]

    x = solve(b)
    return x + solve(b - A @ x)


def _old_polish_equal(A, b, w, cols):
    out = w.copy()
    top = np.max(np.abs(A[:, cols]), axis=1)
    top = np.where(top > 0, top, 1.0)
    As = A[:, cols] / top[:, None]
    for _ in range(3):
        out[cols] += _old_least_norm(As, (b - A @ out) / top)
    return out


@pytest.mark.parametrize("shape", [(6, 200), (6, 20), (8, 5)])
def test_factored_least_norm_is_the_old_formula(shape):
    rng = np.random.default_rng(7)
    A = rng.normal(size=shape) * np.logspace(0, 6, shape[0])[:, None]
    b = rng.normal(size=shape[0])
    old = _old_least_norm(A, b)
    np.testing.assert_array_equal(least_norm(A, b), old)  # the same bits
    solve = least_norm_solver(A)
    for _ in range(3):  # one factor, many right-hand sides
        np.testing.assert_allclose(least_norm(A, b, solve), old, rtol=1e-12, atol=0)
    if shape[1] > shape[0]:  # a wide system is met to rounding
        x = least_norm(A, b)
        assert np.linalg.norm(A @ x - b) <= 1e-9 * np.linalg.norm(b)


def test_polish_equal_is_the_old_formula():
    rng = np.random.default_rng(3)
    A = rng.normal(size=(7, 300))
    b = rng.normal(size=7)
    w = rng.normal(size=300)
    cols = np.sort(rng.choice(300, size=120, replace=False))
    np.testing.assert_allclose(
        polish_equal(A, b, w, cols), _old_polish_equal(A, b, w, cols), rtol=1e-12, atol=0
    )
