"""The direct route's fast kernel (chargedesign.simulation.direct): correctness only.

The kernel is checked against the term-by-term physics of ``direct_terms`` (space axes, forces
and lever arms), against the public body-axes field methods, and its single-state Python-float
path against its batched path. No timings here (see docs/simulate.md for the measured cost).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chargedesign.bench.common import random_body as bench_random_body
from chargedesign.fields import zonal_sums, zonal_z_coefficients
from chargedesign.params import Parameters
from chargedesign.simulation import (
    Body,
    RigidBodySystem,
    attitude_from_gamma,
    direct_terms,
    quaternion_gamma,
    quaternion_rotation,
)
from chargedesign.simulation.direct import DirectKernel

PHYSICAL = ["lorentz", "electric", "magnetization", "gravity"]


FIELDS = {
    "magnetic": (0.4, 1.0, -0.6, 0.3),
    "electric": (0.2, 0.5, 0.3, 0.4, -0.2),
    "gravity": (9.81, 0.3),
}


def random_body(seed: int, n: int = 10, fields: dict | None = None) -> Body:
    """Elements of every kind (the shared builder) in ``fields`` or :data:`FIELDS`."""
    params = Parameters(C=0.7, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9)
    return bench_random_body(seed, params, fields or FIELDS, n)


def _states(seed: int, m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    quats = rng.normal(size=(m, 4))
    return rng.normal(size=(m, 3)), quaternion_gamma(quats), quaternion_rotation(quats)


def _reference(body: Body, effects: list[str], W: np.ndarray, R: np.ndarray) -> np.ndarray:
    return sum(direct_terms(body, e, W, R)[0] for e in effects)


@pytest.mark.parametrize("order", [0, 1, 2])
def test_z_coefficients_are_the_zonal_sums(order: int) -> None:
    """Polynomials in Z per point reproduce the recurrence evaluated at (Z, S)."""
    rng = np.random.default_rng(order)
    coeffs = rng.normal(size=6)
    coeffs[2] = 0.0  # a zero coefficient in the middle
    pts = rng.uniform(-1.5, 1.5, (40, 3))
    G = rng.normal(size=3)
    G /= np.linalg.norm(G)
    Z, S = pts @ G, np.einsum("ij,ij->i", pts, pts)
    table = zonal_z_coefficients(coeffs, S, order)
    sums = zonal_sums(coeffs, Z, S, order)
    powers = Z[:, None] ** np.arange(len(coeffs) + 1)
    expected = {"": 0, "Z": 1, "S": 1, "ZZ": 2, "ZS": 2, "SS": 2}
    assert sorted(table) == sorted(k for k, o in expected.items() if o <= order)
    for key, c in table.items():
        assert c.shape == (len(pts), len(coeffs) + 1)
        got = np.einsum("ia,ia->i", c, powers)
        scale = np.max(np.abs(sums[key])) + 1.0
        assert np.max(np.abs(got - sums[key])) <= 1e-13 * scale, key


def test_z_coefficients_of_the_zero_field() -> None:
    table = zonal_z_coefficients(np.zeros(0), np.array([1.0, 2.0]), 2)
    assert all(c.shape == (2, 1) and not c.any() for c in table.values())


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_kernel_matches_term_by_term_physics(seed: int) -> None:
    body = random_body(seed)
    W, G, R = _states(50 + seed, 8)
    for effects in [[e] for e in PHYSICAL] + [PHYSICAL]:
        kernel = DirectKernel(body, effects)
        got = kernel.torque(W, G)
        ref = _reference(body, effects, W, R)
        assert np.max(np.abs(got - ref)) <= 1e-13 * np.max(np.abs(ref)), effects


@settings(max_examples=25, deadline=None)
@given(
    st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(
        lambda v: sum(x * x for x in v) > 0.1
    ),
    st.lists(st.floats(-3, 3), min_size=3, max_size=3),
)
def test_kernel_matches_term_by_term_at_any_attitude(quat: list[float], omega: list[float]) -> None:
    body = random_body(7, n=5)
    q = np.array([quat])
    R, G, W = quaternion_rotation(q), quaternion_gamma(q), np.array([omega])
    got = DirectKernel(body, PHYSICAL).torque(W, G)
    ref = _reference(body, PHYSICAL, W, R)
    scale = sum(float(np.max(np.abs(_reference(body, [e], W, R)))) for e in PHYSICAL)
    assert np.max(np.abs(got - ref)) <= 1e-13 * scale


def test_kernel_terms_are_the_fields_at_the_elements() -> None:
    """D and M from the public body-axes field methods, element by element."""
    body = random_body(3)
    _, G, _ = _states(3, 5)
    # electric: D = sum q Phi_Z r = sum q dPhi/dgamma
    D, M = DirectKernel(body, ["electric"]).terms(G)
    dphi = body.field("electric").gamma_derivative(body.charge_positions, G)
    np.testing.assert_allclose(D, np.einsum("n,mni->mi", body.charge_values, dphi), atol=1e-13)
    assert not M.any()
    # lorentz: M = mu = -sum q (r . B) r with B = -gradient_body
    D, M = DirectKernel(body, ["lorentz"]).terms(G)
    r = body.charge_positions
    r_dot_b = -np.einsum("mni,ni->mn", body.field("magnetic").gradient_body(r, G), r)
    mu = -np.einsum("n,mn,ni->mi", body.charge_values, r_dot_b, r)
    np.testing.assert_allclose(M, mu, atol=1e-13)
    assert not D.any()
    # magnetization: D = d(-sum sigma . B)/dgamma, -sigma . B = Phi_Z (sigma . gamma)
    # + 2 Phi_S (sigma . r), from the recurrence evaluated at every (Z, S)
    D, _ = DirectKernel(body, ["magnetization"]).terms(G)
    fld, pts, sig = body.field("magnetic"), body.dipole_positions, body.dipole_moments
    S = np.einsum("ij,ij->i", pts, pts)
    Z = np.einsum("mj,nj->mn", G, pts)
    sums = zonal_sums(np.array(fld.legendre), Z, S, 2)
    expected = np.einsum("mn,nj->mj", sums["Z"], sig)  # Phi_Z sigma
    sig_dot_g = np.einsum("nj,mj->mn", sig, G)
    e = sums["ZZ"] * sig_dot_g + 2.0 * sums["ZS"] * np.einsum("ij,ij->i", pts, sig)
    expected += np.einsum("mn,nj->mj", e, pts)
    np.testing.assert_allclose(D, expected, atol=1e-13)


def test_single_state_path_matches_the_batch() -> None:
    body = random_body(4)
    kernel = DirectKernel(body, PHYSICAL)
    _, G, _ = _states(4, 6)
    single = kernel.scalar_function()
    D, M = kernel.terms(G)
    for k, g in enumerate(G):
        got = np.array(single(*g.tolist()))
        assert np.max(np.abs(got - np.concatenate([D[k], M[k]]))) <= 1e-14 * np.max(np.abs(D))


@pytest.mark.parametrize("effects", [PHYSICAL, ["gravity"], [*PHYSICAL, "theorem"]])
def test_direct_right_hand_side_single_and_batched(effects: list[str]) -> None:
    """rhs_function(1) (Python floats + kernel) equals derivatives (batched kernel)."""
    system = RigidBodySystem(random_body(5), effects, "direct")
    rng = np.random.default_rng(9)
    states = np.hstack([rng.normal(size=(4, 3)), rng.normal(size=(4, 4))])
    states[:, 6] += 2.0  # keep gamma3 away from 0
    batched = system.derivatives(states)
    fun = system.rhs_function(1)
    single = np.array([fun(0.0, s) for s in states])
    assert np.max(np.abs(single - batched)) <= 1e-13 * np.max(np.abs(batched))
    reduced = RigidBodySystem(random_body(5), effects, "reduced").derivatives(states)
    assert np.max(np.abs(reduced - batched)) <= 1e-13 * np.max(np.abs(batched))


def test_uniform_gravity_has_constant_rows() -> None:
    """A field of degree 1 gives polynomials of degree 0 (no Horner step)."""
    body = random_body(6, fields={"gravity": (9.81, 0.0, 0.0)})
    kernel = DirectKernel(body, ["gravity"])
    assert kernel.coefficients.shape == (1, len(body.mass_values))
    W, G, R = _states(6, 3)
    ref = _reference(body, ["gravity"], W, R)
    assert np.max(np.abs(kernel.torque(W, G) - ref)) <= 1e-13 * np.max(np.abs(ref))
    g = G[0].tolist()
    D = kernel.scalar_function()(*g)[:3]
    np.testing.assert_allclose(D, 9.81 * body.mass_values @ body.mass_positions, rtol=1e-14)


def test_kernel_without_rows_gives_zero() -> None:
    body = Body(parameters=Parameters(C=1.0), fields={"magnetic": (1.0,)}, has_elements=True)
    kernel = DirectKernel(body, ["lorentz", "magnetization"])
    assert kernel.rows == 0
    W, G, _ = _states(1, 2)
    assert not kernel.torque(W, G).any()
    assert kernel.scalar_function()(0.0, 0.0, 1.0) == [0.0] * 6


def test_torque_depends_on_gamma_only() -> None:
    """A turn about space Z (precession) changes X = R r but no body-axes torque."""
    body = random_body(8)
    system = RigidBodySystem(body, PHYSICAL, "direct")
    g = np.array([0.3, -0.5, 0.81])
    g /= np.linalg.norm(g)
    W = np.array([[0.4, -1.0, 0.7]])
    R0, R1 = attitude_from_gamma(g, 0.0), attitude_from_gamma(g, 1.3)
    t0 = system.torque(W, R0[2:3].copy(), R0[None])
    ref = _reference(body, PHYSICAL, W, R1[None])
    assert np.max(np.abs(t0 - ref)) <= 1e-13 * np.max(np.abs(ref))


def test_unknown_effect_is_refused() -> None:
    with pytest.raises(ValueError, match="effects"):
        DirectKernel(random_body(0), ["theorem"])
