"""The eddy torque of a conducting sphere turning with the body, against its currents.

The independent route: the steady current ``J = sigma (v x B - grad phi)`` in the ball, with
``phi`` the minimiser of the dissipation ``int |v x B - grad phi|^2`` over polynomials of
degree <= 3 (its Euler-Lagrange equations are ``div J = 0`` inside and ``J . n = 0`` on the
surface; ``v x B`` is quadratic in the ball, so the exact ``phi`` is in that space), and the
torque ``int (c + rho) x (J x B) dV`` by product Gauss quadrature, with the full field and
velocity (nothing linearised).
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from chargedesign.fields import AxisymmetricField
from chargedesign.physical.parasitics import eddy_torque


def _ball_nodes(radius: float, n: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Nodes (k, 3) and weights of a product Gauss rule over the ball, exact to degree 2n - 3."""
    x, w = np.polynomial.legendre.leggauss(n)
    r = radius * (x + 1) / 2
    wr = w * radius / 2 * r**2
    ct, wt = x, w
    phi = np.arange(2 * n) * np.pi / n
    wp = np.full(2 * n, np.pi / n)
    pts, wts = [], []
    for (ri, wri), (ci, wci), (pi, wpi) in itertools.product(
        zip(r, wr, strict=True), zip(ct, wt, strict=True), zip(phi, wp, strict=True)
    ):
        s = np.sqrt(1 - ci**2)
        pts.append(ri * np.array([s * np.cos(pi), s * np.sin(pi), ci]))
        wts.append(wri * wci * wpi)
    return np.array(pts), np.array(wts)


def _monomial_gradients(rho: np.ndarray) -> np.ndarray:
    """Gradients of the monomials of degree 1 to 3 in rho, shape (basis, k, 3)."""
    out = []
    for powers in itertools.product(range(4), repeat=3):
        if not 1 <= sum(powers) <= 3:
            continue
        grad = np.zeros((len(rho), 3))
        for axis in range(3):
            if powers[axis] == 0:
                continue
            lowered = list(powers)
            lowered[axis] -= 1
            grad[:, axis] = powers[axis] * np.prod(rho**lowered, axis=1)
        out.append(grad)
    return np.array(out)


def _quadrature_torque(legendre, centre, radius, sigma, omega) -> np.ndarray:
    """Torque about O of the steady eddy currents in a ball at ``centre`` (space = body axes)."""
    rho, w = _ball_nodes(radius)
    x = centre + rho
    b = -AxisymmetricField(tuple(legendre)).gradient(x)
    emf = np.cross(np.cross(omega, x), b)
    basis = _monomial_gradients(rho)  # (p, k, 3)
    sw = np.sqrt(w)[None, :, None]
    a = (basis * sw).reshape(len(basis), -1).T
    coef, *_ = np.linalg.lstsq(a, (emf * sw[0]).reshape(-1), rcond=None)
    current = sigma * (emf - np.einsum("p,pki->ki", coef, basis))
    # the steady current is divergence-free and tangent to the surface: no net current
    assert np.abs(w @ current).max() <= 1e-10 * np.abs(current).max() * radius**3
    return w @ np.cross(x, np.cross(current, b))


def test_uniform_field_matches_the_rotating_sphere_closed_form():
    # spinning about O off-centre in a uniform B: only the part's spin drives currents
    b0 = np.array([0.0, 0.0, 0.7])
    centre, radius, sigma = np.array([0.03, -0.02, 0.01]), 4e-3, 5.8e7
    omega = np.array([1.3, -0.4, 2.0])
    quad = _quadrature_torque((0.7,), centre, radius, sigma, omega)
    closed = -(2 * np.pi / 15) * sigma * radius**5 * np.cross(b0, np.cross(omega, b0))
    got = eddy_torque(
        (0.7,),
        centre[None],
        np.array([sigma * radius**5]),
        omega[None],
        np.array([[0.0, 0.0, 1.0]]),
    )[0]
    np.testing.assert_allclose(quad, closed, rtol=1e-10, atol=1e-10 * np.abs(closed).max())
    np.testing.assert_allclose(got, closed, rtol=1e-12, atol=1e-14 * np.abs(closed).max())


def test_gradient_field_matches_quadrature_to_the_dropped_order():
    # a1 and a gradient: B linear in position; the closed form drops the current of the part
    # of v x B quadratic in rho, a correction of order (a / |c|)^2: seen as that order
    legendre = (0.02, 2 * 0.5)
    centre = np.array([0.04, 0.01, -0.03])
    sigma = 1.5e7
    omega = np.array([0.7, -1.1, 0.4])
    errors = []
    for ratio in (0.1, 0.05):
        radius = ratio * np.linalg.norm(centre)
        quad = _quadrature_torque(legendre, centre, radius, sigma, omega)
        got = eddy_torque(
            legendre,
            centre[None],
            np.array([sigma * radius**5]),
            omega[None],
            np.array([[0.0, 0.0, 1.0]]),
        )[0]
        errors.append(np.linalg.norm(got - quad) / np.linalg.norm(quad))
        assert errors[-1] <= 0.3 * ratio**2, errors
    assert errors[1] / errors[0] == pytest.approx(0.25, rel=0.02)


def test_body_axes_and_dissipation():
    # the same sphere seen in body axes at another attitude gives the rotated torque, and
    # the torque only dissipates (tau . omega <= 0 at every state)
    rng = np.random.default_rng(3)
    legendre = (0.01, 2 * 0.3, 0.05)
    centres = rng.normal(size=(5, 3)) * 0.03
    weights = rng.uniform(1.0, 2.0, 5) * 1e7 * 3e-3**5
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.linalg.det(q))
    omega = rng.normal(size=(40, 3))
    gammas = rng.normal(size=(40, 3))
    gammas /= np.linalg.norm(gammas, axis=1)[:, None]
    tau = eddy_torque(legendre, centres, weights, omega, gammas)
    assert np.all(np.einsum("ij,ij->i", tau, omega) < 0)
    rotated = eddy_torque(legendre, centres @ q.T, weights, omega @ q.T, gammas @ q.T)
    np.testing.assert_allclose(rotated, tau @ q.T, rtol=1e-10, atol=1e-12 * np.abs(tau).max())
    # linear in omega: tau = -D(gamma) omega
    np.testing.assert_allclose(
        eddy_torque(legendre, centres, weights, 2.5 * omega, gammas), 2.5 * tau, rtol=1e-12
    )
